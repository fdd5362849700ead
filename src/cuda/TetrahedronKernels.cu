// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// CUDA kernels of the tetrahedron objectives. Each warp evaluates one
// direction of one tetrahedron: the samples are spread over its lanes and
// reduced with shuffles. The arithmetic mirrors TetrahedronEvaluator (same
// Sobol points, same seeds, same trilinear weights, double precision) so the
// two backends agree to rounding; volumes, on which fold decisions and sample
// counts depend, are computed without fused multiply-adds, as on the CPU.
#include "TetrahedronKernels.h"

#include "DeviceMemory.h"
#include "TetrahedronDevice.cuh"

#include <cstdint>

namespace morea_core::cuda
{
namespace
{
using namespace device;

__constant__ std::uint32_t c_SobolDirections[4 * 32];

constexpr int WarpsPerBlock = 8;

/** Grid position of `p` (clamped like ChannelVolume::Sample): the first
 *  corner's index and the fractions. */
template <typename View>
__device__ void
GridPosition(const View & image, const double p[3], int base[3], double f[3])
{
  for (int a = 0; a < 3; ++a)
  {
    double       x = (p[a] - image.origin[a]) * image.inverseSpacing[a];
    const double last = static_cast<double>(image.size[a] - 1);
    x = x < 0.0 ? 0.0 : (x > last ? last : x);
    double i = floor(x);
    if (i >= last && image.size[a] > 1)
      i = last - 1.0;
    base[a] = static_cast<int>(i);
    f[a] = image.size[a] > 1 ? x - i : 0.0;
  }
}

/** Trilinear interpolation set-up: the first voxel's offset, the channel
 *  strides to the 7 other corners and the 8 weights (ChannelVolume::Sample). */
struct Trilinear
{
  const float * v;
  int           o[8];
  double        w[8];

  __device__
  Trilinear(const VolumeView & image, const double p[3])
  {
    int    base[3];
    double f[3];
    GridPosition(image, p, base, f);
    const int c = image.channels;
    const int sx = image.size[0] > 1 ? c : 0;
    const int sy = image.size[1] > 1 ? c * image.size[0] : 0;
    const int sz = image.size[2] > 1 ? c * image.size[0] * image.size[1] : 0;
    v = image.data + static_cast<std::size_t>(c) *
                       (static_cast<std::size_t>(base[0]) +
                        static_cast<std::size_t>(image.size[0]) *
                          (static_cast<std::size_t>(base[1]) + static_cast<std::size_t>(image.size[1]) * base[2]));
    w[0] = (1 - f[0]) * (1 - f[1]) * (1 - f[2]);
    w[1] = f[0] * (1 - f[1]) * (1 - f[2]);
    w[2] = (1 - f[0]) * f[1] * (1 - f[2]);
    w[3] = f[0] * f[1] * (1 - f[2]);
    w[4] = (1 - f[0]) * (1 - f[1]) * f[2];
    w[5] = f[0] * (1 - f[1]) * f[2];
    w[6] = (1 - f[0]) * f[1] * f[2];
    w[7] = f[0] * f[1] * f[2];
    o[0] = 0;
    o[1] = sx;
    o[2] = sy;
    o[3] = sx + sy;
    o[4] = sz;
    o[5] = sx + sz;
    o[6] = sy + sz;
    o[7] = sx + sy + sz;
  }

  __device__ float
  Channel(int channel) const
  {
    double s = 0.0;
#pragma unroll
    for (int k = 0; k < 8; ++k)
      s += w[k] * static_cast<double>(__ldg(v + o[k] + channel));
    return static_cast<float>(s);
  }
};

__device__ float
Component(const float4 & v, int c)
{
  return c == 0 ? v.x : (c == 1 ? v.y : (c == 2 ? v.z : v.w));
}

/** Up to 4 channels from one 16-byte load per corner, weights in single
 *  precision: agrees with the CPU to rounding. */
struct PackedExact
{
  float4 v;

