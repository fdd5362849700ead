// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The fold repair's moves (RepairNoise.h): the hand-written logarithm and
// sine/cosine match the C library to double precision, and the normals are
// standard normal and a pure function of their key.
#include "morea_core/RepairNoise.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <set>

using namespace morea_core;

TEST(RepairNoise, LogarithmMatchesTheLibrary)
{
  for (double u : { 1.0, 0.5, 0.70710678118654752, 0.7071067811865476, 0.999999, 1e-300, 0x1.0p-53, 0.123456789 })
    EXPECT_NEAR(repair_noise::Log(u), std::log(u), 4e-16 * std::max(1.0, std::abs(std::log(u)))) << u;
  for (int i = 1; i <= 10000; ++i)
  {
    const double u = static_cast<double>(i) / 10000.0;
    EXPECT_NEAR(repair_noise::Log(u), std::log(u), 4e-16 * std::max(1.0, std::abs(std::log(u)))) << u;
  }
}

TEST(RepairNoise, CosineAndSineOfTurnsMatchTheLibrary)
{
  const double twoPi = 6.283185307179586476925286766559;
  for (int i = 0; i <= 10000; ++i)
  {
    const double u = static_cast<double>(i) / 10000.0;
    double       c = 0.0, s = 0.0;
    repair_noise::CosSinOfTurns(u, c, s);
    EXPECT_NEAR(c, std::cos(twoPi * u), 1e-15) << u;
    EXPECT_NEAR(s, std::sin(twoPi * u), 1e-15) << u;
  }
}

TEST(RepairNoise, NormalsAreStandardAndKeyed)
{
  double      sum = 0.0, squares = 0.0, fourth = 0.0;
  std::size_t n = 0, beyondTwo = 0;
  for (std::uint32_t trial = 0; trial < 64; ++trial)
    for (std::uint32_t point = 0; point < 500; ++point)
    {
      double v[3];
      RepairTrialNormals(12345, trial % 3, point, trial, v);
      for (double x : v)
      {
        sum += x;
        squares += x * x;
        fourth += x * x * x * x;
        beyondTwo += std::abs(x) > 2.0;
        ++n;
      }
    }
  const double count = static_cast<double>(n);
  EXPECT_NEAR(sum / count, 0.0, 0.02);
  EXPECT_NEAR(squares / count, 1.0, 0.03);
  EXPECT_NEAR(fourth / count, 3.0, 0.2);                           // Gaussian kurtosis
  EXPECT_NEAR(static_cast<double>(beyondTwo) / count, 0.0455, 0.006); // P(|x| > 2)

  // A pure function of (seed, pass, point, trial); each part of the key matters.
  double a[3], b[3];
  RepairTrialNormals(7, 1, 2, 3, a);
  RepairTrialNormals(7, 1, 2, 3, b);
  EXPECT_EQ(a[0], b[0]);
  EXPECT_EQ(a[2], b[2]);
  std::set<double> firsts;
  for (auto key : { std::array<std::uint32_t, 4>{ 7, 1, 2, 3 }, { 8, 1, 2, 3 }, { 7, 2, 2, 3 }, { 7, 1, 3, 3 },
                    { 7, 1, 2, 4 } })
  {
    RepairTrialNormals(key[0], key[1], key[2], key[3], a);
    firsts.insert(a[0]);
  }
  EXPECT_EQ(firsts.size(), 5u);
}
