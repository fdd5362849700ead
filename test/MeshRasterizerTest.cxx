// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/MeshRasterizer.h"

#include "morea_core/Error.h"

#include "BoxMesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

namespace
{
using morea_core::Vec3;
using morea_core::Volume;
using Mat3 = std::array<Vec3, 3>; // rows

/** A non-trivial affine map x -> A x + b with det A > 0. */
const Mat3 AffineMatrix{ { { { 1.05, 0.08, -0.03 } }, { { -0.06, 0.95, 0.05 } }, { { 0.04, -0.02, 1.10 } } } };
const Vec3 AffineOffset{ { 2.0, -1.5, 1.0 } };

Vec3
Apply(const Mat3 & m, const Vec3 & x)
{
  return { m[0][0] * x[0] + m[0][1] * x[1] + m[0][2] * x[2],
           m[1][0] * x[0] + m[1][1] * x[1] + m[1][2] * x[2],
           m[2][0] * x[0] + m[2][1] * x[1] + m[2][2] * x[2] };
}

Mat3
Inverse(const Mat3 & m)
{
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      // Cofactor of (j, i) over the determinant.
      const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
      r[i][j] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
    }
  return r;
}

Vec3
AffineImage(const Vec3 & x)
{
  const Vec3 y = Apply(AffineMatrix, x);
  return { y[0] + AffineOffset[0], y[1] + AffineOffset[1], y[2] + AffineOffset[2] };
}

Vec3
InverseAffineImage(const Vec3 & y)
{
  return Apply(Inverse(AffineMatrix), { y[0] - AffineOffset[0], y[1] - AffineOffset[1], y[2] - AffineOffset[2] });
}

std::vector<Vec3>
MapPoints(const std::vector<Vec3> & points, Vec3 (*map)(const Vec3 &))
{
  std::vector<Vec3> out;
  for (const auto & p : points)
    out.push_back(map(p));
  return out;
}

double
Distance(const Vec3 & a, const Vec3 & b)
{
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

Vec3
Plus(const Vec3 & a, const Vec3 & b)
{
  return { a[0] + b[0], a[1] + b[1], a[2] + b[2] };
}

/** Trilinear interpolation of a field at a frame point (clamped to the grid). */
Vec3
Interpolate(const Volume<Vec3> & field, const Vec3 & x)
{
  std::array<std::size_t, 3> i0;
  Vec3                       w;
  for (int a = 0; a < 3; ++a)
  {
    const double g = std::clamp((x[a] - field.origin[a]) / field.spacing[a], 0.0, double(field.size[a] - 1));
    i0[a] = std::min<std::size_t>(static_cast<std::size_t>(g), field.size[a] - 2);
    w[a] = g - static_cast<double>(i0[a]);
  }
  Vec3 sum{ { 0.0, 0.0, 0.0 } };
  for (int c = 0; c < 8; ++c)
  {
    const int    di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
    const double weight = (di ? w[0] : 1 - w[0]) * (dj ? w[1] : 1 - w[1]) * (dk ? w[2] : 1 - w[2]);
    const Vec3 & v = field(i0[0] + di, i0[1] + dj, i0[2] + dk);
    for (int a = 0; a < 3; ++a)
      sum[a] += weight * v[a];
  }
  return sum;
}

/** An anisotropic grid off the origin, and the box of its voxel centres. */
Volume<Vec3>
TestGrid()
{
  return Volume<Vec3>({ 40, 36, 32 }, { 1.0, 1.2, 0.9 }, { -12.0, 5.0, 30.0 });
}

class MeshRasterizer : public ::testing::Test
{
protected:
  Volume<Vec3>        grid = TestGrid();
  morea_test::BoxMesh box = morea_test::MakeBoxMesh(morea_core::MeshDomain::OfGrid(grid), { 5, 4, 4 });
  morea_core::MeshTopology topology{ box.tetrahedra, box.points.size() };
};
} // namespace

TEST_F(MeshRasterizer, BoxMeshIsValid)
{
  EXPECT_EQ(box.tetrahedra.size(), 5u * 4u * 4u * 6u);
  EXPECT_GT(morea_test::MinimumSignedVolume(box.tetrahedra, box.points), 0.0);
}

TEST_F(MeshRasterizer, IdenticalMeshesGiveZeroField)
{
  morea_core::RasterizationReport report;
  morea_core::RasterizeDisplacement(topology, box.points, box.points, grid, &report);
  EXPECT_EQ(report.voxels, grid.NumberOfVoxels());
  EXPECT_EQ(report.outsideMesh, 0u);
  EXPECT_TRUE(report.outsideMask.empty()) << "no mask when the mesh covers the grid";
  double largest = 0.0;
  for (const auto & u : grid.data)
    largest = std::max({ largest, std::abs(u[0]), std::abs(u[1]), std::abs(u[2]) });
  EXPECT_LT(largest, 1e-12);
}

