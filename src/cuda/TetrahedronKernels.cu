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
      double       x = (p[a] - image.origin[a]) / image.spacing[a];
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
    for (int k = 0; k < 8; ++k)
      s += w[k] * static_cast<double>(__ldg(v + o[k] + channel));
    return static_cast<float>(s);
  }
};

__device__ double
WarpSum(double x)
{
  for (int offset = 16; offset > 0; offset >>= 1)
    x += __shfl_down_sync(0xffffffffu, x, offset);
  return x;
}

__global__ void
EvaluateTetrahedraKernel(EvaluationConstants k, const double * __restrict__ corners,
                         const std::uint32_t * __restrict__ tetrahedra, std::size_t items, double * itemOut,
                         double * directionOut)
{
  const std::size_t warp = (static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x) / 32;
  const int         lane = threadIdx.x & 31;
  if (warp >= 2 * items)
    return; // whole warps leave together: 2 * items warps exactly
  const std::size_t item = warp >> 1;
  const int         direction = static_cast<int>(warp & 1);
  double            source[12], target[12];
  for (int i = 0; i < 12; ++i)
  {
    source[i] = corners[item * ItemCorners + i];
    target[i] = corners[item * ItemCorners + 12 + i];
  }
  // Direction 0 samples the source tetrahedron (moving image) and maps to
  // the target (fixed image); direction 1 the other way round.
  const double *     from = direction == 0 ? source : target;
  const double *     to = direction == 0 ? target : source;
  const VolumeView & fromImage = direction == 0 ? k.moving : k.fixed;
  const VolumeView & toImage = direction == 0 ? k.fixed : k.moving;

  const double volume = fabs(SignedVolume(from));
  double       count = round(__ddiv_rn(__dmul_rn(k.samplingRate, volume), k.voxelVolume));
  const std::uint32_t n = count < 1.0 ? 1u : static_cast<std::uint32_t>(count);
  std::uint32_t       shift[4];
  SobolShifts(TetrahedronSeed(from), shift);

  const double r = k.guidanceRadius;
  double       intensity = 0.0, guidance = 0.0;
  for (std::uint32_t s = lane; s < n; s += 32)
  {
    const std::uint32_t gray = s ^ (s >> 1);
    double              w[4], sum = 0.0;
    for (int d = 0; d < 4; ++d)
    {
      std::uint32_t state = 0;
      for (std::uint32_t bits = gray, b = 0; bits; bits >>= 1, ++b)
        if (bits & 1u)
          state ^= c_SobolDirections[d * 32 + b];
      const double u = (static_cast<double>(state ^ shift[d]) + 0.5) / 4294967296.0;
      sum += (w[d] = -log(u));
    }
    double p[3] = { 0.0, 0.0, 0.0 }, q[3] = { 0.0, 0.0, 0.0 };
    for (int i = 0; i < 4; ++i)
    {
      const double wi = w[i] / sum;
      for (int a = 0; a < 3; ++a)
      {
        p[a] += wi * from[3 * i + a];
        q[a] += wi * to[3 * i + a];
      }
    }
    const Trilinear at(fromImage, p), bt(toImage, q);
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
        guidance += k.guidanceWeights[g] * (r - d) / r * e * e;
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
  if (direction == 0)
  {
    const std::uint32_t t = tetrahedra[item];
    double              folded = 0.0;
    double              value = VolumeViolation(SignedVolume(source), k.referenceVolumes[t], k.volumeFraction, folded);
    value += VolumeViolation(SignedVolume(target), k.referenceVolumes[t], k.volumeFraction, folded);
    double * o = itemOut + item * ItemValues;
    o[0] = TetrahedronMagnitude(source, target, k.elasticity ? k.elasticity[t] : 1.0);
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
  EvaluateTetrahedraKernel<<<static_cast<unsigned>(blocks), WarpsPerBlock * 32, 0,
                             static_cast<cudaStream_t>(stream)>>>(constants, corners, tetrahedra, items, itemOut,
                                                                  directionOut);
  Check(cudaGetLastError(), "launching the tetrahedron kernel");
}
} // namespace morea::cuda
