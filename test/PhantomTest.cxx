// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of morea_core::PelvisPhantom: the analytic deformation and the generated case.
// Core tests: no ITK headers here.
#include "morea_core/Error.h"
#include "morea_core/Phantom.h"
#include "morea_core/Random.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace
{
using morea_core::PelvisPhantom;
using morea_core::PhantomOptions;
using morea_core::Vec3;

constexpr double kPi = 3.14159265358979323846;

// The phantom's domain (fixed frame), as documented for the tests.
constexpr double kLo[3] = { -170.0, -120.0, -80.0 };
constexpr double kHi[3] = { 170.0, 120.0, 70.0 };

enum Structure : std::size_t
{
  Body = 0,
  Bones = 1,
  Bladder = 2,
  Rectum = 3,
  Bowel = 4
};

double
Distance(const Vec3 & a, const Vec3 & b)
{
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

Vec3
RandomPoint(morea_core::RandomGenerator & g)
{
  return { g.Uniform(kLo[0], kHi[0]), g.Uniform(kLo[1], kHi[1]), g.Uniform(kLo[2], kHi[2]) };
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
    const Vec3 tp = phantom.FixedToMoving(plus);
    const Vec3 tm = phantom.FixedToMoving(minus);
    for (int r = 0; r < 3; ++r)
      j[r][c] = (tp[r] - tm[r]) / (2.0 * h);
  }
  return j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0]) +
         j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
}

PhantomOptions
Coarse(std::uint64_t seed = 1)
{
  PhantomOptions o;
  o.spacing = 4.0;
  o.seed = seed;
  return o;
}

/** One generated coarse case shared by the tests that only read it. */
const PelvisPhantom::Case &
SharedCase()
{
  static const PelvisPhantom::Case c = PelvisPhantom(Coarse()).Generate();
  return c;
}

std::size_t
CountOn(const morea_core::Volume<std::uint8_t> & mask)
{
  std::size_t n = 0;
  for (auto v : mask.data)
    n += v != 0;
  return n;
}
} // namespace

// ---------------------------------------------------------------------------
// The analytic deformation
// ---------------------------------------------------------------------------

TEST(Phantom, InverseUndoesTheForwardMappingEverywhere)
{
  const PelvisPhantom    phantom;
  morea_core::RandomGenerator g(5);
  double                 worst = 0.0;
  for (int n = 0; n < 20000; ++n)
  {
    const Vec3 x = RandomPoint(g);
    worst = std::max(worst, Distance(phantom.MovingToFixed(phantom.FixedToMoving(x)), x));
    // The other direction, for points of the moving frame.
    const Vec3 y = RandomPoint(g);
    worst = std::max(worst, Distance(phantom.FixedToMoving(phantom.MovingToFixed(y)), y));
  }
  EXPECT_LT(worst, 1e-6);
  // The bladder centre itself (rho = 0 branch) and points right on the bladder wall.
  for (const Vec3 & x : { Vec3{ { 0.0, -25.0, -15.0 } }, Vec3{ { 28.0, -25.0, -15.0 } },
                          Vec3{ { 0.0, -3.0, -15.0 } }, Vec3{ { 0.0, -25.0, 5.0 } } })
  {
    EXPECT_LT(Distance(phantom.MovingToFixed(phantom.FixedToMoving(x)), x), 1e-6);
  }
}

TEST(Phantom, InverseIsExactForTheLargestAllowedGrowth)
{
  PhantomOptions o;
  o.bladderGrowth = 2.35;
  const PelvisPhantom    phantom(o);
  morea_core::RandomGenerator g(6);
  for (int n = 0; n < 5000; ++n)
  {
    const Vec3 x = RandomPoint(g);
    ASSERT_LT(Distance(phantom.MovingToFixed(phantom.FixedToMoving(x)), x), 1e-6) << n;
  }
}

