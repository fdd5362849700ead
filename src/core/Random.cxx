// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/Random.h"

#include <cmath>

namespace morea_core
{
namespace
{
std::uint64_t
SplitMix64(std::uint64_t & x)
{
  std::uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

std::uint64_t
RotateLeft(std::uint64_t x, int k)
{
  return (x << k) | (x >> (64 - k));
}
} // namespace

RandomGenerator::RandomGenerator(std::uint64_t seed)
{
  for (auto & s : m_State)
  {
    s = SplitMix64(seed);
  }
}

std::uint64_t
RandomGenerator::NextU64()
{
  const std::uint64_t result = RotateLeft(m_State[1] * 5, 7) * 9;
  const std::uint64_t t = m_State[1] << 17;
  m_State[2] ^= m_State[0];
  m_State[3] ^= m_State[1];
  m_State[1] ^= m_State[2];
  m_State[0] ^= m_State[3];
  m_State[2] ^= t;
  m_State[3] = RotateLeft(m_State[3], 45);
  return result;
}

double
RandomGenerator::Uniform()
{
  return static_cast<double>(NextU64() >> 11) * 0x1.0p-53;
}

double
RandomGenerator::Uniform(double low, double high)
{
  return low + (high - low) * Uniform();
}

double
RandomGenerator::Normal()
{
  if (m_HasSpare)
  {
    m_HasSpare = false;
    return m_SpareNormal;
  }
  double u1 = Uniform();
  while (u1 <= 0.0)
  {
    u1 = Uniform();
  }
  const double u2 = Uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  const double angle = 2.0 * M_PI * u2;
  m_SpareNormal = r * std::sin(angle);
  m_HasSpare = true;
  return r * std::cos(angle);
}

std::uint64_t
HashCombine(std::uint64_t a, std::uint64_t b)
{
  // Mix `a` fully before combining: the boost-style a ^ (b + c + (a << 6) + (a >> 2))
  // collides for small inputs (e.g. (15, 46) and (16, 0)), which gave phantoms of
  // neighbouring seeds the same noise slices.
  std::uint64_t x = a;
  x = SplitMix64(x) ^ b;
  return SplitMix64(x);
}
} // namespace morea_core
