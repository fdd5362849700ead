// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of the deformation magnitude objective.
#include "MeshTestSupport.h"

#include "morea_core/Error.h"
#include "morea_core/InitialPopulation.h"
#include "morea_core/MagnitudeObjective.h"

#include <gtest/gtest.h>

#include <cmath>

namespace
{
using morea_core::Vec3;

TEST(MagnitudeObjective, ScalingAUnitTetrahedronByTwo)
{
  // Edges 1,1,1,sqrt2,sqrt2,sqrt2; spokes sqrt(3/16) and 3 x sqrt(11/16).
  // Doubling every length: sum of squared differences = 3 + 6 + 3/16 + 33/16 = 11.25.
  const std::vector<Vec3>         source{ { { 0, 0, 0 } }, { { 1, 0, 0 } }, { { 0, 1, 0 } }, { { 0, 0, 1 } } };
  std::vector<Vec3>               target;
  for (const Vec3 & p : source)
    target.push_back({ { 2 * p[0] + 5, 2 * p[1], 2 * p[2] - 1 } });
  const morea_core::MeshTopology topology({ { { 0, 1, 2, 3 } } }, 4);
  EXPECT_NEAR(morea_core::TetrahedronMagnitude(topology.Tetrahedra()[0], source, target, 2.0), 22.5, 1e-12);
  EXPECT_NEAR(morea_core::MagnitudeObjective(topology, { source, target }, { 2.0 }), 2.25, 1e-12);
  EXPECT_THROW(morea_core::MagnitudeObjective(topology, { source, target }, { 1.0, 2.0 }), morea_core::Error);
}

TEST(MagnitudeObjective, RigidMotionsCostNothingAndPartsSumToTheWhole)
{
  const auto &              pm = morea_test::PhantomMesh600();
  const morea_core::MeshTopology topology(pm.mesh.tetrahedra, pm.mesh.NumberOfPoints());
  morea_core::DualMesh           moved = morea_core::DualMesh::FromBase(pm.mesh);
  const double              c = std::cos(0.3), s = std::sin(0.3);
  for (auto & p : moved.target)
    p = { { c * p[0] - s * p[1] + 7.0, s * p[0] + c * p[1] - 2.0, p[2] + 1.0 } };
  EXPECT_NEAR(morea_core::MagnitudeObjective(topology, moved, {}), 0.0, 1e-20);

  const morea_core::FoldConstraint constraint(topology, pm.mesh.points);
  const auto                  population = morea_core::GenerateInitialPopulation(pm.mesh, constraint, 3, 5);
  std::vector<double>         elasticity(topology.NumberOfTetrahedra());
  for (std::size_t t = 0; t < elasticity.size(); ++t)
    elasticity[t] = 0.5 + static_cast<double>(t % 7);
  const double whole = morea_core::MagnitudeObjective(topology, population[2], elasticity);
  double       parts = 0.0;
  for (std::size_t t = 0; t < topology.NumberOfTetrahedra(); ++t)
    parts += morea_core::TetrahedronMagnitude(topology.Tetrahedra()[t], population[2].source, population[2].target,
                                         elasticity[t]) /
             (10.0 * static_cast<double>(topology.NumberOfTetrahedra()));
  EXPECT_GT(whole, 0.0);
  EXPECT_NEAR(parts, whole, 1e-9 * whole);
}
} // namespace