TEST(Phantom, DeformationIsADiffeomorphism)
{
  for (double growth : { 1.0, 1.9, 2.35 })
  {
    PhantomOptions o;
    o.bladderGrowth = growth;
    const PelvisPhantom    phantom(o);
    morea_core::RandomGenerator g(7);
    double                 smallest = std::numeric_limits<double>::infinity();
    for (int n = 0; n < 20000; ++n)
    {
      smallest = std::min(smallest, JacobianDeterminant(phantom, RandomPoint(g)));
    }
    // Points along the bladder's axes, through the wall where g changes form.
    for (double t = 0.0; t <= 4.0; t += 0.01)
    {
      smallest = std::min(smallest, JacobianDeterminant(phantom, { { 28.0 * t, -25.0, -15.0 } }));
      smallest = std::min(smallest, JacobianDeterminant(phantom, { { 0.0, -25.0 - 22.0 * t, -15.0 } }));
      smallest = std::min(smallest, JacobianDeterminant(phantom, { { 0.0, -25.0, -15.0 + 20.0 * t } }));
    }
    EXPECT_GT(smallest, 0.0) << "growth " << growth;
  }
}

TEST(Phantom, BladderGrowsUniformlyInside)
{
  const PelvisPhantom phantom; // growth 1.9
  const double        k = phantom.Options().bladderGrowth;
  // Inside the bladder T is a scaling by k followed by a rigid motion: det J = k^3.
  EXPECT_NEAR(JacobianDeterminant(phantom, { { 0.0, -25.0, -15.0 } }), k * k * k, 1e-4);
  EXPECT_NEAR(JacobianDeterminant(phantom, { { 10.0, -20.0, -10.0 } }), k * k * k, 1e-4);
  // Distances from the bladder centre to its wall scale by k.
  const Vec3 centre{ { 0.0, -25.0, -15.0 } };
  const Vec3 dome{ { 0.0, -25.0, 4.0 } };
  EXPECT_NEAR(Distance(phantom.FixedToMoving(dome), phantom.FixedToMoving(centre)), k * 19.0, 1e-9);
  // Far from the bladder the deformation is negligible: det J = 1 (rigid).
  EXPECT_NEAR(JacobianDeterminant(phantom, { { 160.0, 110.0, 65.0 } }), 1.0, 1e-4);
}

TEST(Phantom, RigidPartFollowsTheDocumentedConvention)
{
  // With no bladder growth, T is exactly the rigid motion R x + t.
  PhantomOptions o;
  o.bladderGrowth = 1.0;
  o.translation = { { 0.0, 0.0, 0.0 } };
  o.rotationDegrees = { { 0.0, 0.0, 90.0 } };
  {
    const PelvisPhantom phantom(o);
    const Vec3          y = phantom.FixedToMoving({ { 10.0, 0.0, 0.0 } });
    EXPECT_NEAR(y[0], 0.0, 1e-9);
    EXPECT_NEAR(y[1], 10.0, 1e-9); // +90 degrees about z turns x into y
    EXPECT_NEAR(y[2], 0.0, 1e-9);
  }
  o.rotationDegrees = { { 90.0, 0.0, 0.0 } };
  {
    const PelvisPhantom phantom(o);
    const Vec3          y = phantom.FixedToMoving({ { 0.0, 10.0, 0.0 } });
    EXPECT_NEAR(y[0], 0.0, 1e-9);
    EXPECT_NEAR(y[1], 0.0, 1e-9);
    EXPECT_NEAR(y[2], 10.0, 1e-9); // +90 degrees about x turns y into z
  }
  o.rotationDegrees = { { 0.0, 0.0, 0.0 } };
  o.translation = { { 4.0, -7.0, 12.0 } };
  {
    const PelvisPhantom    phantom(o);
    morea_core::RandomGenerator g(8);
    for (int n = 0; n < 100; ++n)
    {
      const Vec3 x = RandomPoint(g);
      const Vec3 y = phantom.FixedToMoving(x);
      for (int d = 0; d < 3; ++d)
        ASSERT_NEAR(y[d] - x[d], o.translation[d], 1e-9);
    }
  }
  // The default motion is a proper rigid motion away from the bladder: it keeps distances between far points.
  PhantomOptions rigid;
  rigid.bladderGrowth = 1.0;
  const PelvisPhantom    phantom(rigid);
  morea_core::RandomGenerator g(9);
  for (int n = 0; n < 100; ++n)
  {
    const Vec3 a = RandomPoint(g), b = RandomPoint(g);
    ASSERT_NEAR(Distance(phantom.FixedToMoving(a), phantom.FixedToMoving(b)), Distance(a, b), 1e-9);
  }
  // ... and moves the origin by the translation.
  const Vec3 t = phantom.FixedToMoving({ { 0.0, 0.0, 0.0 } });
  for (int d = 0; d < 3; ++d)
    EXPECT_NEAR(t[d], rigid.translation[d], 1e-9);
}

