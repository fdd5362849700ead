// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of the mesh model's geometry, point placement, tetrahedralisation and
// the generated phantom mesh.
#include "MeshTestSupport.h"

#include "morea_core/Error.h"
#include "morea_core/MeshGenerator.h"
#include "morea_core/MeshPointPlacement.h"
#include "morea_core/ParameterSet.h"
#include "morea_core/StructureSurface.h"
#include "morea_core/Tetrahedralization.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <set>

namespace
{
using morea_core::Tetrahedron;
using morea_core::Vec3;

double
Distance(const Vec3 & a, const Vec3 & b)
{
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

TEST(TetrahedralMesh, SignedVolumeOfUnitCornerTetrahedron)
{
  const Vec3 o{ { 0, 0, 0 } }, x{ { 2, 0, 0 } }, y{ { 0, 3, 0 } }, z{ { 0, 0, 4 } };
  EXPECT_DOUBLE_EQ(morea_core::SignedVolume(o, x, y, z), 4.0);
  EXPECT_DOUBLE_EQ(morea_core::SignedVolume(o, y, x, z), -4.0);
  EXPECT_DOUBLE_EQ(morea_core::SignedVolume(o, x, x, z), 0.0);
}

TEST(TetrahedralMesh, TopologyListsTetrahedraEdgesAndNeighbours)
{
  // Two tetrahedra sharing the face (0,1,2).
  const std::vector<Tetrahedron> tets{ { { 0, 1, 2, 3 } }, { { 0, 2, 1, 4 } } };
  const morea_core::MeshTopology      topology(tets, 5);
  EXPECT_EQ(topology.NumberOfPoints(), 5u);
  EXPECT_EQ(topology.Edges().size(), 9u); // 3 shared + 3 + 3
  EXPECT_EQ(topology.TetrahedraOfPoint(0), (std::vector<std::uint32_t>{ 0, 1 }));
  EXPECT_EQ(topology.TetrahedraOfPoint(3), (std::vector<std::uint32_t>{ 0 }));
  EXPECT_EQ(topology.Neighbours(3), (std::vector<std::uint32_t>{ 0, 1, 2 }));
  EXPECT_EQ(topology.Neighbours(0), (std::vector<std::uint32_t>{ 1, 2, 3, 4 }));
  EXPECT_THROW(morea_core::MeshTopology(tets, 4), morea_core::Error);
}

TEST(TetrahedralMesh, PinsAndProjectionKeepPointsOnTheirFaces)
{
  morea_core::MeshDomain d;
  d.lower = { { 0, 0, 0 } };
  d.upper = { { 10, 20, 30 } };
  EXPECT_EQ(morea_core::PinOf({ { 0, 5, 30 } }, d, 1e-9), (morea_core::BoundaryPin{ { -1, 0, 1 } }));
  EXPECT_EQ(morea_core::PinOf({ { 5, 5, 5 } }, d, 1e-9), (morea_core::BoundaryPin{ { 0, 0, 0 } }));
  const Vec3 q = morea_core::ProjectToDomain({ { 3, -4, 31 } }, { { -1, 0, 0 } }, d);
  EXPECT_EQ(q, (Vec3{ { 0, 0, 30 } }));
}

TEST(MeshPointPlacement, SpreadOutSubsetPicksFarthestPoints)
{
  // Points on a line 0..100: from an existing point at 0 the farthest-first
  // order is 100, 50, then 25 or 75.
  std::vector<Vec3> line;
  for (int i = 0; i <= 100; ++i)
    line.push_back({ { double(i), 0, 0 } });
  const auto chosen = morea_core::SpreadOutSubset(line, 3, { { { 0, 0, 0 } } }, 0.0);
  ASSERT_EQ(chosen.size(), 3u);
  EXPECT_EQ(chosen[0][0], 100.0);
  EXPECT_EQ(chosen[1][0], 50.0);
  EXPECT_TRUE(chosen[2][0] == 25.0 || chosen[2][0] == 75.0);
  // The minimum distance stops the selection instead of placing near-duplicates.
  const std::vector<Vec3> two{ { { 0, 0, 0 } }, { { 0.1, 0, 0 } } };
  EXPECT_EQ(morea_core::SpreadOutSubset(two, 2, { { { 50, 0, 0 } } }, 1.0).size(), 1u);
}

TEST(MeshPointPlacement, MaskBoundaryPointsOfACube)
{
  morea_core::Volume<std::uint8_t> mask({ { 5, 5, 5 } }, { { 1, 1, 1 } }, { { 0, 0, 0 } });
  for (std::size_t k = 1; k < 4; ++k)
    for (std::size_t j = 1; j < 4; ++j)
      for (std::size_t i = 1; i < 4; ++i)
        mask(i, j, k) = 1;
  EXPECT_EQ(morea_core::MaskBoundaryPoints(mask).size(), 26u); // 27 voxels minus the centre
}

TEST(MeshPointPlacement, DistanceToMaskIsTheExactEuclideanDistance)
{
  // Anisotropic voxels and a scattered mask: every voxel's distance equals the
  // brute-force distance to the nearest mask voxel centre.
  morea_core::Volume<std::uint8_t> mask({ { 9, 7, 6 } }, { { 1.0, 1.5, 2.5 } }, { { -3, 2, 1 } });
  morea_core::RandomGenerator      random(11);
  std::vector<Vec3>                inside;
  for (std::size_t k = 0; k < 6; ++k)
    for (std::size_t j = 0; j < 7; ++j)
      for (std::size_t i = 0; i < 9; ++i)
        if (random.Uniform() < 0.06)
        {
          mask(i, j, k) = 1;
          inside.push_back(mask.PointAt(i, j, k));
        }
  ASSERT_GT(inside.size(), 2u);
  const auto distance = morea_core::DistanceToMask(mask);
  for (std::size_t k = 0; k < 6; ++k)
    for (std::size_t j = 0; j < 7; ++j)
      for (std::size_t i = 0; i < 9; ++i)
      {
        double best = 1e300;
        for (const Vec3 & q : inside)
          best = std::min(best, Distance(mask.PointAt(i, j, k), q));
        ASSERT_NEAR(distance(i, j, k), best, 1e-5) << i << " " << j << " " << k;
      }
  // No mask: no distance.
  const morea_core::Volume<std::uint8_t> empty({ { 3, 3, 3 } }, { { 1, 1, 1 } }, { { 0, 0, 0 } });
  EXPECT_TRUE(std::isinf(morea_core::DistanceToMask(empty)(1, 1, 1)));
}

TEST(MeshPointPlacement, ShellPointsLieAtTheirDistanceAroundABall)
{
  morea_core::Volume<std::uint8_t> ball({ { 41, 41, 41 } }, { { 1.5, 1.5, 1.5 } }, { { -30, -30, -30 } });
  for (std::size_t k = 0; k < 41; ++k)
    for (std::size_t j = 0; j < 41; ++j)
      for (std::size_t i = 0; i < 41; ++i)
        ball(i, j, k) = Distance(ball.PointAt(i, j, k), { { 0, 0, 0 } }) <= 10.0 ? 1 : 0;
  const auto distance = morea_core::DistanceToMask(ball);
  for (const double offset : { 4.0, 12.0 })
  {
    const auto shell = morea_core::ShellPoints(distance, offset);
    ASSERT_GT(shell.size(), 100u);
    for (const Vec3 & p : shell)
    {
      // The ball's voxel centres reach 10 mm; the shell lies offset +- half a voxel outside them.
      const double r = Distance(p, { { 0, 0, 0 } });
      EXPECT_GT(r, 10.0 + offset - 0.75 - 1.5) << offset;
      EXPECT_LT(r, 10.0 + offset + 0.75 + 1e-9) << offset;
    }
  }
  EXPECT_TRUE(morea_core::ShellPoints(distance, 100.0).empty()); // outside the grid
}

TEST(Tetrahedralization, DelaunayOfACubeTilesIt)
{
  morea_core::MeshDomain d;
  d.upper = { { 2, 3, 4 } };
  auto points = morea_core::DomainCorners(d);
  points.push_back({ { 1, 1.5, 2 } });
  const auto result = morea_core::Tetrahedralize(points);
  EXPECT_EQ(result.steinerPoints, 0u);
  double volume = 0.0;
  for (const auto & t : result.tetrahedra)
  {
    const double v = morea_core::SignedVolume(t, result.points);
    EXPECT_GT(v, 0.0);
    volume += v;
  }
  EXPECT_NEAR(volume, 24.0, 1e-9);
  EXPECT_THROW(morea_core::Tetrahedralize({ points[0], points[1], points[2] }), morea_core::Error);
  EXPECT_THROW(morea_core::Tetrahedralize(points, { { { 0, 1, 99 } } }), morea_core::Error);
}

TEST(StructureSurface, SphereSurfaceIsClosedAndDecimated)
{
  morea_core::Volume<std::uint8_t> mask({ { 40, 40, 40 } }, { { 1, 1, 1 } }, { { -20, -20, -20 } });
  for (std::size_t k = 0; k < 40; ++k)
    for (std::size_t j = 0; j < 40; ++j)
      for (std::size_t i = 0; i < 40; ++i)
        mask(i, j, k) = Distance(mask.PointAt(i, j, k), { { 0, 0, 0 } }) <= 12.0;
  const auto surface = morea_core::ExtractStructureSurface(mask, 150);
  EXPECT_GT(surface.vertices.size(), 100u);
  EXPECT_LT(surface.vertices.size(), 200u);
  // Closed 2-manifold: every edge is shared by exactly two triangles.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edgeUse;
  for (const auto & t : surface.triangles)
    for (int e = 0; e < 3; ++e)
    {
      const auto a = t[e], b = t[(e + 1) % 3];
      ++edgeUse[{ std::min(a, b), std::max(a, b) }];
    }
  for (const auto & [edge, uses] : edgeUse)
    EXPECT_EQ(uses, 2);
  EXPECT_EQ(surface.vertices.size() + surface.triangles.size() - edgeUse.size(), 2u); // Euler: sphere
  for (const Vec3 & v : surface.vertices)
    EXPECT_NEAR(Distance(v, { { 0, 0, 0 } }), 12.0, 1.5);
  EXPECT_TRUE(morea_core::ExtractStructureSurface(mask.Like<std::uint8_t>(0), 100).triangles.empty());
}

TEST(MeshGenerator, OptionsFollowTheMethodName)
{
  morea_core::ParameterSet p;
  auto                o = morea_core::MeshGeneratorOptions::FromParameters(p);
  EXPECT_TRUE(o.useContourPoints);
  EXPECT_DOUBLE_EQ(o.randomFraction, 0.10);
  EXPECT_EQ(o.surfaceStructures, (std::vector<std::string>{ "bladder" }));
  p.SetFromString("morea_mesh_generation_method", "annotation-group-random-20");
  o = morea_core::MeshGeneratorOptions::FromParameters(p);
  EXPECT_DOUBLE_EQ(o.randomFraction, 0.20);
  EXPECT_TRUE(o.surfaceStructures.empty());
  p.SetFromString("morea_mesh_generation_method", "random");
  EXPECT_FALSE(morea_core::MeshGeneratorOptions::FromParameters(p).useContourPoints);
  for (const char * bad : { "grid", "annotation-group-random-bladder-x", "annotation-group-random-200" })
  {
    p.SetFromString("morea_mesh_generation_method", bad);
    EXPECT_THROW(morea_core::MeshGeneratorOptions::FromParameters(p), morea_core::Error) << bad;
  }
  p.SetFromString("morea_mesh_generation_method", "random");
  p.SetFromString("morea_mesh_structure_shares", "bladder=2, bones");
  EXPECT_THROW(morea_core::MeshGeneratorOptions::FromParameters(p), morea_core::Error);
}

TEST(MeshGenerator, ShellOptionsFromParameters)
{
  morea_core::ParameterSet p;
  auto                     o = morea_core::MeshGeneratorOptions::FromParameters(p);
  EXPECT_EQ(o.shellOffsets, (std::vector<double>{ 8.0, 20.0 })); // the default
  EXPECT_DOUBLE_EQ(o.shellFraction, 0.15);
  EXPECT_EQ(o.shellStructures, (std::vector<std::string>{ "bladder" }));
  p.SetFromString("morea_mesh_shell_offsets", "5,12.5, 30");
  p.SetFromString("morea_mesh_shell_fraction", "0.2");
  p.SetFromString("morea_mesh_shell_structures", "stomach, bladder");
  o = morea_core::MeshGeneratorOptions::FromParameters(p);
  EXPECT_EQ(o.shellOffsets, (std::vector<double>{ 5.0, 12.5, 30.0 }));
  EXPECT_DOUBLE_EQ(o.shellFraction, 0.2);
  EXPECT_EQ(o.shellStructures, (std::vector<std::string>{ "stomach", "bladder" }));
  p.SetFromString("morea_mesh_shell_offsets", "");
  EXPECT_TRUE(morea_core::MeshGeneratorOptions::FromParameters(p).shellOffsets.empty());
  for (const char * bad : { "x", "8 mm", "0", "-4", "inf" })
  {
    p.SetFromString("morea_mesh_shell_offsets", bad);
    EXPECT_THROW(morea_core::MeshGeneratorOptions::FromParameters(p), morea_core::Error) << bad;
  }
}

TEST(MeshGenerator, ShellsAroundTheBladder)
{
  const auto &                           pm = morea_test::PhantomMesh600();
  const auto & structures = pm.structures;
  morea_core::MeshGeneratorOptions options;
  options.seed = 7;
  options.shellOffsets = { 6.0, 15.0 };
  options.shellFraction = 0.2;
  morea_core::MeshGenerationReport report;
  const auto mesh = morea_core::GenerateMesh(pm.domain, structures, options, &report);
  for (const auto & note : report.notes)
    ADD_FAILURE() << note;
  EXPECT_EQ(report.shellPoints, 120u);
  EXPECT_EQ(report.corners + report.boundaryPoints + report.randomPoints + report.refinementPoints +
              report.contourPoints + report.surfacePoints + report.shellPoints,
            600u);
  EXPECT_EQ(report.randomPoints + report.refinementPoints + report.boundaryPoints, 60u);
  // Shell points sit at one of the offsets from the bladder, not on any structure.
  const auto & bladder = pm.phantomCase.movingMasks[2];
  ASSERT_EQ(pm.names[2], "bladder");
  const double half = 0.5 * bladder.spacing[0];
  std::size_t  shell = 0, onShell = 0;
  for (std::size_t i = 0; i < mesh.origins.size(); ++i)
  {
    if (mesh.origins[i] != morea_core::PointOrigin::Shell)
      continue;
    ++shell;
    EXPECT_EQ(mesh.structures[i], -1);
    double nearest = 1e300;
    for (std::size_t k = 0; k < bladder.size[2]; ++k)
      for (std::size_t j = 0; j < bladder.size[1]; ++j)
        for (std::size_t v = 0; v < bladder.size[0]; ++v)
          if (bladder(v, j, k) != 0)
            nearest = std::min(nearest, Distance(mesh.points[i], bladder.PointAt(v, j, k)));
    onShell += std::abs(nearest - 6.0) <= half + 1e-9 || std::abs(nearest - 15.0) <= half + 1e-9;
    EXPECT_GT(nearest, 0.0); // never inside the bladder
  }
  EXPECT_EQ(shell, 120u);
  // Sliver removal moves a few of them (they are as free as random points).
  EXPECT_GE(onShell, 100u);
  for (const auto & t : mesh.tetrahedra)
    ASSERT_GT(morea_core::SignedVolume(t, mesh.points), 0.0);

  // No shell structure among the structures: a note, and the points go to the rest.
  options.shellStructures = { "stomach" };
  morea_core::MeshGenerationReport none;
  morea_core::GenerateMesh(pm.domain, structures, options, &none);
  EXPECT_EQ(none.shellPoints, 0u);
  EXPECT_EQ(none.notes.size(), 1u);
}

TEST(MeshGenerator, PhantomMeshWithBladderSurface)
{
  const auto & pm = morea_test::PhantomMesh600();
  const auto & mesh = pm.mesh;
  const auto & r = pm.report;
  for (const auto & note : r.notes)
    ADD_FAILURE() << note;
  EXPECT_EQ(mesh.NumberOfPoints(), 600u + r.steinerPoints);
  EXPECT_EQ(r.corners + r.boundaryPoints + r.randomPoints + r.refinementPoints + r.contourPoints + r.surfacePoints +
              r.shellPoints,
            600u);
  EXPECT_EQ(r.shellPoints, 90u); // 15 % on the default shells around the bladder
  EXPECT_GT(r.surfacePoints, 50u);
  EXPECT_GT(r.contourPoints, 300u);
  EXPECT_EQ(r.randomPoints + r.refinementPoints + r.boundaryPoints, 60u);
  EXPECT_GT(r.refinementPoints, 0u);

  // Positively oriented tetrahedra that tile the domain.
  double volume = 0.0;
  for (const auto & t : mesh.tetrahedra)
  {
    const double v = morea_core::SignedVolume(t, mesh.points);
    ASSERT_GT(v, 0.0);
    volume += v;
  }
  const Vec3 e = pm.domain.Extent();
  EXPECT_NEAR(volume, e[0] * e[1] * e[2], 1e-6 * e[0] * e[1] * e[2]);

  // Every constraining triangle is a face of the mesh.
  if (r.steinerPoints == 0)
  {
    std::set<std::array<std::uint32_t, 3>> faces;
    for (const auto & t : mesh.tetrahedra)
      for (int skip = 0; skip < 4; ++skip)
      {
        std::array<std::uint32_t, 3> f{};
        for (int v = 0, n = 0; v < 4; ++v)
          if (v != skip)
            f[n++] = t[v];
        std::sort(f.begin(), f.end());
        faces.insert(f);
      }
    ASSERT_FALSE(mesh.constrainedFaces.empty());
    for (auto f : mesh.constrainedFaces)
    {
      std::sort(f.begin(), f.end());
      EXPECT_TRUE(faces.count(f)) << "constraint triangle is not a mesh face";
    }
  }
  // Pins: exactly the corners are fixed; boundary points are on their faces.
  std::size_t fixed = 0;
  for (std::size_t i = 0; i < mesh.NumberOfPoints(); ++i)
  {
    const auto & pin = mesh.pins[i];
    fixed += (pin[0] != 0 && pin[1] != 0 && pin[2] != 0);
    EXPECT_EQ(morea_core::ProjectToDomain(mesh.points[i], pin, pm.domain), mesh.points[i]);
  }
  EXPECT_EQ(fixed, 8u);

  std::cout << "phantom mesh: " << mesh.NumberOfPoints() << " points (" << r.surfacePoints << " surface, "
            << r.contourPoints << " contour, " << r.shellPoints << " shell, " << r.randomPoints << " random, " << r.refinementPoints
            << " refinement, " << r.boundaryPoints << " on faces, " << r.steinerPoints << " Steiner), "
            << mesh.NumberOfTetrahedra() << " tetrahedra (" << r.slivers << " of quality < 0.05, worst "
            << r.worstQuality << "); placement "
            << r.secondsPlacement << " s, surfaces " << r.secondsSurfaces << " s, TetGen "
            << r.secondsTetrahedralization << " s\n";
}

TEST(MeshGenerator, SameSeedSameMesh)
{
  const auto &                      pm = morea_test::PhantomMesh600();
  const auto & structures = pm.structures;
  morea_core::MeshGeneratorOptions options;
  options.seed = 7;
  const auto again = morea_core::GenerateMesh(pm.domain, structures, options);
  EXPECT_EQ(again.points, pm.mesh.points);
  EXPECT_EQ(again.tetrahedra, pm.mesh.tetrahedra);
  options.seed = 8;
  EXPECT_NE(morea_core::GenerateMesh(pm.domain, structures, options).points, pm.mesh.points);
}
} // namespace
