// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The phantom suite's cases besides "pelvis" (PhantomTest.cxx): the
// documented volumes and displacements, bones that do not move, content in
// one image only, landmarks of every kind, and a truth that is consistent:
// an invertible mapping whose fields, masks and landmarks agree with it.
#include "morea_core/Error.h"
#include "morea_core/Phantom.h"
#include "morea_core/Random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

namespace
{
using morea_core::PelvisPhantom;
using morea_core::PhantomOptions;
using morea_core::Vec3;

enum Structure : std::size_t
{
  Body = 0,
  Bones = 1,
  Bladder = 2,
  Rectum = 3,
  Bowel = 4
};

const std::vector<std::string> kSuiteCases = { "bladder-emptying", "gas-pocket", "static-bones" };

double
Distance(const Vec3 & a, const Vec3 & b)
{
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

PhantomOptions
Coarse(const std::string & name, double noise = 15.0)
{
  PhantomOptions o = PhantomOptions::OfCase(name);
  o.spacing = 3.0;
  o.noiseSigma = noise;
  return o;
}

/** Generated cases shared by the tests that only read them. */
const PelvisPhantom::Case &
SharedCase(const std::string & name)
{
  static std::map<std::string, PelvisPhantom::Case> cases;
  auto                                              it = cases.find(name);
  if (it == cases.end())
    it = cases.emplace(name, PelvisPhantom(Coarse(name)).Generate()).first;
  return it->second;
}

std::size_t
Voxels(const morea_core::Volume<std::uint8_t> & mask)
{
  return static_cast<std::size_t>(std::count_if(mask.data.begin(), mask.data.end(), [](std::uint8_t v) { return v != 0; }));
}

/** det dT/dx by central differences. */
double
JacobianDeterminant(const PelvisPhantom & phantom, const Vec3 & x, double h = 1e-3)
{
  double j[3][3];
  for (int c = 0; c < 3; ++c)
  {
    Vec3 plus = x, minus = x;
    plus[c] += h;
    minus[c] -= h;
    const Vec3 tp = phantom.FixedToMoving(plus), tm = phantom.FixedToMoving(minus);
    for (int r = 0; r < 3; ++r)
      j[r][c] = (tp[r] - tm[r]) / (2.0 * h);
  }
  return j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0]) +
         j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
}
} // namespace

TEST(PhantomSuite, CasesAreNamedAndCheckedLikeThePelvis)
{
  EXPECT_EQ(PelvisPhantom::CaseNames(),
            (std::vector<std::string>{ "pelvis", "bladder-emptying", "gas-pocket", "static-bones" }));
  // The pelvis's defaults are the plain options: its output stays as it was.
  const PhantomOptions pelvis = PhantomOptions::OfCase("pelvis"), plain;
  EXPECT_EQ(pelvis.bladderGrowth, plain.bladderGrowth);
  EXPECT_EQ(pelvis.translation, plain.translation);
  EXPECT_EQ(pelvis.rotationDegrees, plain.rotationDegrees);
  for (const std::string & name : kSuiteCases)
  {
    const PhantomOptions o = PhantomOptions::OfCase(name);
    EXPECT_EQ(o.translation, (Vec3{ { 0.0, 0.0, 0.0 } })) << name;
    EXPECT_EQ(o.rotationDegrees, (Vec3{ { 0.0, 0.0, 0.0 } })) << name;
  }
  EXPECT_THROW(PhantomOptions::OfCase("knee"), morea_core::Error);
  PhantomOptions bad = PhantomOptions::OfCase("bladder-emptying");
  bad.bladderGrowth = 1.2; // emptying grows nothing
  EXPECT_THROW(PelvisPhantom{ bad }, morea_core::Error);
  bad = PhantomOptions::OfCase("static-bones");
  bad.bladderGrowth = 2.2; // beyond what its reach keeps monotone
  EXPECT_THROW(PelvisPhantom{ bad }, morea_core::Error);
  bad.caseName = "knee";
  EXPECT_THROW(PelvisPhantom{ bad }, morea_core::Error);
}