TEST_F(MeshRasterizer, AffineTargetReproducesAffineMap)
{
  morea_core::RasterizationReport report;
  morea_core::RasterizeDisplacement(topology, box.points, MapPoints(box.points, AffineImage), grid, &report);
  EXPECT_EQ(report.outsideMesh, 0u);
  double worst = 0.0;
  for (std::size_t k = 0; k < grid.size[2]; ++k)
    for (std::size_t j = 0; j < grid.size[1]; ++j)
      for (std::size_t i = 0; i < grid.size[0]; ++i)
      {
        const Vec3 x = grid.PointAt(i, j, k);
        worst = std::max(worst, Distance(Plus(x, grid(i, j, k)), AffineImage(x)));
      }
  EXPECT_LT(worst, 1e-3);
}

TEST_F(MeshRasterizer, AffineSourceGivesInverseMapInsideItsImage)
{
  morea_core::RasterizationReport report;
  morea_core::RasterizeDisplacement(topology, MapPoints(box.points, AffineImage), box.points, grid, &report);
  // The sheared, shifted box leaves part of the grid uncovered.
  EXPECT_GT(report.outsideMesh, 0u);
  EXPECT_LT(report.outsideMesh, grid.NumberOfVoxels());
  std::size_t inside = 0;
  double      worst = 0.0;
  for (std::size_t k = 0; k < grid.size[2]; ++k)
    for (std::size_t j = 0; j < grid.size[1]; ++j)
      for (std::size_t i = 0; i < grid.size[0]; ++i)
      {
        const Vec3 x = grid.PointAt(i, j, k);
        const Vec3 preimage = InverseAffineImage(x);
        bool       inBox = true;
        for (int a = 0; a < 3; ++a)
          inBox = inBox && preimage[a] >= box.domain.lower[a] && preimage[a] <= box.domain.upper[a];
        if (!inBox)
          continue;
        ++inside;
        worst = std::max(worst, Distance(Plus(x, grid(i, j, k)), preimage));
      }
  EXPECT_GT(inside, grid.NumberOfVoxels() / 2);
  EXPECT_LT(worst, 1e-3);
}

TEST(MeshRasterizerInverse, RandomPerturbationComposesToIdentity)
{
  // Trilinear interpolation of the second field misses the kinks between
  // tetrahedra by about (gradient jump) x (voxel size), so the perturbation is
  // gentle relative to the cells (~9 voxels wide), yet moves voxels by more than
  // a voxel; a wrong tetrahedron or map would cost about the displacement itself.
  const Volume<Vec3>        grid({ 56, 52, 48 }, { 1.0, 1.1, 0.9 }, { -12.0, 5.0, 30.0 });
  const auto                box = morea_test::MakeBoxMesh(morea_core::MeshDomain::OfGrid(grid), { 3, 3, 3 });
  const morea_core::MeshTopology topology(box.tetrahedra, box.points.size());
  const std::vector<Vec3>   moved = morea_test::Perturb(box, 0.06, 8);
  ASSERT_GT(morea_test::MinimumSignedVolume(box.tetrahedra, moved), 0.0) << "the perturbation folded the mesh";
  Volume<Vec3>               forward = grid;
  Volume<Vec3>               backward = grid;
  morea_core::RasterizationReport forwardReport;
  morea_core::RasterizationReport backwardReport;
  morea_core::RasterizeDisplacement(topology, box.points, moved, forward, &forwardReport);
  morea_core::RasterizeDisplacement(topology, moved, box.points, backward, &backwardReport);
  EXPECT_EQ(forwardReport.outsideMesh, 0u);
  EXPECT_EQ(backwardReport.outsideMesh, 0u);

  const double voxel = std::min({ grid.spacing[0], grid.spacing[1], grid.spacing[2] });
  double       worst = 0.0;
  double       largestDisplacement = 0.0;
  for (std::size_t k = 0; k < grid.size[2]; ++k)
    for (std::size_t j = 0; j < grid.size[1]; ++j)
      for (std::size_t i = 0; i < grid.size[0]; ++i)
      {
        const Vec3 x = grid.PointAt(i, j, k);
        const Vec3 y = Plus(x, forward(i, j, k));
        largestDisplacement = std::max(largestDisplacement, Distance(x, y));
        worst = std::max(worst, Distance(Plus(y, Interpolate(backward, y)), x));
      }
  EXPECT_GT(largestDisplacement, voxel) << "the perturbation should move voxels by more than a voxel";
  EXPECT_LT(worst, 0.1 * voxel);
}