TEST(Phantom, BonesBarelyDeform)
{
  const PelvisPhantom phantom;
  const Vec3          right{ { -90.0, 0.0, -35.0 } }, left{ { 90.0, 0.0, -35.0 } };
  ASSERT_TRUE(phantom.InStructure(Bones, right));
  ASSERT_TRUE(phantom.InStructure(Bones, left));
  const double before = Distance(right, left);
  const double after = Distance(phantom.FixedToMoving(right), phantom.FixedToMoving(left));
  EXPECT_LT(std::abs(after - before), 0.5);
  // The sacrum, furthest from the bladder, moves rigidly to within 0.05 mm.
  const Vec3 s1{ { 0.0, 85.0, 15.0 } }, s2{ { 0.0, 85.0, -25.0 } };
  EXPECT_LT(std::abs(Distance(phantom.FixedToMoving(s1), phantom.FixedToMoving(s2)) - Distance(s1, s2)), 0.05);
  // The bladder, by contrast, deforms a lot: its dome moves by centimetres relative to the femoral head.
  const Vec3 dome{ { 0.0, -25.0, 4.0 } };
  EXPECT_GT(std::abs(Distance(phantom.FixedToMoving(dome), phantom.FixedToMoving(right)) - Distance(dome, right)),
            5.0);
}

TEST(Phantom, StructureMembershipAndHounsfieldValues)
{
  const PelvisPhantom phantom;
  EXPECT_EQ(PelvisPhantom::StructureNames(),
            (std::vector<std::string>{ "body", "bones", "bladder", "rectum", "bowel" }));
  EXPECT_TRUE(phantom.InStructure(Bladder, { { 0.0, -25.0, -15.0 } }));
  EXPECT_FALSE(phantom.InStructure(Bladder, { { 0.0, -25.0, 6.0 } }));
  EXPECT_TRUE(phantom.InStructure(Body, { { 0.0, 0.0, 0.0 } }));
  EXPECT_FALSE(phantom.InStructure(Body, { { 165.0, 0.0, 0.0 } }));
  EXPECT_DOUBLE_EQ(phantom.HounsfieldAt({ { 165.0, 0.0, 0.0 } }), -1000.0); // air
  // bone: trabecular texture between 300 and 800 HU, varying within the bone
  const double boneA = phantom.HounsfieldAt({ { 90.0, 0.0, -35.0 } });
  const double boneB = phantom.HounsfieldAt({ { 92.0, 3.0, -31.0 } });
  EXPECT_GE(boneA, 300.0);
  EXPECT_LE(boneA, 800.0);
  EXPECT_GE(boneB, 300.0);
  EXPECT_LE(boneB, 800.0);
  EXPECT_GT(std::abs(boneA - boneB), 1.0);
  EXPECT_DOUBLE_EQ(phantom.HounsfieldAt({ { 0.0, -25.0, -15.0 } }), 5.0);   // urine
  EXPECT_THROW(phantom.InStructure(5, { { 0.0, 0.0, 0.0 } }), morea_core::Error);
}

