// CUDA kernels of the tetrahedron objectives. Each warp evaluates one
// direction of one tetrahedron: the samples are spread over its lanes and
// reduced with shuffles. The arithmetic mirrors TetrahedronEvaluator (same
// Sobol points, same seeds, same trilinear weights, double precision) so the
// two backends agree to rounding; volumes, on which fold decisions and sample
// counts depend, are computed without fused multiply-adds, as on the CPU.
#include "TetrahedronKernels.h"

#include "DeviceMemory.h"

#include <cstdint>

namespace morea::cuda
{
namespace
{
__constant__ std::uint32_t c_SobolDirections[4 * 32];

constexpr int WarpsPerBlock = 8;

__device__ std::uint64_t
SplitMix64(std::uint64_t & x)
{
  std::uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

__device__ std::uint64_t
HashCombine(std::uint64_t a, std::uint64_t b)
{
  std::uint64_t x = a;
  x = SplitMix64(x) ^ b;
  return SplitMix64(x);
}

__device__ std::uint64_t
RotateLeft(std::uint64_t x, int k)
{
  return (x << k) | (x >> (64 - k));
}

/** The four digital shifts ScrambledSobol4 draws from a seed (xoshiro256**). */
__device__ void
SobolShifts(std::uint64_t seed, std::uint32_t shift[4])
{
  std::uint64_t s[4];
  for (int i = 0; i < 4; ++i)
    s[i] = SplitMix64(seed);
  for (int i = 0; i < 4; ++i)
  {
    const std::uint64_t result = RotateLeft(s[1] * 5, 7) * 9;
    const std::uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = RotateLeft(s[3], 45);
    shift[i] = static_cast<std::uint32_t>(result >> 32);
  }
}

__device__ std::uint64_t
TetrahedronSeed(const double c[12])
{
  std::uint64_t h = 0x7465747261ull;
  for (int i = 0; i < 12; ++i)
    h = HashCombine(h, static_cast<std::uint64_t>(__double_as_longlong(c[i])));
  return h;
}

/** Signed volume, rounded exactly as the CPU computes it (no contraction). */
__device__ double
SignedVolume(const double c[12])
{
  const double ux = __dsub_rn(c[3], c[0]), uy = __dsub_rn(c[4], c[1]), uz = __dsub_rn(c[5], c[2]);
  const double vx = __dsub_rn(c[6], c[0]), vy = __dsub_rn(c[7], c[1]), vz = __dsub_rn(c[8], c[2]);
  const double wx = __dsub_rn(c[9], c[0]), wy = __dsub_rn(c[10], c[1]), wz = __dsub_rn(c[11], c[2]);
  const double a = __dmul_rn(ux, __dsub_rn(__dmul_rn(vy, wz), __dmul_rn(vz, wy)));
  const double b = __dmul_rn(uy, __dsub_rn(__dmul_rn(vx, wz), __dmul_rn(vz, wx)));
  const double d = __dmul_rn(uz, __dsub_rn(__dmul_rn(vx, wy), __dmul_rn(vy, wx)));
  return __ddiv_rn(__dadd_rn(__dsub_rn(a, b), d), 6.0);
}

__device__ double
VolumeViolation(double v, double reference, double fraction, double & folded)
{
  const double size = fabs(reference);
  const double oriented = reference > 0.0 ? v : -v;
  const double lower = __dmul_rn(fraction, size);
  if (!(oriented > lower))
  {
    folded += 1.0;
    return __dsub_rn(lower, oriented);
  }
  if (fraction > 0.0 && __dmul_rn(oriented, fraction) > size)
  {
    folded += 1.0;
    return __dsub_rn(oriented, __ddiv_rn(size, fraction));
  }
  return 0.0;
}

__device__ double
Distance(const double * a, const double * b)
{
  const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
  return sqrt(x * x + y * y + z * z);
}

__device__ double
TetrahedronMagnitude(const double s[12], const double t[12], double elasticity)
{
  double sum = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
    {
      const double d = Distance(s + 3 * i, s + 3 * j) - Distance(t + 3 * i, t + 3 * j);
      sum += d * d;
    }
  double cs[3] = { 0.0, 0.0, 0.0 }, ct[3] = { 0.0, 0.0, 0.0 };
  for (int i = 0; i < 4; ++i)
    for (int a = 0; a < 3; ++a)
    {
      cs[a] += 0.25 * s[3 * i + a];
      ct[a] += 0.25 * t[3 * i + a];
    }
  for (int i = 0; i < 4; ++i)
  {
    const double d = Distance(cs, s + 3 * i) - Distance(ct, t + 3 * i);
    sum += d * d;
  }
  return elasticity * sum;
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

/** Up to 4 channels from one filtered texture fetch. */
struct PackedTexture
{
  float4 v;

  __device__
  PackedTexture(const PackedVolumeView & image, const double p[3])
  {
    float x[3];
    for (int a = 0; a < 3; ++a)
    {
      double       t = (p[a] - image.origin[a]) * image.inverseSpacing[a];
      const double last = static_cast<double>(image.size[a] - 1);
      t = t < 0.0 ? 0.0 : (t > last ? last : t);
      x[a] = static_cast<float>(t) + 0.5f; // texel centres lie at +0.5
    }
    v = tex3D<float4>(static_cast<cudaTextureObject_t>(image.texture), x[0], x[1], x[2]);
  }
  __device__ float
  Channel(int c) const
  {
    return Component(v, c);
  }
};

__device__ double
WarpSum(double x)
{
  for (int offset = 16; offset > 0; offset >>= 1)
    x += __shfl_down_sync(0xffffffffu, x, offset);
  return x;
}

template <typename Sampler, typename View>
__global__ void __launch_bounds__(256, 2)
EvaluateTetrahedraKernel(EvaluationConstants k, View moving, View fixed, const double * __restrict__ corners,
                         const std::uint32_t * __restrict__ tetrahedra, std::size_t items, double * itemOut,
                         double * directionOut)
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

  const double volume = fabs(SignedVolume(from));
  double       count = round(__ddiv_rn(__dmul_rn(k.samplingRate, volume), k.voxelVolume));
  const std::uint32_t n = count < 1.0 ? 1u : static_cast<std::uint32_t>(count);
  std::uint32_t       shift[4];
  SobolShifts(TetrahedronSeed(from), shift);

  const double r = k.guidanceRadius;
  const double inverseRadius = 1.0 / r;
  // Sample s = 32 j + lane has Gray code gray(s) = 16 (2j ^ j) ^ gray(lane)
  // (XOR is linear and the parts' bits do not overlap), so its Sobol state is
  // this lane's fixed part XOR a part shared by the whole warp.
  std::uint32_t laneState[4];
  {
    const std::uint32_t gray = static_cast<std::uint32_t>(lane) ^ (static_cast<std::uint32_t>(lane) >> 1);
#pragma unroll
    for (int d = 0; d < 4; ++d)
    {
      std::uint32_t state = shift[d];
#pragma unroll
      for (int b = 0; b < 5; ++b)
        if ((gray >> b) & 1u)
          state ^= c_SobolDirections[d * 32 + b];
      laneState[d] = state;
    }
  }
  double intensity = 0.0, guidance = 0.0;
  for (std::uint32_t j = 0; 32 * j < n; ++j)
  {
    std::uint32_t shared[4] = { 0, 0, 0, 0 };
    for (std::uint32_t bits = (2 * j) ^ j, b = 4; bits; bits >>= 1, ++b) // warp-uniform loop
      if (bits & 1u)
#pragma unroll
        for (int d = 0; d < 4; ++d)
          shared[d] ^= c_SobolDirections[d * 32 + b];
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
  out[2] = static_cast<double>(n);
  if (direction == 0) // from = source, to = target
  {
    const std::uint32_t t = tetrahedra[item];
    double              folded = 0.0;
    double              value = VolumeViolation(SignedVolume(from), k.referenceVolumes[t], k.volumeFraction, folded);
    value += VolumeViolation(SignedVolume(to), k.referenceVolumes[t], k.volumeFraction, folded);
    double * o = itemOut + item * ItemValues;
    o[0] = TetrahedronMagnitude(from, to, k.elasticity ? k.elasticity[t] : 1.0);
    o[1] = value;
    o[2] = folded;
  }
}
} // namespace

void
UploadSobolDirections(const std::uint32_t * directions)
{
  Check(cudaMemcpyToSymbol(c_SobolDirections, directions, sizeof(std::uint32_t) * 4 * 32),
        "copying the Sobol direction numbers");
}

void
LaunchEvaluateTetrahedra(const EvaluationConstants & constants, const double * corners,
                         const std::uint32_t * tetrahedra, std::size_t items, double * itemOut,
                         double * directionOut, void * stream)
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
                                                                           items, itemOut, directionOut);
  else if (k.interpolation == Interpolation::Exact)
    EvaluateTetrahedraKernel<PackedExact><<<grid, WarpsPerBlock * 32, 0, s>>>(
      k, k.packedMoving, k.packedFixed, corners, tetrahedra, items, itemOut, directionOut);
  else
    EvaluateTetrahedraKernel<PackedTexture><<<grid, WarpsPerBlock * 32, 0, s>>>(
      k, k.packedMoving, k.packedFixed, corners, tetrahedra, items, itemOut, directionOut);
  Check(cudaGetLastError(), "launching the tetrahedron kernel");
}
} // namespace morea::cuda