TEST(PhantomSuite, EveryCaseIsADiffeomorphismWithAnExactInverse)
{
  for (const std::string & name : kSuiteCases)
  {
    const PelvisPhantom    phantom(PhantomOptions::OfCase(name));
    morea_core::RandomGenerator g(7);
    double                 worst = 0.0, smallestDeterminant = 1e300;
    const Vec3 &           c = phantom.DeformationCentre();
    const Vec3 &           a = phantom.DeformationAxes();
    for (int n = 0; n < 20000; ++n)
    {
      // Half the points within the deformation's reach, where it acts.
      const double r = phantom.DeformationReach();
      Vec3         x;
      for (int d = 0; d < 3; ++d)
        x[d] = n % 2 ? g.Uniform(-170.0, 170.0) * (d == 2 ? 0.45 : 0.7) : c[d] + a[d] * r * g.Uniform(-0.8, 0.8);
      worst = std::max(worst, Distance(phantom.MovingToFixed(phantom.FixedToMoving(x)), x));
      worst = std::max(worst, Distance(phantom.FixedToMoving(phantom.MovingToFixed(x)), x));
      if (n % 10 == 0)
        smallestDeterminant = std::min(smallestDeterminant, JacobianDeterminant(phantom, x));
    }
    EXPECT_LT(worst, 1e-6) << name;
    EXPECT_GT(smallestDeterminant, 0.0) << name;
  }
}

TEST(PhantomSuite, BladderEmptiesByAFactorOfThreeOrMoreAndTheBowelDescends)
{
  const auto & c = SharedCase("bladder-emptying");
  const double full = static_cast<double>(Voxels(c.fixedMasks[Bladder]));
  const double empty = static_cast<double>(Voxels(c.movingMasks[Bladder]));
  EXPECT_GE(full / empty, 3.0);
  // The largest displacement of the bladder wall, over its mask's voxels.
  double largest = 0.0;
  for (std::size_t o = 0; o < c.fixedMasks[Bladder].data.size(); ++o)
    if (c.fixedMasks[Bladder].data[o])
    {
      const Vec3 & u = c.fixedToMoving.data[o];
      largest = std::max(largest, std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]));
    }
  EXPECT_GE(largest, 25.0);
  // The bowel resting on the full bladder's dome follows it down into the
  // space, and the two organs never overlap.
  std::size_t overlap = 0;
  for (std::size_t o = 0; o < c.fixedMasks[Bladder].data.size(); ++o)
    overlap += c.fixedMasks[Bladder].data[o] && c.fixedMasks[Bowel].data[o];
  EXPECT_EQ(overlap, 0u);
  double descent = 0.0;
  for (std::size_t o = 0; o < c.fixedMasks[Bowel].data.size(); ++o)
    if (c.fixedMasks[Bowel].data[o])
      descent = std::max(descent, -c.fixedToMoving.data[o][2]);
  EXPECT_GE(descent, 15.0);
}

TEST(PhantomSuite, GasPocketAppearsInTheMovingImageOnly)
{
  const PelvisPhantom phantom(Coarse("gas-pocket", 0.0));
  const auto          c = phantom.Generate();
  const Vec3 &        centre = phantom.DeformationCentre();
  // The fixed image holds rectal content there, the moving image gas where T carries it.
  EXPECT_EQ(phantom.HounsfieldAt(centre), 50.0);
  EXPECT_EQ(phantom.MovingHounsfieldAt(centre), -900.0);
  std::size_t fixedGas = 0, movingGas = 0;
  for (std::size_t k = 0; k < c.fixedImage.size[2]; ++k)
    for (std::size_t j = 0; j < c.fixedImage.size[1]; ++j)
      for (std::size_t i = 0; i < c.fixedImage.size[0]; ++i)
      {
        const Vec3 p = c.fixedImage.PointAt(i, j, k);
        if (Distance(p, centre) > 9.0)
          continue;
        fixedGas += c.fixedImage(i, j, k) < -500.0f;
        movingGas += c.movingImage(i, j, k) < -500.0f;
      }
  EXPECT_EQ(fixedGas, 0u);
  // A ball of about 9 mm radius (10.5 mm in the pocket) on a 3 mm grid: about 113 voxels.
  EXPECT_GT(movingGas, 90u);
  // The wall is pushed aside by centimetres; the rectum stays one structure around the pocket.
  const Vec3 wall{ { centre[0] + 3.0, centre[1], centre[2] } };
  EXPECT_GT(Distance(phantom.FixedToMoving(wall), wall), 6.0);
  EXPECT_TRUE(phantom.InStructure(Rectum, centre));
}

