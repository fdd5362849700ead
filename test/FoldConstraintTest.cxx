// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of fold detection, the constraint value and the Gaussian repair.
#include "MeshTestSupport.h"

#include "morea_core/Error.h"
#include "morea_core/FoldConstraint.h"
#include "morea_core/MeshRepair.h"

#include <gtest/gtest.h>

#include <cmath>

namespace
{
using morea_core::Vec3;

// Two tetrahedra on the triangle (0,1,2) in the plane z = 0: point 3 above,
// point 4 below. Area of the triangle: 8.
struct TwoTetrahedra
{
  std::vector<Vec3>              points{ { { 0, 0, 0 } }, { { 4, 0, 0 } }, { { 0, 4, 0 } }, { { 1, 1, 3 } }, { { 1, 1, -2 } } };
  std::vector<morea_core::Tetrahedron> tets{ { { 0, 1, 2, 3 } }, { { 0, 2, 1, 4 } } };
  morea_core::MeshTopology            topology{ tets, 5 };
};

TEST(FoldConstraint, PlantedFoldHasTheRightSeverity)
{
  TwoTetrahedra         m;
  morea_core::FoldConstraint constraint(m.topology, m.points);
  EXPECT_TRUE(constraint.Evaluate(m.points).Feasible());
  EXPECT_EQ(constraint.Evaluate(m.points).value, 0.0);

  // Push point 3 through the shared face to z = -1.5: the first tetrahedron
  // turns inside out with |volume| = 8 * 1.5 / 3 = 4; the second is untouched.
  std::vector<Vec3> folded = m.points;
  folded[3] = { { 1, 1, -1.5 } };
  const auto v = constraint.Evaluate(folded);
  EXPECT_EQ(v.folded, 1u);
  EXPECT_NEAR(v.value, 4.0, 1e-12);
  EXPECT_EQ(constraint.FoldedTetrahedra(folded), (std::vector<std::uint32_t>{ 0 }));
  // Flattening it exactly onto the face is a fold of severity 0.
  folded[3] = { { 1, 1, 0 } };
  EXPECT_EQ(constraint.Evaluate(folded).folded, 1u);
  EXPECT_EQ(constraint.Evaluate(folded).value, 0.0);

  // Both meshes add up.
  morea_core::DualMesh dual{ m.points, m.points };
  dual.target[3] = { { 1, 1, -1.5 } };
  dual.source[4] = { { 1, 1, 0.5 } }; // |volume| = 8 * 0.5 / 3
  const auto both = constraint.Evaluate(dual);
  EXPECT_EQ(both.folded, 2u);
  EXPECT_NEAR(both.value, 4.0 + 4.0 / 3.0, 1e-12);
}

TEST(FoldConstraint, RejectsMismatchedSizesAndFlatReference)
{
  TwoTetrahedra m;
  EXPECT_THROW(morea_core::FoldConstraint(m.topology, { m.points[0] }), morea_core::Error);
  auto flat = m.points;
  flat[3][2] = 0.0;
  EXPECT_THROW(morea_core::FoldConstraint(m.topology, flat), morea_core::Error);
  morea_core::FoldConstraint constraint(m.topology, m.points);
  EXPECT_THROW(constraint.Evaluate(std::vector<Vec3>(3)), morea_core::Error);
}

TEST(FoldConstraint, TranslatedPhantomMeshHasNoFold)
{
  const auto &              pm = morea_test::PhantomMesh600();
  const morea_core::MeshTopology topology(pm.mesh.tetrahedra, pm.mesh.NumberOfPoints());
  morea_core::FoldConstraint     constraint(topology, pm.mesh.points);
  for (const Vec3 shift : { Vec3{ { 12.5, -3.0, 40.0 } }, Vec3{ { -0.001, 0.0, 0.0 } } })
  {
    std::vector<Vec3> moved = pm.mesh.points;
    for (auto & p : moved)
      for (int a = 0; a < 3; ++a)
        p[a] += shift[a];
    const auto v = constraint.Evaluate(moved);
    EXPECT_TRUE(v.Feasible());
    EXPECT_EQ(v.value, 0.0);
  }
}

/** Moves an inner point of the phantom mesh through the face opposite it in
 *  one of its tetrahedra (mirrors it in that face's plane). */
std::uint32_t
PlantFold(std::vector<Vec3> & points, const morea_core::TetrahedralMesh & mesh, const morea_core::MeshTopology & topology,
          std::size_t which)
{
  std::size_t seen = 0;
  for (std::uint32_t p = 0; p < points.size(); ++p)
  {
    if (mesh.origins[p] != morea_core::PointOrigin::Random || seen++ != which)
      continue;
    const auto & tet = topology.Tetrahedra()[*topology.TetrahedraOfPointBegin(p)];
    Vec3         f[3];
    int          n = 0;
    for (auto v : tet)
      if (v != p)
        f[n++] = points[v];
    const Vec3   u{ { f[1][0] - f[0][0], f[1][1] - f[0][1], f[1][2] - f[0][2] } };
    const Vec3   w{ { f[2][0] - f[0][0], f[2][1] - f[0][1], f[2][2] - f[0][2] } };
    Vec3         nrm{ { u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0] } };
    const double len = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    const double d = ((points[p][0] - f[0][0]) * nrm[0] + (points[p][1] - f[0][1]) * nrm[1] +
                      (points[p][2] - f[0][2]) * nrm[2]) /
                     len;
    for (int a = 0; a < 3; ++a)
      points[p][a] -= 2.0 * d * nrm[a] / len;
    return p;
  }
  ADD_FAILURE() << "no inner point to fold";
  return 0;
}

