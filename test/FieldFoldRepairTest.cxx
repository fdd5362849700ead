// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/FieldFoldRepair.h"

#include "morea_core/Error.h"
#include "morea_core/MeshRasterizer.h"

#include "BoxMesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace
{
using morea_core::Vec3;
using morea_core::Volume;

Volume<Vec3>
Grid(std::array<std::size_t, 3> size, Vec3 spacing)
{
  return Volume<Vec3>(size, spacing, { { -3.0, 1.0, 2.0 } });
}

double
Distance(const Vec3 & a, const Vec3 & b)
{
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}
} // namespace

TEST(FieldFoldRepair, AffineFieldDeterminantIsExactEverywhere)
{
  // u(x) = (A - I) x + b: central and one-sided differences are both exact.
  const double A[3][3] = { { 1.2, 0.1, -0.05 }, { 0.03, 0.8, 0.2 }, { -0.1, 0.05, 1.5 } };
  const double expected = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                          A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                          A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
  auto field = Grid({ { 6, 5, 4 } }, { { 1.5, 2.0, 0.5 } });
  for (std::size_t k = 0; k < 4; ++k)
    for (std::size_t j = 0; j < 5; ++j)
      for (std::size_t i = 0; i < 6; ++i)
      {
        const Vec3 x = field.PointAt(i, j, k);
        for (int c = 0; c < 3; ++c)
          field(i, j, k)[c] = A[c][0] * x[0] + A[c][1] * x[1] + A[c][2] * x[2] - x[c] + 0.7 * c;
      }
  for (std::size_t k = 0; k < 4; ++k)
    for (std::size_t j = 0; j < 5; ++j)
      for (std::size_t i = 0; i < 6; ++i)
        EXPECT_NEAR(morea_core::JacobianDeterminantAt(field, i, j, k), expected, 1e-12) << i << "," << j << "," << k;
  EXPECT_EQ(morea_core::CountNonPositiveJacobians(field), 0u);

  const auto before = field.data;
  const auto report = morea_core::RemoveVoxelFolds(field);
  EXPECT_EQ(report.foldedBefore, 0u);
  EXPECT_EQ(report.voxelsChanged, 0u);
  EXPECT_EQ(report.projectionRounds, 0u);
  EXPECT_EQ(report.smoothingRounds, 0u);
  EXPECT_EQ(field.data, before) << "a fold-free field is left exactly as it is";
}

TEST(FieldFoldRepair, ReflectionCountsEveryVoxel)
{
  // x -> -x along axis 0: determinant -1 everywhere.
  auto field = Grid({ { 4, 3, 3 } }, { { 1.0, 1.0, 1.0 } });
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t i = 0; i < 4; ++i)
        field(i, j, k) = { { -2.0 * field.PointAt(i, j, k)[0], 0.0, 0.0 } };
  EXPECT_NEAR(morea_core::JacobianDeterminantAt(field, 1, 1, 1), -1.0, 1e-12);
  EXPECT_EQ(morea_core::CountNonPositiveJacobians(field), field.NumberOfVoxels());
}