TEST(Phantom, InvalidOptionsThrow)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double spacing : { 0.0, 0.1, -2.0, 10.5, nan })
  {
    PhantomOptions o;
    o.spacing = spacing;
    EXPECT_THROW(PelvisPhantom{ o }, morea_core::Error) << "spacing " << spacing;
  }
  // Above about 2.4 the radial profile is no longer monotonic and T folds.
  for (double growth : { 0.99, 0.0, 2.4, 2.5, nan })
  {
    PhantomOptions o;
    o.bladderGrowth = growth;
    EXPECT_THROW(PelvisPhantom{ o }, morea_core::Error) << "growth " << growth;
  }
  for (double noise : { -1.0, nan })
  {
    PhantomOptions o;
    o.noiseSigma = noise;
    EXPECT_THROW(PelvisPhantom{ o }, morea_core::Error) << "noise " << noise;
  }
  // The limits themselves are valid.
  PhantomOptions o;
  o.spacing = 10.0;
  o.bladderGrowth = 1.0;
  o.noiseSigma = 0.0;
  EXPECT_NO_THROW(PelvisPhantom{ o });
  o.spacing = 0.25;
  o.bladderGrowth = 2.35;
  EXPECT_NO_THROW(PelvisPhantom{ o });
}

// ---------------------------------------------------------------------------
// The generated case
// ---------------------------------------------------------------------------

TEST(Phantom, GeneratedGridCoversTheDomain)
{
  const auto & c = SharedCase();
  EXPECT_EQ(c.fixedImage.size[0], 86u); // 340 mm / 4 + 1
  EXPECT_EQ(c.fixedImage.size[1], 61u);
  EXPECT_EQ(c.fixedImage.size[2], 38u);
  for (int d = 0; d < 3; ++d)
  {
    EXPECT_DOUBLE_EQ(c.fixedImage.spacing[d], 4.0);
    EXPECT_DOUBLE_EQ(c.fixedImage.origin[d], kLo[d]);
  }
  const std::size_t n = c.fixedImage.NumberOfVoxels();
  EXPECT_EQ(c.fixedImage.data.size(), n);
  EXPECT_EQ(c.movingImage.size, c.fixedImage.size);
  EXPECT_EQ(c.movingImage.data.size(), n);
  EXPECT_EQ(c.fixedToMoving.data.size(), n);
  EXPECT_EQ(c.movingToFixed.data.size(), n);
  ASSERT_EQ(c.fixedMasks.size(), PelvisPhantom::StructureNames().size());
  ASSERT_EQ(c.movingMasks.size(), PelvisPhantom::StructureNames().size());
  for (std::size_t s = 0; s < c.fixedMasks.size(); ++s)
  {
    EXPECT_EQ(c.fixedMasks[s].data.size(), n);
    EXPECT_EQ(c.movingMasks[s].data.size(), n);
    EXPECT_GT(CountOn(c.fixedMasks[s]), 0u) << PelvisPhantom::StructureNames()[s];
    EXPECT_GT(CountOn(c.movingMasks[s]), 0u) << PelvisPhantom::StructureNames()[s];
  }
}

TEST(Phantom, BladderVolumeGrowsByTheCubeOfTheGrowth)
{
  const auto &   c = SharedCase();
  const double   k = Coarse().bladderGrowth;
  const double   fixedVoxels = static_cast<double>(CountOn(c.fixedMasks[Bladder]));
  const double   movingVoxels = static_cast<double>(CountOn(c.movingMasks[Bladder]));
  const double   voxel = 4.0 * 4.0 * 4.0;
  const double   analytic = 4.0 / 3.0 * kPi * 28.0 * 22.0 * 20.0; // the fixed bladder's ellipsoid
  EXPECT_NEAR(fixedVoxels * voxel / analytic, 1.0, 0.1);
  EXPECT_NEAR(movingVoxels / fixedVoxels / (k * k * k), 1.0, 0.1);
  // The bones keep their volume (rigid), up to voxelisation.
  const double bonesRatio =
    static_cast<double>(CountOn(c.movingMasks[Bones])) / static_cast<double>(CountOn(c.fixedMasks[Bones]));
  EXPECT_NEAR(bonesRatio, 1.0, 0.05);
}

