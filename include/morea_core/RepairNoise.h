// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the Gaussian moves of the fold repair.
// Each trial's move is a pure function of (seed, pass, point, trial), not a
// draw from a running stream, so that the trials of one point can be drawn in
// any order or all at once (one GPU lane each). The moves are bit-identical
// on the CPU and on a GPU: the logarithm, sine and cosine are evaluated here
// from correctly rounded +, -, x, / only (the libraries' versions differ in
// the last bits), and a repaired point's bits decide its tetrahedra's sample
// seeds. Plain inline code: nvcc compiles it for the device.
#ifndef morea_RepairNoise_h
#define morea_RepairNoise_h

#include <cmath>
#include <cstdint>

#ifdef __CUDACC__
#  define MOREA_HOST_DEVICE __host__ __device__
#else
#  define MOREA_HOST_DEVICE
#endif

namespace morea_core
{
namespace repair_noise
{
// Round-to-nearest operations the device compiler may not fuse into FMAs
// (the host compiler does not fuse without FMA instructions in its target).
MOREA_HOST_DEVICE inline double
Mul(double a, double b)
{
#ifdef __CUDA_ARCH__
  return __dmul_rn(a, b);
#else
  return a * b;
#endif
}
MOREA_HOST_DEVICE inline double
Add(double a, double b)
{
#ifdef __CUDA_ARCH__
  return __dadd_rn(a, b);
#else
  return a + b;
#endif
}
MOREA_HOST_DEVICE inline double
Sub(double a, double b)
{
#ifdef __CUDA_ARCH__
  return __dsub_rn(a, b);
#else
  return a - b;
#endif
}
MOREA_HOST_DEVICE inline double
Div(double a, double b)
{
#ifdef __CUDA_ARCH__
  return __ddiv_rn(a, b);
#else
  return a / b;
#endif
}

/** The SplitMix64 finaliser: a bijective 64-bit mix. */
MOREA_HOST_DEVICE inline std::uint64_t
Mix(std::uint64_t z)
{
  z += 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/** Uniform in (0, 1] with 53 random bits: never 0, so its logarithm is finite. */
MOREA_HOST_DEVICE inline double
Uniform(std::uint64_t bits)
{
  return static_cast<double>((bits >> 11) + 1) * 0x1.0p-53;
}

/** Natural logarithm of u in (0, 1]: u = m 2^e with m in [1/sqrt 2, sqrt 2),
 *  log m = 2 atanh((m - 1) / (m + 1)) by its series (|s| < 0.172: 11 terms
 *  reach double precision). */
MOREA_HOST_DEVICE inline double
Log(double u)
{
  int    e = 0;
  double m = frexp(u, &e); // exact
  if (m < 0.70710678118654752440)
  {
    m *= 2.0;
    --e;
  }
  const double s = Div(m - 1.0, Add(m, 1.0));
  const double z = Mul(s, s);
  double       p = 1.0 / 21.0;
  p = Add(Mul(p, z), 1.0 / 19.0);
  p = Add(Mul(p, z), 1.0 / 17.0);
  p = Add(Mul(p, z), 1.0 / 15.0);
  p = Add(Mul(p, z), 1.0 / 13.0);
  p = Add(Mul(p, z), 1.0 / 11.0);
  p = Add(Mul(p, z), 1.0 / 9.0);
  p = Add(Mul(p, z), 1.0 / 7.0);
  p = Add(Mul(p, z), 1.0 / 5.0);
  p = Add(Mul(p, z), 1.0 / 3.0);
  p = Add(Mul(p, z), 1.0);
  return Add(Mul(static_cast<double>(e), 0.69314718055994530942), Mul(2.0 * s, p));
}

/** cos and sin of 2 pi u for u in [0, 1]: u minus the nearest quarter turn
 *  (exact) leaves |angle| <= pi / 4 for the Taylor series. */
MOREA_HOST_DEVICE inline void
CosSinOfTurns(double u, double & c, double & s)
{
  const double k = floor(Add(Mul(4.0, u), 0.5));
  const double x = Mul(u - 0.25 * k, 6.28318530717958647693);
  const double z = Mul(x, x);
  double       ps = -1.0 / 1307674368000.0; // -1/15!
  ps = Add(Mul(ps, z), 1.0 / 6227020800.0);
  ps = Add(Mul(ps, z), -1.0 / 39916800.0);
  ps = Add(Mul(ps, z), 1.0 / 362880.0);
  ps = Add(Mul(ps, z), -1.0 / 5040.0);
  ps = Add(Mul(ps, z), 1.0 / 120.0);
  ps = Add(Mul(ps, z), -1.0 / 6.0);
  const double sine = Add(x, Mul(Mul(x, z), ps));
  double       pc = 1.0 / 20922789888000.0; // 1/16!
  pc = Add(Mul(pc, z), -1.0 / 87178291200.0);
  pc = Add(Mul(pc, z), 1.0 / 479001600.0);
  pc = Add(Mul(pc, z), -1.0 / 3628800.0);
  pc = Add(Mul(pc, z), 1.0 / 40320.0);
  pc = Add(Mul(pc, z), -1.0 / 720.0);
  pc = Add(Mul(pc, z), 1.0 / 24.0);
  pc = Add(Mul(pc, z), -0.5);
  const double cosine = Add(1.0, Mul(z, pc));
  switch (static_cast<int>(k) % 4)
  {
    case 1:
      c = -sine;
      s = cosine;
      break;
    case 2:
      c = -cosine;
      s = -sine;
      break;
    case 3:
      c = sine;
      s = -cosine;
      break;
    default:
      c = cosine;
      s = sine;
  }
}
} // namespace repair_noise

/** Three independent standard normals for trial `trial` of `point` in repair
 *  pass `pass` of the repair seeded by `seed` (Box-Muller). */
MOREA_HOST_DEVICE inline void
RepairTrialNormals(std::uint64_t seed, std::uint32_t pass, std::uint32_t point, std::uint32_t trial, double out[3])
{
  using namespace repair_noise;
  const std::uint64_t key =
    (static_cast<std::uint64_t>(pass) << 56) ^ (static_cast<std::uint64_t>(point) << 24) ^ trial;
  std::uint64_t h = Mix(seed ^ Mix(key));
  double        u[4];
  for (double & v : u)
  {
    v = Uniform(h);
    h = Mix(h);
  }
  const double r0 = sqrt(-2.0 * Log(u[0])); // sqrt is correctly rounded on both
  const double r1 = sqrt(-2.0 * Log(u[2]));
  double       c = 0.0, s = 0.0;
  CosSinOfTurns(u[1], c, s);
  out[0] = Mul(r0, c);
  out[1] = Mul(r0, s);
  CosSinOfTurns(u[3], c, s);
  out[2] = Mul(r1, c);
}
} // namespace morea_core

#endif