TEST(FieldFoldRepair, LocalSpikeIsProjectedAwayAndTheRestIsKept)
{
  // A smooth field plus one voxel pushed 2.5 voxels along x: its neighbours
  // along x see a folded central difference.
  auto field = Grid({ { 21, 21, 21 } }, { { 1.0, 1.2, 0.8 } });
  for (std::size_t k = 0; k < 21; ++k)
    for (std::size_t j = 0; j < 21; ++j)
      for (std::size_t i = 0; i < 21; ++i)
        field(i, j, k) = { { 0.02 * static_cast<double>(j), -0.01 * static_cast<double>(k), 0.5 } };
  field(10, 10, 10)[0] += 2.5;
  field(10, 11, 10)[0] -= 2.5;
  const auto before = field.data;
  const std::size_t folded = morea_core::CountNonPositiveJacobians(field);
  ASSERT_GT(folded, 0u);

  const auto report = morea_core::RemoveVoxelFolds(field);
  EXPECT_EQ(report.foldedBefore, folded);
  EXPECT_EQ(report.foldedAfter, 0u);
  EXPECT_EQ(morea_core::CountNonPositiveJacobians(field), 0u);
  EXPECT_GT(report.projectionRounds, 0u);
  EXPECT_EQ(report.smoothingRounds, 0u) << "the projection alone removes a spike";
  EXPECT_GT(report.voxelsChanged, 0u);
  EXPECT_LT(report.voxelsChanged, 100u) << "the repair stays local";
  EXPECT_GT(report.maximumChange, 0.1);
  EXPECT_LT(report.maximumChange, 2.5) << "less than undoing the spike";

  // Far from the spike nothing moved; the largest change is reported exactly.
  double largest = 0.0;
  for (std::size_t k = 0; k < 21; ++k)
    for (std::size_t j = 0; j < 21; ++j)
      for (std::size_t i = 0; i < 21; ++i)
      {
        const std::size_t o = field.Offset(i, j, k);
        largest = std::max(largest, Distance(field.data[o], before[o]));
        const std::size_t far = std::max({ i > 10 ? i - 10 : 10 - i, j > 10 ? j - 10 : 10 - j, k > 10 ? k - 10 : 10 - k });
        if (far > 4)
          EXPECT_EQ(field.data[o], before[o]) << i << "," << j << "," << k;
      }
  EXPECT_DOUBLE_EQ(largest, report.maximumChange);
}

TEST(FieldFoldRepair, CompressedTetrahedraOfAFoldFreeMeshAreRepaired)
{
  // A fold-free mesh map whose voxel field still folds: where strongly sheared
  // tetrahedra meet, a central difference mixes their gradients and the
  // finite-difference determinant goes negative. (Perturbation and seed were
  // picked so that this happens: 7 folded voxels.)
  Volume<Vec3> grid({ { 25, 25, 25 } }, { { 1.0, 1.0, 1.0 } }, { { 0.0, 0.0, 0.0 } });
  const auto   box = morea_test::MakeBoxMesh(morea_core::MeshDomain::OfGrid(grid), { { 3, 3, 3 } });
  const morea_core::MeshTopology topology(box.tetrahedra, box.points.size());
  const auto                moved = morea_test::Perturb(box, 0.45, 115);
  ASSERT_GT(morea_test::MinimumSignedVolume(box.tetrahedra, moved), 0.0) << "the mesh map itself is fold-free";

  morea_core::RasterizeDisplacement(topology, box.points, moved, grid);
  const std::size_t folded = morea_core::CountNonPositiveJacobians(grid);
  ASSERT_GT(folded, 0u) << "the test needs a field that folds at voxel level";
  const auto before = grid.data;
  auto       smoothedGrid = grid;

  const auto report = morea_core::RemoveVoxelFolds(grid);
  EXPECT_EQ(report.foldedBefore, folded);
  EXPECT_EQ(report.smoothingRounds, 0u);
  EXPECT_EQ(report.foldedAfter, 0u);
  EXPECT_EQ(morea_core::CountNonPositiveJacobians(grid), 0u);
  std::size_t changed{ 0 };
  for (std::size_t o = 0; o < grid.NumberOfVoxels(); ++o)
    changed += grid.data[o] != before[o];
  EXPECT_EQ(changed, report.voxelsChanged);
  EXPECT_LT(changed, grid.NumberOfVoxels() / 50) << "the rest keeps the exact piecewise-affine map";
  // Displacements here reach 0.45 x 8 mm per axis; the repair moves far less,
  // and less than smoothing alone does.
  EXPECT_LT(report.maximumChange, 2.0);
  morea_core::FieldFoldRepairOptions smoothingOnly;
  smoothingOnly.maximumProjectionRounds = 0;
  const auto smoothing = morea_core::RemoveVoxelFolds(smoothedGrid, smoothingOnly);
  EXPECT_EQ(smoothing.projectionRounds, 0u);
  EXPECT_GT(smoothing.smoothingRounds, 0u);
  EXPECT_EQ(smoothing.foldedAfter, 0u);
  EXPECT_LT(report.maximumChange, 0.5 * smoothing.maximumChange);
  EXPECT_LT(report.voxelsChanged, smoothing.voxelsChanged);
}

