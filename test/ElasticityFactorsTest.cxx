// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of the per-tetrahedron elasticity factors.
#include "MeshTestSupport.h"

#include "morea_core/ElasticityFactors.h"
#include "morea_core/Error.h"
#include "morea_core/Tetrahedralization.h"

#include <gtest/gtest.h>

namespace
{
using morea_core::Vec3;

TEST(ElasticityFactors, HalfCoveredBoxAveragesTheFactors)
{
  // A 20 mm cube meshed from its corners and centre; the mask covers x < 10.
  morea_core::TetrahedralMesh mesh;
  mesh.domain.upper = { { 20, 20, 20 } };
  auto points = morea_core::DomainCorners(mesh.domain);
  points.push_back({ { 10, 10, 10 } });
  const auto t = morea_core::Tetrahedralize(points);
  mesh.points = t.points;
  mesh.tetrahedra = t.tetrahedra;
  morea_core::Volume<std::uint8_t> mask({ { 41, 41, 41 } }, { { 0.5, 0.5, 0.5 } }, { { 0, 0, 0 } });
  for (std::size_t k = 0; k < 41; ++k)
    for (std::size_t j = 0; j < 41; ++j)
      for (std::size_t i = 0; i < 41; ++i)
        mask(i, j, k) = mask.PointAt(i, j, k)[0] < 10.0;

  const auto fractions = morea_core::StructureOverlapFractions(mesh, { &mask });
  double     covered = 0.0, volume = 0.0;
  for (std::size_t k = 0; k < mesh.NumberOfTetrahedra(); ++k)
  {
    const double v = morea_core::SignedVolume(mesh.tetrahedra[k], mesh.points);
    covered += fractions[0][k] * v;
    volume += v;
  }
  EXPECT_NEAR(covered / volume, 0.5, 0.03);

  const auto factors = morea_core::ComputeElasticityFactors(mesh, { { "soft", &mask, 3.0 } });
  double     weighted = 0.0;
  for (std::size_t k = 0; k < mesh.NumberOfTetrahedra(); ++k)
  {
    EXPECT_GE(factors[k], 1.0);
    EXPECT_LE(factors[k], 3.0);
    EXPECT_NEAR(factors[k], 1.0 + 2.0 * fractions[0][k], 1e-12);
    weighted += factors[k] * morea_core::SignedVolume(mesh.tetrahedra[k], mesh.points);
  }
  EXPECT_NEAR(weighted / volume, 2.0, 0.06);
  // Two masks over the same region: there the mean of their factors applies.
  const auto both = morea_core::ComputeElasticityFactors(mesh, { { "a", &mask, 3.0 }, { "b", &mask, 5.0 } });
  for (std::size_t k = 0; k < mesh.NumberOfTetrahedra(); ++k)
    EXPECT_NEAR(both[k], 1.0 + fractions[0][k] * (0.5 * 3.0 + 0.5 * 5.0 - 1.0), 1e-12);
  EXPECT_THROW(morea_core::ComputeElasticityFactors(mesh, { { "bad", &mask, 0.0 } }), morea_core::Error);
}

TEST(ElasticityFactors, PhantomBonesAndBladder)
{
  const auto & pm = morea_test::PhantomMesh600();
  const auto & masks = pm.phantomCase.movingMasks; // body, bones, bladder, rectum, bowel
  const auto   parsed = morea_core::ParseElasticityFactors("bones=10, bladder=0.5");
  ASSERT_EQ(parsed.size(), 2u);
  const auto factors =
    morea_core::ComputeElasticityFactors(pm.mesh, { { "bones", &masks[1], parsed[0].second }, { "bladder", &masks[2], parsed[1].second } });
  double lowest = 1e9, highest = 0.0;
  for (double f : factors)
  {
    lowest = std::min(lowest, f);
    highest = std::max(highest, f);
  }
  // Tetrahedra inside the bladder (its surface is a constraint) are pure bladder.
  EXPECT_NEAR(lowest, 0.5, 0.02);
  EXPECT_GT(highest, 5.0);
  EXPECT_THROW(morea_core::ParseElasticityFactors("bones=-1"), morea_core::Error);
}
} // namespace