TEST(Phantom, GenerateIsDeterministicAndTheSeedOnlyChangesTheNoise)
{
  const auto & a = SharedCase();
  const auto   b = PelvisPhantom(Coarse(1)).Generate();
  EXPECT_EQ(a.fixedImage.data, b.fixedImage.data);
  EXPECT_EQ(a.movingImage.data, b.movingImage.data);
  for (std::size_t s = 0; s < a.fixedMasks.size(); ++s)
  {
    EXPECT_EQ(a.fixedMasks[s].data, b.fixedMasks[s].data);
    EXPECT_EQ(a.movingMasks[s].data, b.movingMasks[s].data);
  }

  const auto  other = PelvisPhantom(Coarse(2)).Generate();
  std::size_t differentFixed = 0, differentMoving = 0, insideView = 0;
  for (std::size_t o = 0; o < a.fixedImage.data.size(); ++o)
  {
    if (a.fixedImage.data[o] == PelvisPhantom::OutsideFieldOfView)
    {
      EXPECT_EQ(other.fixedImage.data[o], PelvisPhantom::OutsideFieldOfView);
      continue;
    }
    ++insideView;
    differentFixed += a.fixedImage.data[o] != other.fixedImage.data[o];
    differentMoving += a.movingImage.data[o] != other.movingImage.data[o];
  }
  EXPECT_GT(differentFixed, insideView * 99 / 100);
  EXPECT_GT(differentMoving, insideView * 99 / 100);
  for (std::size_t s = 0; s < a.fixedMasks.size(); ++s)
  {
    EXPECT_EQ(a.fixedMasks[s].data, other.fixedMasks[s].data); // the anatomy does not depend on the seed
  }
  // The fixed and moving noise are independent draws, not the same field.
  std::size_t sameNoise = 0;
  for (std::size_t o = 0; o < a.fixedImage.data.size(); ++o)
  {
    if (a.fixedImage.data[o] != PelvisPhantom::OutsideFieldOfView)
    {
      const float nf = a.fixedImage.data[o] - other.fixedImage.data[o];
      const float nm = a.movingImage.data[o] - other.movingImage.data[o];
      sameNoise += nf == nm;
    }
  }
  EXPECT_LT(sameNoise, insideView / 100);
}

TEST(Phantom, ImagesAreTheAnatomyPlusGaussianNoise)
{
  const PelvisPhantom phantom(Coarse());
  const auto &        c = SharedCase();
  double              sum = 0.0, sum2 = 0.0;
  std::size_t         n = 0, outside = 0;
  for (std::size_t k = 0; k < c.fixedImage.size[2]; ++k)
    for (std::size_t j = 0; j < c.fixedImage.size[1]; ++j)
      for (std::size_t i = 0; i < c.fixedImage.size[0]; ++i)
      {
        const Vec3 p = c.fixedImage.PointAt(i, j, k);
        const bool inView = p[0] * p[0] + p[1] * p[1] <= 180.0 * 180.0;
        if (!inView)
        {
          ASSERT_EQ(c.fixedImage(i, j, k), PelvisPhantom::OutsideFieldOfView);
          ASSERT_EQ(c.movingImage(i, j, k), PelvisPhantom::OutsideFieldOfView);
          ++outside;
          continue;
        }
        const double e = c.fixedImage(i, j, k) - phantom.HounsfieldAt(p);
        sum += e;
        sum2 += e * e;
        ++n;
      }
  EXPECT_GT(outside, 0u); // the domain's corners lie outside the 180 mm field of view
  const double mean = sum / static_cast<double>(n);
  const double sd = std::sqrt(sum2 / static_cast<double>(n) - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.3);
  EXPECT_NEAR(sd, Coarse().noiseSigma, 0.3);

  // Without noise the moving image is exactly the anatomy carried by T.
  PhantomOptions o = Coarse();
  o.noiseSigma = 0.0;
  o.spacing = 8.0;
  const PelvisPhantom clean(o);
  const auto          cc = clean.Generate();
  for (std::size_t k = 0; k < cc.movingImage.size[2]; ++k)
    for (std::size_t j = 0; j < cc.movingImage.size[1]; ++j)
      for (std::size_t i = 0; i < cc.movingImage.size[0]; ++i)
      {
        const Vec3 p = cc.movingImage.PointAt(i, j, k);
        if (p[0] * p[0] + p[1] * p[1] > 180.0 * 180.0)
          continue;
        ASSERT_EQ(cc.fixedImage(i, j, k), static_cast<float>(clean.HounsfieldAt(p)));
        ASSERT_EQ(cc.movingImage(i, j, k), static_cast<float>(clean.HounsfieldAt(clean.MovingToFixed(p))));
      }
}