TEST(FieldFoldRepair, SplitsItsReportBetweenVoxelsTheMeshCoversAndTheRest)
{
  // Two spikes, one in a region marked outside the mesh (i >= 15); the mask
  // splits the report and leaves the repair exactly as without it.
  auto field = Grid({ { 21, 21, 21 } }, { { 1.0, 1.0, 1.0 } });
  for (std::size_t k = 0; k < 21; ++k)
    for (std::size_t j = 0; j < 21; ++j)
      for (std::size_t i = 0; i < 21; ++i)
        field(i, j, k) = { { 0.01 * static_cast<double>(j), 0.0, 0.2 } };
  field(5, 10, 10)[0] += 2.0;
  field(5, 11, 10)[0] -= 2.0;
  field(17, 10, 10)[0] += 4.0;
  field(17, 11, 10)[0] -= 4.0;
  std::vector<std::uint8_t> outside(field.NumberOfVoxels(), 0);
  std::size_t               foldedOutside{ 0 };
  for (std::size_t k = 0; k < 21; ++k)
    for (std::size_t j = 0; j < 21; ++j)
      for (std::size_t i = 15; i < 21; ++i)
      {
        outside[field.Offset(i, j, k)] = 1;
        foldedOutside += morea_core::JacobianDeterminantAt(field, i, j, k) <= 0.0;
      }
  ASSERT_GT(foldedOutside, 0u);
  auto       plain = field;
  const auto withMask = morea_core::RemoveVoxelFolds(field, {}, &outside);
  const auto without = morea_core::RemoveVoxelFolds(plain);
  EXPECT_EQ(field.data, plain.data) << "the mask only splits the report";
  EXPECT_EQ(withMask.foldedBefore, without.foldedBefore);
  EXPECT_GT(withMask.foldedBefore, foldedOutside) << "the spike the mesh covers folds too";
  EXPECT_EQ(withMask.foldedBeforeOutsideMesh, foldedOutside);
  EXPECT_EQ(without.foldedBeforeOutsideMesh, 0u);
  EXPECT_DOUBLE_EQ(withMask.maximumChange, without.maximumChange);
  EXPECT_GT(withMask.maximumChangeInsideMesh, 0.0);
  EXPECT_LE(withMask.maximumChangeInsideMesh, 2.0 + 1e-9) << "the larger spike lies outside the mesh";
  EXPECT_GT(withMask.maximumChange, withMask.maximumChangeInsideMesh);
  EXPECT_DOUBLE_EQ(without.maximumChangeInsideMesh, without.maximumChange);

  std::vector<std::uint8_t> wrongSize(3, 0);
  EXPECT_THROW(morea_core::RemoveVoxelFolds(plain, {}, &wrongSize), morea_core::Error);
}

TEST(FieldFoldRepair, GivesUpAfterTheIterationLimitAndSaysSo)
{
  // A global reflection cannot be smoothed away in a few rounds.
  auto field = Grid({ { 8, 8, 8 } }, { { 1.0, 1.0, 1.0 } });
  for (std::size_t k = 0; k < 8; ++k)
    for (std::size_t j = 0; j < 8; ++j)
      for (std::size_t i = 0; i < 8; ++i)
        field(i, j, k) = { { -2.0 * field.PointAt(i, j, k)[0], 0.0, 0.0 } };
  morea_core::FieldFoldRepairOptions options;
  options.maximumProjectionRounds = 5;
  options.maximumIterations = 3;
  const auto report = morea_core::RemoveVoxelFolds(field, options);
  EXPECT_EQ(report.projectionRounds, 5u);
  EXPECT_EQ(report.smoothingRounds, 3u);
  EXPECT_EQ(report.foldedBefore, field.NumberOfVoxels());
  EXPECT_GT(report.foldedAfter, 0u);
  EXPECT_EQ(report.foldedAfter, morea_core::CountNonPositiveJacobians(field));
}