  __device__
  PackedExact(const PackedVolumeView & image, const double p[3])
  {
    int    base[3];
    double f[3];
    GridPosition(image, p, base, f);
    const int     sx = image.size[0] > 1 ? 1 : 0;
    const int     sy = image.size[1] > 1 ? image.size[0] : 0;
    const int     sz = image.size[2] > 1 ? image.size[0] * image.size[1] : 0;
    const float4 * d = static_cast<const float4 *>(image.data) +
                       (static_cast<std::size_t>(base[0]) +
                        static_cast<std::size_t>(image.size[0]) *
                          (static_cast<std::size_t>(base[1]) + static_cast<std::size_t>(image.size[1]) * base[2]));
    const float fx = static_cast<float>(f[0]), fy = static_cast<float>(f[1]), fz = static_cast<float>(f[2]);
    const float4 c000 = __ldg(d), c100 = __ldg(d + sx), c010 = __ldg(d + sy), c110 = __ldg(d + sx + sy);
    const float4 c001 = __ldg(d + sz), c101 = __ldg(d + sx + sz), c011 = __ldg(d + sy + sz),
                 c111 = __ldg(d + sx + sy + sz);
    const float w[8] = { (1 - fx) * (1 - fy) * (1 - fz), fx * (1 - fy) * (1 - fz), (1 - fx) * fy * (1 - fz),
                         fx * fy * (1 - fz),             (1 - fx) * (1 - fy) * fz, fx * (1 - fy) * fz,
                         (1 - fx) * fy * fz,             fx * fy * fz };
    const float4 c[8] = { c000, c100, c010, c110, c001, c101, c011, c111 };
    v = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
#pragma unroll
    for (int k = 0; k < 8; ++k)
    {
      v.x += w[k] * c[k].x;
      v.y += w[k] * c[k].y;
      v.z += w[k] * c[k].z;
      v.w += w[k] * c[k].w;
    }
  }
  __device__ float
  Channel(int c) const
  {
    return Component(v, c);
  }
};

template <typename Sampler, typename View>
__global__ void __launch_bounds__(256, 2)
EvaluateTetrahedraKernel(EvaluationConstants k, View moving, View fixed, const double * __restrict__ corners,
                         const std::uint32_t * __restrict__ tetrahedra, const std::uint8_t * __restrict__ itemSkip,
                         std::size_t items, double * itemOut, double * directionOut)
{
  const std::size_t warp = (static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x) / 32;
  const int         lane = threadIdx.x & 31;
  if (warp >= 2 * items)
    return; // whole warps leave together: 2 * items warps exactly
  const std::size_t item = warp >> 1;
  const int         direction = static_cast<int>(warp & 1);
  // Direction 0 samples the source tetrahedron (moving image) and maps to
  // the target (fixed image); direction 1 the other way round. The corners
  // go to registers: selecting between two local arrays at run time would
  // put them in (slow) local memory.
  const double * c = corners + item * ItemCorners;
  const int      fromOffset = direction == 0 ? 0 : 12;
  double         from[12], to[12];
#pragma unroll
  for (int i = 0; i < 12; ++i)
  {
    from[i] = c[fromOffset + i];
    to[i] = c[12 - fromOffset + i];
  }
  const View fromImage = direction == 0 ? moving : fixed;
  const View toImage = direction == 0 ? fixed : moving;

  // Not sampled: an item whose values go unused gets no sample count either,
  // one a refusal bound skipped keeps its count (ItemSkip).
  const std::uint8_t  skip = itemSkip != nullptr ? itemSkip[item] : ItemSampled;
  const auto          full = static_cast<std::uint32_t>(SampleCount(k.samplingRate, k.voxelVolume, from));
  const std::uint32_t n = skip == ItemSampled ? full : 0u;
  std::uint32_t       shift[4];
  SobolShifts(TetrahedronSeed(from), shift);

  const double r = k.guidanceRadius;
  const double inverseRadius = 1.0 / r;
  std::uint32_t laneState[4];
  SobolLaneState(shift, lane, c_SobolDirections, laneState);
  double intensity = 0.0, guidance = 0.0;
  for (std::uint32_t j = 0; 32 * j < n; ++j)
  {
    std::uint32_t shared[4];
    SobolWarpPart(j, c_SobolDirections, shared);
    if (32 * j + lane >= n)
      break;
    // Barycentric weights -log(u) in single precision: the samples' positions
    // move by ~1e-7 of the tetrahedron's size, far below the agreement bound.
    float w[4], sum = 0.0f;
#pragma unroll
    for (int d = 0; d < 4; ++d)
    {
      const float u = (static_cast<float>(laneState[d] ^ shared[d]) + 0.5f) * 2.3283064365386963e-10f;
      sum += (w[d] = -logf(u));
    }
    const double inverseSum = 1.0 / static_cast<double>(sum);
    double       p[3] = { 0.0, 0.0, 0.0 }, q[3] = { 0.0, 0.0, 0.0 };
#pragma unroll
    for (int i = 0; i < 4; ++i)
    {
      const double wi = static_cast<double>(w[i]) * inverseSum;
#pragma unroll
      for (int a = 0; a < 3; ++a)
      {
        p[a] += wi * from[3 * i + a];
        q[a] += wi * to[3 * i + a];
      }
    }
    const Sampler   at(fromImage, p), bt(toImage, q);
    const float     a0 = at.Channel(0), b0 = bt.Channel(0);
    if (a0 > 0.0f && b0 > 0.0f)
    {
      const double d = static_cast<double>(a0) - static_cast<double>(b0);
      intensity += d * d;
    }
    else if (a0 > 0.0f || b0 > 0.0f)
      intensity += 1.0;
    for (int g = 0; g < k.structures; ++g)
    {
      const double d = at.Channel(1 + g);
      if (d < r)
      {
        const double e = d - static_cast<double>(bt.Channel(1 + g));
        guidance += k.guidanceWeights[g] * (r - d) * inverseRadius * e * e;
      }
    }
  }
  intensity = WarpSum(intensity);
  guidance = WarpSum(guidance);
  if (lane != 0)
    return;
  double * out = directionOut + warp * DirectionValues;
  out[0] = intensity;
  out[1] = guidance;
  out[2] = static_cast<double>(skip == ItemUnused ? 0u : full);
  if (direction == 0) // from = source, to = target
  {
    WriteItemValues(k.referenceVolumes, k.volumeFraction, k.elasticity, k.rigidWeights, k.rigidInverseEdges,
                    k.rigidLimitVolumes, k.rigidStrainLimitSquared,
                    tetrahedra[item], from, to, itemOut + item * ItemValues);
  }
}
} // namespace

void
UploadSobolDirections(const std::uint32_t * directions)
{
  Check(cudaMemcpyToSymbol(c_SobolDirections, directions, sizeof(std::uint32_t) * 4 * 32),
        "copying the Sobol direction numbers");
  UploadTextureSobolDirections(directions); // the texture kernels' module has its own copy
}

void
LaunchEvaluateTetrahedra(const EvaluationConstants & constants, const double * corners,
                         const std::uint32_t * tetrahedra, const std::uint8_t * itemSkip, std::size_t items,
                         double * itemOut, double * directionOut, void * stream)
{
  if (items == 0)
    return;
  const std::size_t warps = 2 * items;
  const std::size_t blocks = (warps + WarpsPerBlock - 1) / WarpsPerBlock;
  const unsigned     grid = static_cast<unsigned>(blocks);
  const cudaStream_t s = static_cast<cudaStream_t>(stream);
  const auto &       k = constants;
  if (!k.packed)
    EvaluateTetrahedraKernel<Trilinear><<<grid, WarpsPerBlock * 32, 0, s>>>(k, k.moving, k.fixed, corners, tetrahedra,
                                                                           itemSkip, items, itemOut, directionOut);
  else
    EvaluateTetrahedraKernel<PackedExact><<<grid, WarpsPerBlock * 32, 0, s>>>(
      k, k.packedMoving, k.packedFixed, corners, tetrahedra, itemSkip, items, itemOut, directionOut);
  Check(cudaGetLastError(), "launching the tetrahedron kernel");
}
} // namespace morea_core::cuda
