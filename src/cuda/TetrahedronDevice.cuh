// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Device functions shared by the tetrahedron kernels (TetrahedronKernels.cu,
// TextureKernels.cu): the seeds, Sobol shifts, volumes and magnitude exactly
// as the CPU's TetrahedronEvaluator computes them. Included by .cu files only.
#ifndef morea_cuda_TetrahedronDevice_cuh
#define morea_cuda_TetrahedronDevice_cuh

#include <cstdint>

namespace morea_core::cuda::device
{
inline __device__ std::uint64_t
SplitMix64(std::uint64_t & x)
{
  std::uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

inline __device__ std::uint64_t
HashCombine(std::uint64_t a, std::uint64_t b)
{
  std::uint64_t x = a;
  x = SplitMix64(x) ^ b;
  return SplitMix64(x);
}

inline __device__ std::uint64_t
RotateLeft(std::uint64_t x, int k)
{
  return (x << k) | (x >> (64 - k));
}

/** The four digital shifts ScrambledSobol4 draws from a seed (xoshiro256**). */
inline __device__ void
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

/** Sobol state of sample 32 j + lane, split in two. Its Gray code is
 *  16 (2j ^ j) ^ gray(lane) (XOR is linear and the parts' bits do not
 *  overlap), so the state is this lane's fixed part XOR a part shared by the
 *  whole warp. `directions`: the 4 x 32 direction numbers. */
inline __device__ void
SobolLaneState(const std::uint32_t shift[4], int lane, const std::uint32_t * directions, std::uint32_t state[4])
{
  const std::uint32_t gray = static_cast<std::uint32_t>(lane) ^ (static_cast<std::uint32_t>(lane) >> 1);
#pragma unroll
  for (int d = 0; d < 4; ++d)
  {
    state[d] = shift[d];
#pragma unroll
    for (int b = 0; b < 5; ++b)
      if ((gray >> b) & 1u)
        state[d] ^= directions[d * 32 + b];
  }
}

/** The warp-shared part of the Sobol state of samples 32 j + lane. */
inline __device__ void
SobolWarpPart(std::uint32_t j, const std::uint32_t * directions, std::uint32_t part[4])
{
  part[0] = part[1] = part[2] = part[3] = 0;
  for (std::uint32_t bits = (2 * j) ^ j, b = 4; bits; bits >>= 1, ++b) // warp-uniform loop
    if (bits & 1u)
#pragma unroll
      for (int d = 0; d < 4; ++d)
        part[d] ^= directions[d * 32 + b];
}

inline __device__ std::uint64_t
TetrahedronSeed(const double c[12])
{
  std::uint64_t h = 0x7465747261ull;
  for (int i = 0; i < 12; ++i)
    h = HashCombine(h, static_cast<std::uint64_t>(__double_as_longlong(c[i])));
  return h;
}

/** Six times the signed volume (the triple product), rounded exactly as
 *  the CPU computes it (no contraction). */
inline __device__ double
SixfoldSignedVolume(const double c[12])
{
  const double ux = __dsub_rn(c[3], c[0]), uy = __dsub_rn(c[4], c[1]), uz = __dsub_rn(c[5], c[2]);
  const double vx = __dsub_rn(c[6], c[0]), vy = __dsub_rn(c[7], c[1]), vz = __dsub_rn(c[8], c[2]);
  const double wx = __dsub_rn(c[9], c[0]), wy = __dsub_rn(c[10], c[1]), wz = __dsub_rn(c[11], c[2]);
  const double a = __dmul_rn(ux, __dsub_rn(__dmul_rn(vy, wz), __dmul_rn(vz, wy)));
  const double b = __dmul_rn(uy, __dsub_rn(__dmul_rn(vx, wz), __dmul_rn(vz, wx)));
  const double d = __dmul_rn(uz, __dsub_rn(__dmul_rn(vx, wy), __dmul_rn(vy, wx)));
  return __dadd_rn(__dsub_rn(a, b), d);
}

/** Signed volume, rounded exactly as the CPU computes it. */
inline __device__ double
SignedVolume(const double c[12])
{
  return __ddiv_rn(SixfoldSignedVolume(c), 6.0);
}

/** Samples one direction of a tetrahedron with corners `c` gets: rate x
 *  |volume| / voxel volume, rounded, at least 1 (TetrahedronEvaluator::SampleCount). */
inline __device__ double
SampleCount(double samplingRate, double voxelVolume, const double c[12])
{
  const double count = round(__ddiv_rn(__dmul_rn(samplingRate, fabs(SignedVolume(c))), voxelVolume));
  return count < 1.0 ? 1.0 : count;
}

inline __device__ double
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

/** VolumeViolation(SignedVolume(c), ...), dividing only where the quotient
 *  matters. Without a volume fraction (the lower bound is then 0 for a
 *  finite reference), a tetrahedron oriented as its reference (six times its
 *  volume above 1e-300, so that the correctly rounded sixth has the same
 *  sign) is not folded and adds 0, whatever the quotient's last bits. The
 *  fold repair's trials meet mostly such tetrahedra, and the double
 *  division was the longest chain of the check. */
inline __device__ double
CornersVolumeViolation(const double c[12], double reference, double fraction, double & folded)
{
  const double six = SixfoldSignedVolume(c);
  if (fraction == 0.0 && isfinite(reference) && (reference > 0.0 ? six : -six) > 1e-300)
    return 0.0;
  return VolumeViolation(__ddiv_rn(six, 6.0), reference, fraction, folded);
}

inline __device__ double
Distance(const double * a, const double * b)
{
  const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
  return sqrt(x * x + y * y + z * z);
}

inline __device__ double
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

/** TetrahedronRigidDeviation of morea/RigidityTerm.h, in its order of operations. */
inline __device__ double
TetrahedronRigidDeviation(const double s[12], const double t[12], const double * inverseEdges)
{
  double gs[9], gt[9];
  for (int a = 0; a < 3; ++a)
    for (int j = 0; j < 3; ++j)
    {
      double ss = 0.0, st = 0.0;
      for (int e = 0; e < 3; ++e)
      {
        ss += (s[3 * (e + 1) + a] - s[a]) * inverseEdges[3 * e + j];
        st += (t[3 * (e + 1) + a] - t[a]) * inverseEdges[3 * e + j];
      }
      gs[3 * a + j] = ss;
      gt[3 * a + j] = st;
    }
  double sum = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      double c = 0.0;
      for (int a = 0; a < 3; ++a)
        c += gt[3 * a + i] * gt[3 * a + j] - gs[3 * a + i] * gs[3 * a + j];
      sum += 0.25 * c * c;
    }
  return sum;
}

/** A tetrahedron's whole magnitude term: its edges times its elasticity
 *  factor, plus its rigidity term (elasticity null: 1 everywhere;
 *  rigidWeights null: no rigid structures). */
inline __device__ double
ItemMagnitude(const double * elasticity, const double * rigidWeights, const double * rigidInverseEdges,
              std::uint32_t t, const double source[12], const double target[12])
{
  double m = TetrahedronMagnitude(source, target, elasticity ? elasticity[t] : 1.0);
  if (rigidWeights != nullptr && rigidWeights[t] != 0.0)
    m += rigidWeights[t] * TetrahedronRigidDeviation(source, target, rigidInverseEdges + 9 * static_cast<std::size_t>(t));
  return m;
}

/** TetrahedronRigidViolation of morea/RigidityTerm.h: the strain limit's
 *  constraint value (limitVolumes null: no limit). */
inline __device__ double
RigidViolation(const double * limitVolumes, double limitSquared, const double * rigidInverseEdges, std::uint32_t t,
               const double source[12], const double target[12], double & violated)
{
  if (limitVolumes == nullptr || limitVolumes[t] == 0.0)
    return 0.0;
  const double deviation = TetrahedronRigidDeviation(source, target, rigidInverseEdges + 9 * static_cast<std::size_t>(t));
  if (!(deviation > limitSquared))
    return 0.0;
  violated += 1.0;
  return __dmul_rn(__dsub_rn(deviation, limitSquared), limitVolumes[t]);
}

inline __device__ double
WarpSum(double x)
{
  for (int offset = 16; offset > 0; offset >>= 1)
    x += __shfl_down_sync(0xffffffffu, x, offset);
  return x;
}

/** An item's values besides its samples' (ItemValues' layout: magnitude,
 *  fold value, folded count) for tetrahedron t with corners `source` and
 *  `target`; the magnitude as ItemMagnitude, the fold value with the rigid
 *  strain limit's (RigidViolation). */
inline __device__ void
WriteItemValues(const double * referenceVolumes, double volumeFraction, const double * elasticity,
                const double * rigidWeights, const double * rigidInverseEdges, const double * rigidLimitVolumes,
                double rigidStrainLimitSquared, std::uint32_t t, const double source[12], const double target[12],
                double * out)
{
  double folded = 0.0;
  double value = VolumeViolation(SignedVolume(source), referenceVolumes[t], volumeFraction, folded);
  value += VolumeViolation(SignedVolume(target), referenceVolumes[t], volumeFraction, folded);
  value += RigidViolation(rigidLimitVolumes, rigidStrainLimitSquared, rigidInverseEdges, t, source, target, folded);
  out[0] = ItemMagnitude(elasticity, rigidWeights, rigidInverseEdges, t, source, target);
  out[1] = value;
  out[2] = folded;
}
} // namespace morea_core::cuda::device

#endif