TEST(FieldFoldRepair, SmoothsWhatTheProjectionLeavesAndIsDeterministic)
{
  // One projection round does not lift a deep fold; smoothing finishes it.
  auto field = Grid({ { 21, 21, 21 } }, { { 1.0, 1.0, 1.0 } });
  field(10, 10, 10)[0] += 6.0;
  field(10, 11, 10)[0] -= 6.0;
  morea_core::FieldFoldRepairOptions options;
  options.maximumProjectionRounds = 1;
  auto       again = field;
  const auto report = morea_core::RemoveVoxelFolds(field, options);
  EXPECT_EQ(report.projectionRounds, 1u);
  EXPECT_GT(report.smoothingRounds, 0u);
  EXPECT_EQ(report.foldedAfter, 0u);
  EXPECT_EQ(morea_core::CountNonPositiveJacobians(field), 0u);
  const auto repeated = morea_core::RemoveVoxelFolds(again, options);
  EXPECT_EQ(again.data, field.data) << "the same field gives the same repair, bit for bit";
  EXPECT_EQ(repeated.smoothingRounds, report.smoothingRounds);
}

TEST(FieldFoldRepair, ProjectionDoesNotDependOnTheThreads)
{
  // Many folds spread over the grid, so that every thread has requests to sum.
  auto field = Grid({ { 40, 30, 20 } }, { { 1.0, 1.5, 2.0 } });
  for (std::size_t k = 2; k < 20; k += 5)
    for (std::size_t j = 2; j < 30; j += 6)
      for (std::size_t i = 2; i < 40; i += 7)
      {
        field(i, j, k)[0] += 2.5;
        field(i, j + 1, k)[0] -= 2.0;
      }
  auto one = field;
  auto many = field;
  morea_core::FieldFoldRepairOptions options;
  options.threads = 1;
  const auto alone = morea_core::RemoveVoxelFolds(one, options);
  options.threads = 5;
  const auto together = morea_core::RemoveVoxelFolds(many, options);
  ASSERT_GT(alone.foldedBefore, 100u);
  EXPECT_EQ(alone.foldedAfter, 0u);
  EXPECT_EQ(alone.smoothingRounds, 0u);
  EXPECT_EQ(together.projectionRounds, alone.projectionRounds);
  EXPECT_EQ(many.data, one.data) << "bit for bit";
}

TEST(FieldFoldRepair, RejectsBadFields)
{
  Volume<Vec3> empty;
  EXPECT_THROW(morea_core::RemoveVoxelFolds(empty), morea_core::Error);
  auto field = Grid({ { 3, 3, 3 } }, { { 1.0, 0.0, 1.0 } });
  EXPECT_THROW(morea_core::RemoveVoxelFolds(field), morea_core::Error);
  EXPECT_THROW(morea_core::CountNonPositiveJacobians(field), morea_core::Error);
  auto fine = Grid({ { 3, 3, 3 } }, { { 1.0, 1.0, 1.0 } });
  morea_core::FieldFoldRepairOptions options;
  options.projectionStep = 1.5;
  EXPECT_THROW(morea_core::RemoveVoxelFolds(fine, options), morea_core::Error);
  options.projectionStep = 0.9;
  options.projectionTarget = 0.0;
  EXPECT_THROW(morea_core::RemoveVoxelFolds(fine, options), morea_core::Error);
}