TEST_F(MeshRasterizer, IsDeterministic)
{
  const std::vector<Vec3> moved = morea_test::Perturb(box, 0.2, 11);
  Volume<Vec3>            first = grid;
  Volume<Vec3>            second = grid;
  morea_core::RasterizeDisplacement(topology, box.points, moved, first);
  morea_core::RasterizeDisplacement(topology, box.points, moved, second);
  EXPECT_TRUE(first.data == second.data);
}

TEST_F(MeshRasterizer, PartialMeshExtrapolatesAffinely)
{
  // A mesh over the voxel centres with i <= 19 only.
  morea_core::MeshDomain half = box.domain;
  half.upper[0] = grid.origin[0] + grid.spacing[0] * 19.0;
  const auto                 partial = morea_test::MakeBoxMesh(half, { 3, 4, 4 });
  morea_core::MeshTopology        partialTopology(partial.tetrahedra, partial.points.size());
  morea_core::RasterizationReport report;
  morea_core::RasterizeDisplacement(partialTopology, partial.points, MapPoints(partial.points, AffineImage), grid, &report);
  EXPECT_EQ(report.outsideMesh, (grid.size[0] - 20) * grid.size[1] * grid.size[2]);
  ASSERT_EQ(report.outsideMask.size(), grid.NumberOfVoxels());
  for (std::size_t k = 0; k < grid.size[2]; ++k)
    for (std::size_t j = 0; j < grid.size[1]; ++j)
      for (std::size_t i = 0; i < grid.size[0]; ++i)
        ASSERT_EQ(report.outsideMask[grid.Offset(i, j, k)], i >= 20 ? 1 : 0) << i << "," << j << "," << k;
  double worst = 0.0;
  for (std::size_t k = 0; k < grid.size[2]; ++k)
    for (std::size_t j = 0; j < grid.size[1]; ++j)
      for (std::size_t i = 20; i < grid.size[0]; ++i)
      {
        const Vec3 x = grid.PointAt(i, j, k);
        worst = std::max(worst, Distance(Plus(x, grid(i, j, k)), AffineImage(x)));
      }
  EXPECT_LT(worst, 1e-3);
  // The far corner, 20 voxels outside the mesh.
  const std::size_t nx = grid.size[0] - 1, ny = grid.size[1] - 1, nz = grid.size[2] - 1;
  EXPECT_LT(Distance(Plus(grid.PointAt(nx, ny, nz), grid(nx, ny, nz)), AffineImage(grid.PointAt(nx, ny, nz))), 1e-3);
}

TEST_F(MeshRasterizer, DegenerateTetrahedraAreSkipped)
{
  // A zero-volume sliver (a repeated point) with the lowest index: were it not
  // skipped, its singular edge matrix would spread non-finite values.
  auto tetrahedra = box.tetrahedra;
  tetrahedra.insert(tetrahedra.begin(), morea_core::Tetrahedron{ { 0, 1, 1, 2 } });
  morea_core::MeshTopology        withSliver(tetrahedra, box.points.size());
  morea_core::RasterizationReport report;
  morea_core::RasterizeDisplacement(withSliver, box.points, MapPoints(box.points, AffineImage), grid, &report);
  EXPECT_EQ(report.outsideMesh, 0u);
  double worst = 0.0;
  for (std::size_t k = 0; k < grid.size[2]; ++k)
    for (std::size_t j = 0; j < grid.size[1]; ++j)
      for (std::size_t i = 0; i < grid.size[0]; ++i)
      {
        const Vec3   x = grid.PointAt(i, j, k);
        const double error = Distance(Plus(x, grid(i, j, k)), AffineImage(x));
        worst = std::isfinite(error) ? std::max(worst, error) : 1e300;
      }
  EXPECT_LT(worst, 1e-3);
}

TEST_F(MeshRasterizer, BadInputsThrow)
{
  std::vector<Vec3> tooFew(box.points.begin(), box.points.end() - 1);
  EXPECT_THROW(morea_core::RasterizeDisplacement(topology, tooFew, box.points, grid), morea_core::Error);
  Volume<Vec3> flat = grid;
  flat.spacing[1] = 0.0;
  EXPECT_THROW(morea_core::RasterizeDisplacement(topology, box.points, box.points, flat), morea_core::Error);
  // A mesh far away from the grid leaves nothing to extrapolate from.
  auto far = box.points;
  for (auto & p : far)
    p[0] += 1000.0;
  EXPECT_THROW(morea_core::RasterizeDisplacement(topology, far, far, grid), morea_core::Error);
}