TEST(Phantom, TrueFieldsAndMasksMatchTheAnalyticMapping)
{
  const PelvisPhantom phantom(Coarse());
  const auto &        c = SharedCase();
  double              worstForward = 0.0, worstBackward = 0.0;
  std::size_t         maskMismatches = 0;
  for (std::size_t k = 0; k < c.fixedImage.size[2]; k += 3)
    for (std::size_t j = 0; j < c.fixedImage.size[1]; j += 2)
      for (std::size_t i = 0; i < c.fixedImage.size[0]; ++i)
      {
        const Vec3        p = c.fixedImage.PointAt(i, j, k);
        const std::size_t o = c.fixedImage.Offset(i, j, k);
        const Vec3        t = phantom.FixedToMoving(p);
        const Vec3        ti = phantom.MovingToFixed(p);
        for (int d = 0; d < 3; ++d)
        {
          worstForward = std::max(worstForward, std::abs(c.fixedToMoving.data[o][d] - (t[d] - p[d])));
          worstBackward = std::max(worstBackward, std::abs(c.movingToFixed.data[o][d] - (ti[d] - p[d])));
        }
        for (std::size_t s = 0; s < c.fixedMasks.size(); ++s)
        {
          maskMismatches += (c.fixedMasks[s].data[o] != 0) != phantom.InStructure(s, p);
          maskMismatches += (c.movingMasks[s].data[o] != 0) != phantom.InStructure(s, ti);
        }
      }
  EXPECT_LT(worstForward, 1e-9);
  EXPECT_LT(worstBackward, 1e-9);
  EXPECT_EQ(maskMismatches, 0u);

  // The two fields are inverse to each other: u(x) at a voxel centre carries x to T(x), and v(T(x)) = -u(x).
  const Vec3 x = c.fixedImage.PointAt(43, 24, 16);
  const auto & u = c.fixedToMoving(43, 24, 16);
  const Vec3   y{ { x[0] + u[0], x[1] + u[1], x[2] + u[2] } };
  const Vec3   back = phantom.MovingToFixed(y);
  EXPECT_LT(Distance(back, x), 1e-6);
}

TEST(Phantom, LandmarksAreCarriedByTheDeformation)
{
  const PelvisPhantom phantom(Coarse());
  const auto &        c = SharedCase();
  ASSERT_EQ(c.fixedLandmarks.size(), 19u);
  ASSERT_EQ(c.movingLandmarks.size(), c.fixedLandmarks.size());
  for (std::size_t n = 0; n < c.fixedLandmarks.size(); ++n)
  {
    const Vec3 t = phantom.FixedToMoving(c.fixedLandmarks[n]);
    EXPECT_LT(Distance(c.movingLandmarks[n], t), 1e-12) << "landmark " << n;
    EXPECT_LT(Distance(phantom.MovingToFixed(c.movingLandmarks[n]), c.fixedLandmarks[n]), 1e-6) << "landmark " << n;
  }
  // The landmarks lie in the structures their comments name.
  for (std::size_t n = 0; n < 9; ++n)
    EXPECT_TRUE(phantom.InStructure(Bones, c.fixedLandmarks[n])) << "bone landmark " << n;
  for (std::size_t n = 9; n < 13; ++n)
    EXPECT_TRUE(phantom.InStructure(Bladder, c.fixedLandmarks[n])) << "bladder landmark " << n;
  for (std::size_t n = 13; n < 16; ++n)
    EXPECT_TRUE(phantom.InStructure(Rectum, c.fixedLandmarks[n])) << "rectum landmark " << n;
  for (std::size_t n = 16; n < 19; ++n)
    EXPECT_TRUE(phantom.InStructure(Bowel, c.fixedLandmarks[n])) << "bowel landmark " << n;
  // Bladder wall landmarks move by centimetres.
  EXPECT_GT(Distance(c.movingLandmarks[9], c.fixedLandmarks[9]), 20.0);
}
