// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/TetrahedronSampling.h"

#include "morea_core/Random.h"

#include <cstring>

namespace morea_core
{
namespace
{
/** Direction numbers v[d][bit] of Sobol dimensions 1-4 (Joe and Kuo): the
 *  first is van der Corput; the others follow their primitive polynomials. */
struct DirectionNumbers
{
  std::uint32_t v[4][32];

  DirectionNumbers()
  {
    for (int i = 0; i < 32; ++i)
      v[0][i] = 1u << (31 - i);
    // degree s, coefficient bits a, initial m_1..m_s
    const int           degree[3] = { 1, 2, 3 };
    const std::uint32_t coefficients[3] = { 0, 1, 1 };
    const std::uint32_t initial[3][3] = { { 1, 0, 0 }, { 1, 3, 0 }, { 1, 3, 1 } };
    for (int d = 0; d < 3; ++d)
    {
      const int     s = degree[d];
      std::uint32_t m[32];
      for (int i = 0; i < s; ++i)
        m[i] = initial[d][i];
      for (int i = s; i < 32; ++i)
      {
        m[i] = m[i - s] ^ (m[i - s] << s);
        for (int k = 1; k < s; ++k)
          if ((coefficients[d] >> (s - 1 - k)) & 1u)
            m[i] ^= m[i - k] << k;
      }
      for (int i = 0; i < 32; ++i)
        v[d + 1][i] = m[i] << (31 - i);
    }
  }
};

const DirectionNumbers &
Directions()
{
  static const DirectionNumbers directions;
  return directions;
}
} // namespace

const std::uint32_t *
SobolDirectionNumbers()
{
  return &Directions().v[0][0];
}

ScrambledSobol4::ScrambledSobol4(std::uint64_t seed)
{
  RandomGenerator random(seed);
  for (auto & shift : m_Shift)
    shift = static_cast<std::uint32_t>(random.NextU64() >> 32);
}

std::array<double, 4>
ScrambledSobol4::Next()
{
  // Gray-code order: flip the direction number of the lowest zero bit of the index.
  if (m_Index > 0)
  {
    int           bit = 0;
    std::uint32_t n = m_Index - 1;
    while (n & 1u)
    {
      n >>= 1;
      ++bit;
    }
    for (int d = 0; d < 4; ++d)
      m_State[d] ^= Directions().v[d][bit];
  }
  ++m_Index;
  std::array<double, 4> u{};
  for (int d = 0; d < 4; ++d)
    u[d] = (static_cast<double>(m_State[d] ^ m_Shift[d]) + 0.5) / 4294967296.0;
  return u;
}

std::uint64_t
TetrahedronSeed(const Vec3 & a, const Vec3 & b, const Vec3 & c, const Vec3 & d)
{
  std::uint64_t h = 0x7465747261ull; // "tetra"
  for (const Vec3 * p : { &a, &b, &c, &d })
    for (double x : *p)
    {
      std::uint64_t bits;
      std::memcpy(&bits, &x, sizeof bits);
      h = HashCombine(h, bits);
    }
  return h;
}
} // namespace morea_core