TEST(PhantomSuite, BonesDoNotMove)
{
  for (const std::string & name : kSuiteCases)
  {
    const auto & c = SharedCase(name);
    std::size_t  boneVoxels = 0, moved = 0;
    for (std::size_t o = 0; o < c.fixedMasks[Bones].data.size(); ++o)
      if (c.fixedMasks[Bones].data[o])
      {
        ++boneVoxels;
        const Vec3 & u = c.fixedToMoving.data[o];
        moved += u[0] != 0.0 || u[1] != 0.0 || u[2] != 0.0;
      }
    EXPECT_GT(boneVoxels, 1000u) << name;
    EXPECT_EQ(moved, 0u) << name;
    EXPECT_EQ(c.fixedMasks[Bones].data, c.movingMasks[Bones].data) << name;
  }
}

TEST(PhantomSuite, LandmarksOfEveryKindFollowTheTruth)
{
  for (const std::string & name : kSuiteCases)
  {
    const PelvisPhantom phantom(Coarse(name));
    const auto &        c = SharedCase(name);
    ASSERT_GE(c.fixedLandmarks.size(), 40u) << name;
    ASSERT_EQ(c.landmarkKinds.size(), c.fixedLandmarks.size()) << name;
    ASSERT_EQ(c.movingLandmarks.size(), c.fixedLandmarks.size()) << name;
    std::map<std::string, std::size_t> count;
    for (std::size_t n = 0; n < c.fixedLandmarks.size(); ++n)
    {
      const Vec3 &        x = c.fixedLandmarks[n];
      const std::string & kind = c.landmarkKinds[n];
      ++count[kind];
      EXPECT_LT(Distance(c.movingLandmarks[n], phantom.FixedToMoving(x)), 1e-12) << name << " " << n;
      EXPECT_LT(Distance(phantom.MovingToFixed(c.movingLandmarks[n]), x), 1e-6) << name << " " << n;
      if (kind == "bone")
      {
        EXPECT_TRUE(phantom.InStructure(Bones, x)) << name << " " << n;
        EXPECT_EQ(Distance(c.movingLandmarks[n], x), 0.0) << name << " bone landmark " << n << " moved";
      }
      else if (kind == "soft")
      {
        EXPECT_TRUE(phantom.InStructure(Body, x)) << name << " " << n;
        for (std::size_t s = Bones; s <= Bowel; ++s)
          EXPECT_FALSE(phantom.InStructure(s, x)) << name << " " << n;
      }
      else if (kind == "wall")
      {
        // On an organ's wall: of the points 1.5 mm away along the axes, some
        // lie inside the bladder or the rectum and some outside it.
        bool onWall = false;
        for (std::size_t organ : { Bladder, Rectum })
        {
          int inside = 0;
          for (int a = 0; a < 3; ++a)
            for (double step : { -1.5, 1.5 })
            {
              Vec3 q = x;
              q[a] += step;
              inside += phantom.InStructure(organ, q);
            }
          onWall = onWall || (inside > 0 && inside < 6);
        }
        EXPECT_TRUE(onWall) << name << " wall landmark " << n;
      }
      else
        EXPECT_EQ(kind, "organ") << name;
    }
    EXPECT_GE(count["bone"], 10u) << name;
    EXPECT_GE(count["wall"], 10u) << name;
    EXPECT_GE(count["organ"], 5u) << name;
    EXPECT_GE(count["soft"], 10u) << name;
  }
}
