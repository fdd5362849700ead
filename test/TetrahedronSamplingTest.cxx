// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of the scrambled Sobol sampling of tetrahedra.
#include "morea_core/TetrahedronSampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace
{
using morea_core::Vec3;

TEST(TetrahedronSampling, SobolPointsAreStratifiedInEveryDimension)
{
  // The first 2^k points of a (digitally shifted) Sobol sequence put exactly
  // one value of each coordinate in each interval [j/2^k, (j+1)/2^k).
  for (std::uint64_t seed : { 1u, 77u })
  {
    morea_core::ScrambledSobol4            sobol(seed);
    constexpr int                     n = 64;
    std::array<std::set<int>, 4>      cells;
    for (int i = 0; i < n; ++i)
    {
      const auto u = sobol.Next();
      for (int d = 0; d < 4; ++d)
      {
        ASSERT_GT(u[d], 0.0);
        ASSERT_LT(u[d], 1.0);
        cells[d].insert(static_cast<int>(u[d] * n));
      }
    }
    for (int d = 0; d < 4; ++d)
      EXPECT_EQ(cells[d].size(), static_cast<std::size_t>(n)) << "dimension " << d;
  }
  // Pairs of dimensions are stratified too (the Sobol (0,m,2) property for dims 1-2).
  morea_core::ScrambledSobol4        sobol(5);
  std::set<std::pair<int, int>> squares;
  for (int i = 0; i < 64; ++i)
  {
    const auto u = sobol.Next();
    squares.insert({ static_cast<int>(u[0] * 8), static_cast<int>(u[1] * 8) });
  }
  EXPECT_EQ(squares.size(), 64u);
}

TEST(TetrahedronSampling, SameSeedSameSamplesOtherSeedOtherSamples)
{
  morea_core::ScrambledSobol4 a(9), b(9), c(10);
  for (int i = 0; i < 10; ++i)
  {
    const auto ua = a.Next(), ub = b.Next(), uc = c.Next();
    EXPECT_EQ(ua, ub);
    EXPECT_NE(ua, uc);
  }
  const Vec3 p{ { 1, 2, 3 } }, q{ { 4, 2, 3 } }, r{ { 1, 6, 3 } }, s{ { 1, 2, 9 } };
  Vec3       nudged = s;
  nudged[2] = std::nextafter(nudged[2], 10.0);
  EXPECT_EQ(morea_core::TetrahedronSeed(p, q, r, s), morea_core::TetrahedronSeed(p, q, r, s));
  EXPECT_NE(morea_core::TetrahedronSeed(p, q, r, s), morea_core::TetrahedronSeed(p, q, r, nudged));
}

TEST(TetrahedronSampling, BarycentricSamplesFillTheTetrahedronUniformly)
{
  const Vec3             v[4] = { { { 0, 0, 0 } }, { { 6, 0, 0 } }, { { 0, 6, 0 } }, { { 0, 0, 6 } } };
  morea_core::ScrambledSobol4 sobol(morea_core::TetrahedronSeed(v[0], v[1], v[2], v[3]));
  Vec3                   mean{ { 0, 0, 0 } };
  constexpr int          n = 1024;
  int                    nearCorner = 0;
  for (int i = 0; i < n; ++i)
  {
    const auto w = morea_core::UniformBarycentric(sobol.Next());
    double     sum = 0.0;
    for (double x : w)
    {
      ASSERT_GT(x, 0.0);
      sum += x;
    }
    ASSERT_NEAR(sum, 1.0, 1e-12);
    Vec3 p{ { 0, 0, 0 } };
    for (int k = 0; k < 4; ++k)
      for (int a = 0; a < 3; ++a)
        p[a] += w[k] * v[k][a];
    for (int a = 0; a < 3; ++a)
      mean[a] += p[a] / n;
    // The corner region x+y+z < 3 holds 1/8 of the volume.
    nearCorner += (p[0] + p[1] + p[2] < 3.0);
  }
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(mean[a], 1.5, 0.03); // the centroid
  EXPECT_NEAR(nearCorner / double(n), 0.125, 0.015);
}
} // namespace