TEST(FoldConstraint, PartialEvaluationMatchesFullOnThePhantomMesh)
{
  const auto &              pm = morea_test::PhantomMesh600();
  const morea_core::MeshTopology topology(pm.mesh.tetrahedra, pm.mesh.NumberOfPoints());
  morea_core::FoldConstraint     constraint(topology, pm.mesh.points);
  std::vector<Vec3>         before = pm.mesh.points;
  std::vector<Vec3>         after = before;
  const std::uint32_t       p = PlantFold(after, pm.mesh, topology, 3);
  const auto                touched = topology.TetrahedraOfPoint(p);
  const auto                full = constraint.Evaluate(after);
  EXPECT_GE(full.folded, 1u);
  EXPECT_GT(full.value, 0.0);
  const auto b = constraint.Partial(before, touched), a = constraint.Partial(after, touched);
  EXPECT_EQ(constraint.Evaluate(before).folded - b.folded + a.folded, full.folded);
  EXPECT_NEAR(constraint.Evaluate(before).value - b.value + a.value, full.value, 1e-9 * full.value);
  // The folded tetrahedra all contain the moved point.
  for (auto t : constraint.FoldedTetrahedra(after))
    EXPECT_TRUE(std::binary_search(touched.begin(), touched.end(), t));
}

TEST(MeshRepair, RepairsPlantedFoldsInBothMeshes)
{
  const auto &              pm = morea_test::PhantomMesh600();
  const morea_core::MeshTopology topology(pm.mesh.tetrahedra, pm.mesh.NumberOfPoints());
  morea_core::FoldConstraint     constraint(topology, pm.mesh.points);
  morea_core::DualMesh           solution = morea_core::DualMesh::FromBase(pm.mesh);
  for (std::size_t k : { 0, 5, 11 })
    PlantFold(solution.target, pm.mesh, topology, k);
  PlantFold(solution.source, pm.mesh, topology, 20);
  ASSERT_FALSE(constraint.Evaluate(solution).Feasible());

  // The repair is stochastic: over several seeds it always lowers the
  // violation, usually removes every fold, and keeps points on their faces.
  const morea_core::DualMesh planted = solution;
  std::size_t           repaired = 0;
  for (std::uint64_t seed = 0; seed < 20; ++seed)
  {
    solution = planted;
    morea_core::RandomGenerator random(seed);
    const auto             result = morea_core::RepairFolds(solution, pm.mesh, constraint, random);
    EXPECT_GE(result.before.folded, 4u);
    EXPECT_LT(result.after.folded, result.before.folded) << "seed " << seed;
    EXPECT_LT(result.after.value, result.before.value) << "seed " << seed;
    EXPECT_EQ(result.Repaired(), constraint.Evaluate(solution).Feasible());
    EXPECT_EQ(result.after.folded, constraint.Evaluate(solution).folded);
    EXPECT_GE(result.movedPoints, 4u);
    repaired += result.Repaired();
    for (std::size_t i = 0; i < solution.source.size(); ++i)
    {
      EXPECT_EQ(morea_core::ProjectToDomain(solution.source[i], pm.mesh.pins[i], pm.domain), solution.source[i]);
      EXPECT_EQ(morea_core::ProjectToDomain(solution.target[i], pm.mesh.pins[i], pm.domain), solution.target[i]);
    }
  }
  EXPECT_GE(repaired, 6u) << "of 20 seeds";

  // A fold-free mesh is left untouched.
  morea_core::DualMesh untouched = morea_core::DualMesh::FromBase(pm.mesh);
  morea_core::RandomGenerator random(42);
  const auto      none = morea_core::RepairFolds(untouched, pm.mesh, constraint, random);
  EXPECT_EQ(none.movedPoints, 0u);
  EXPECT_EQ(untouched.target, pm.mesh.points);
}
} // namespace
