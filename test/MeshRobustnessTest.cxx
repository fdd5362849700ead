// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of what keeps mesh generation from crashing on real surfaces: child
// processes that take a crash, the checks of constraint surfaces, and the
// constrained tetrahedralisation falling back to fewer surfaces.
#include "MeshTestSupport.h"

#include "ConstraintSurfaces.h" // the mesh layer's own
#include "morea_core/ChildProcess.h"
#include "morea_core/Error.h"
#include "morea_core/SurfaceCheck.h"
#include "morea_core/Tetrahedralization.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <thread>

namespace
{
using morea_core::TriangleSurface;
using morea_core::Vec3;

/** An octahedron of radius r around c, outward oriented. */
TriangleSurface
Octahedron(const Vec3 & c, double r)
{
  TriangleSurface s;
  s.vertices = { { c[0] + r, c[1], c[2] }, { c[0] - r, c[1], c[2] }, { c[0], c[1] + r, c[2] },
                 { c[0], c[1] - r, c[2] }, { c[0], c[1], c[2] + r }, { c[0], c[1], c[2] - r } };
  s.triangles = { { 0, 2, 4 }, { 2, 1, 4 }, { 1, 3, 4 }, { 3, 0, 4 }, { 2, 0, 5 }, { 1, 2, 5 }, { 3, 1, 5 }, { 0, 3, 5 } };
  return s;
}

TEST(ChildProcess, ReturnsBytesErrorsCrashesAndTimeOuts)
{
  ASSERT_TRUE(morea_core::ChildProcessesAvailable());
  // Bytes, also more than a pipe holds at once.
  const std::string big(20'000'000, 'x');
  auto              r = morea_core::RunInChildProcess([&] { return big + "end"; }, 60.0);
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_EQ(r.bytes.size(), big.size() + 3);
  EXPECT_EQ(r.bytes.substr(r.bytes.size() - 3), "end");
  r = morea_core::RunInChildProcess([] { return std::string(); }, 60.0);
  EXPECT_TRUE(r.ok);
  EXPECT_TRUE(r.bytes.empty());

  // An exception comes back as its message.
  r = morea_core::RunInChildProcess([]() -> std::string { throw morea_core::Error("no luck"); }, 60.0);
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.crashed);
  EXPECT_EQ(r.failure, "no luck");

  // A crash is a failure here, and this process goes on.
  r = morea_core::RunInChildProcess(
    []() -> std::string {
      std::raise(SIGSEGV);
      return "unreachable";
    },
    60.0);
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(r.crashed);
  EXPECT_NE(r.failure.find("signal 11"), std::string::npos) << r.failure;
  r = morea_core::RunInChildProcess([]() -> std::string { std::abort(); }, 60.0);
  EXPECT_TRUE(r.crashed);
  EXPECT_NE(r.failure.find("signal 6"), std::string::npos) << r.failure;
  // What it printed before (an assertion, as TetGen's) is kept for the failure, not printed here.
  r = morea_core::RunInChildProcess(
    []() -> std::string {
      std::fprintf(stdout, "some progress\n");
      std::fprintf(stderr, "prog: /build/tetgen.cxx:18522: int f(): Assertion `n >= 3' failed.\n");
      std::abort();
    },
    60.0);
  EXPECT_EQ(r.failure, "crashed (signal 6, Aborted) saying \"/build/tetgen.cxx:18522: int f(): Assertion `n >= 3' "
                       "failed.\"");
  r = morea_core::RunInChildProcess([]() -> std::string { std::_Exit(0); }, 60.0);
  EXPECT_TRUE(r.crashed);
  EXPECT_NE(r.failure.find("without an answer"), std::string::npos) << r.failure;

  // A child that hangs is killed.
  const auto start = std::chrono::steady_clock::now();
  r = morea_core::RunInChildProcess(
    []() -> std::string {
      std::this_thread::sleep_for(std::chrono::seconds(30));
      return "late";
    },
    0.5);
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(r.timedOut);
  EXPECT_EQ(r.failure, "did not finish within 0.5 s (killed)");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
}

TEST(SurfaceCheck, FindsHolesFlipsFoldsAndCrossings)
{
  const TriangleSurface good = Octahedron({ 0, 0, 0 }, 1.0);
  EXPECT_TRUE(morea_core::CheckSurface(good).Valid()) << morea_core::CheckSurface(good).Describe();
  EXPECT_EQ(morea_core::CheckSurface(good).Describe(), "");

  TriangleSurface hole = good;
  hole.triangles.pop_back();
  EXPECT_EQ(morea_core::CheckSurface(hole).openEdges, 3u);
  EXPECT_EQ(morea_core::CheckSurface(hole).Describe(), "3 open edges");

  TriangleSurface flipped = good;
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_EQ(morea_core::CheckSurface(flipped).misorientedEdges, 3u);

  // Two components are fine apart, not when they cross or touch.
  const auto merge = [](TriangleSurface a, const TriangleSurface & b) {
    const auto offset = static_cast<std::uint32_t>(a.vertices.size());
    a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (const auto & t : b.triangles)
      a.triangles.push_back({ t[0] + offset, t[1] + offset, t[2] + offset });
    return a;
  };
  EXPECT_TRUE(morea_core::CheckSurface(merge(good, Octahedron({ 3, 0, 0 }, 1.0))).Valid());
  const auto crossing = morea_core::CheckSurface(merge(good, Octahedron({ 1.2, 0.3, 0.1 }, 1.0)));
  EXPECT_GT(crossing.crossingPairs, 0u);
  EXPECT_EQ(crossing.openEdges, 0u);
  EXPECT_GT(morea_core::CheckSurface(merge(good, Octahedron({ 2.0, 0, 0 }, 1.0))).crossingPairs, 0u); // touching at a vertex
  EXPECT_EQ(morea_core::CountCrossings(good, Octahedron({ 3, 0, 0 }, 1.0)), 0u);
  EXPECT_GT(morea_core::CountCrossings(good, Octahedron({ 0.5, 0.5, 0.5 }, 1.0)), 0u);
  // One inside the other without touching does not cross (TetGen takes nested surfaces).
  EXPECT_EQ(morea_core::CountCrossings(good, Octahedron({ 0.1, 0, 0 }, 0.3)), 0u);

  // The top vertex pulled down into the plane of a lower triangle: triangle
  // 0-2-4 folds onto 2-0-5 across their shared edge (as decimation can fold
  // a thin part), and the top's other triangles cross the bottom's.
  TriangleSurface folded = good;
  folded.vertices[4] = { 0.25, 0.25, -0.5 };
  EXPECT_GT(morea_core::CheckSurface(folded).crossingPairs, 0u) << morea_core::CheckSurface(folded).Describe();
  // An inside-out surface that does not cross itself is not caught here
  // (TetGen takes it as a closed surface all the same).
  TriangleSurface inverted = good;
  for (auto & t : inverted.triangles)
    std::swap(t[1], t[2]);
  EXPECT_TRUE(morea_core::CheckSurface(inverted).Valid());

  TriangleSurface flat = good;
  flat.vertices[4] = { 0.5, 0.5, 0.0 }; // on the equator's edge 0-2: triangles 0-2-4 is flat
  EXPECT_GT(morea_core::CheckSurface(flat).degenerateTriangles, 0u);
}

/** The domain [0, 10]^3: corners, a few inner points, and two surfaces. */
struct TwoSurfaces
{
  std::vector<Vec3>                         points;
  std::vector<std::array<std::uint32_t, 3>> first, second;

  TwoSurfaces(const TriangleSurface & a, const TriangleSurface & b)
  {
    morea_core::MeshDomain d;
    d.upper = { { 10, 10, 10 } };
    points = morea_core::DomainCorners(d);
    for (const auto * s : { &a, &b })
    {
      const auto offset = static_cast<std::uint32_t>(points.size());
      points.insert(points.end(), s->vertices.begin(), s->vertices.end());
      for (const auto & t : s->triangles)
        (s == &a ? first : second).push_back({ t[0] + offset, t[1] + offset, t[2] + offset });
    }
    points.push_back({ 8, 8, 8 });
    points.push_back({ 2, 8, 3 });
  }
  std::vector<std::array<std::uint32_t, 3>>
  Both() const
  {
    auto all = first;
    all.insert(all.end(), second.begin(), second.end());
    return all;
  }
};

TEST(Tetrahedralization, CrossingConstraintsAreAnErrorNotACrash)
{
  const TwoSurfaces crossing(Octahedron({ 5, 5, 5 }, 2.0), Octahedron({ 6.1, 5.3, 5.2 }, 2.0));
  // Each alone is fine.
  EXPECT_NO_THROW(morea_core::Tetrahedralize(crossing.points, crossing.first));
  // Together TetGen cannot keep their triangles as faces: in TetGen 1.5 its
  // error frees memory twice, which the child process takes.
  try
  {
    morea_core::Tetrahedralize(crossing.points, crossing.Both());
    ADD_FAILURE() << "TetGen recovered crossing constraint triangles";
  }
  catch (const morea_core::Error & e)
  {
    std::cout << "TetGen on crossing surfaces: " << e.what() << "\n";
    EXPECT_NE(std::string(e.what()).find("TetGen"), std::string::npos);
  }
  // A hang is an error too (a time-out far too short for any run).
  morea_core::TetrahedralizationOptions impatient;
  impatient.timeoutSeconds = 1e-9;
  EXPECT_THROW(morea_core::Tetrahedralize(crossing.points, crossing.first, impatient), morea_core::Error);
}

TEST(ConstrainedTetrahedralization, DropsTheSurfaceTetGenFailsOnWithANote)
{
  const TwoSurfaces               crossing(Octahedron({ 5, 5, 5 }, 2.0), Octahedron({ 6.1, 5.3, 5.2 }, 2.0));
  morea_core::ConstrainedTetrahedralization tetrahedralization;
  tetrahedralization.AddSurface("bladder", crossing.first);
  tetrahedralization.AddSurface("rectum", crossing.second);
  std::vector<std::string> notes;
  // A trial may not drop surfaces: it fails.
  EXPECT_THROW(tetrahedralization.Run(crossing.points, false, notes), morea_core::Error);
  EXPECT_EQ(tetrahedralization.NumberOfSurfaces(), 2u);
  EXPECT_TRUE(notes.empty());
  // Otherwise the first surface stays, the second goes, with a note.
  const auto result = tetrahedralization.Run(crossing.points, true, notes);
  EXPECT_EQ(tetrahedralization.NumberOfSurfaces(), 1u);
  EXPECT_EQ(tetrahedralization.Triangles(), crossing.first);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].rfind("surface constraint of rectum dropped (its vertices stay mesh points): TetGen", 0), 0u)
    << notes[0];
  double volume = 0.0;
  for (const auto & t : result.tetrahedra)
    volume += morea_core::SignedVolume(t, result.points);
  EXPECT_NEAR(volume, 1000.0, 1e-9);
}

TEST(ConstraintSurfaces, SurfacesThatMeetAreLeftOutWithTheReason)
{
  // Two touching boxes on one grid: their blurred surfaces cross.
  morea_core::Volume<std::uint8_t> a({ { 30, 30, 30 } }, { { 1, 1, 1 } }, { { 0, 0, 0 } });
  morea_core::Volume<std::uint8_t> b = a;
  for (std::size_t k = 8; k < 22; ++k)
    for (std::size_t j = 8; j < 22; ++j)
      for (std::size_t i = 6; i < 24; ++i)
        (i < 15 ? a : b)(i, j, k) = 1;
  morea_core::MeshDomain domain = morea_core::MeshDomain::OfGrid(a);
  std::vector<std::string>     notes;
  std::vector<TriangleSurface> accepted;
  auto                         first = morea_core::PrepareConstraintSurface("left", a, domain, 80, 0.1, accepted, notes);
  ASSERT_TRUE(first);
  EXPECT_TRUE(notes.empty());
  EXPECT_TRUE(morea_core::CheckSurface(*first).Valid());
  accepted.push_back(*first);
  EXPECT_FALSE(morea_core::PrepareConstraintSurface("right", b, domain, 80, 0.1, accepted, notes));
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].rfind("surface of right meets another structure's surface (", 0), 0u) << notes[0];
  EXPECT_NE(notes[0].find("its contour points are used instead"), std::string::npos);
}

/** What running TetGen in a child costs: the phantom's mesh both ways. */
TEST(Tetrahedralization, ChildProcessOverhead)
{
  const auto &                      pm = morea_test::PhantomMesh600();
  const auto & structures = pm.structures;
  morea_core::MeshGeneratorOptions options;
  options.seed = 7;
  double                      seconds[2] = { 0.0, 0.0 };
  morea_core::MeshGenerationReport reports[2];
  morea_core::TetrahedralMesh      meshes[2];
  for (int repeat = 0; repeat < 3; ++repeat)
    for (int isolated = 0; isolated < 2; ++isolated)
    {
      options.tetrahedralization.isolated = isolated == 1;
      meshes[isolated] = morea_core::GenerateMesh(pm.domain, structures, options, &reports[isolated]);
      seconds[isolated] += reports[isolated].secondsTetrahedralization / 3.0;
    }
  EXPECT_EQ(meshes[0].points, meshes[1].points);
  EXPECT_EQ(meshes[0].tetrahedra, meshes[1].tetrahedra);
  EXPECT_EQ(meshes[1].points, pm.mesh.points);
  std::cout << "tetrahedralisation of the phantom's 600-point mesh (TetGen runs for refinement and sliver removal): "
            << seconds[0] << " s in this process, " << seconds[1] << " s in a child process\n";

  // The fallback after a failure runs each TetGen run in a child of its own:
  // one constrained run of the same mesh's points, both ways.
  std::vector<Vec3> points(pm.mesh.points.begin(), pm.mesh.points.begin() + 600);
  double            perRun[2] = { 0.0, 0.0 };
  for (int isolated = 0; isolated < 2; ++isolated)
  {
    morea_core::TetrahedralizationOptions o;
    o.isolated = isolated == 1;
    const auto start = std::chrono::steady_clock::now();
    for (int run = 0; run < 20; ++run)
      EXPECT_EQ(morea_core::Tetrahedralize(points, pm.mesh.constrainedFaces, o).tetrahedra.size(),
                pm.mesh.NumberOfTetrahedra());
    perRun[isolated] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / 20.0;
  }
  std::cout << "one constrained TetGen run of it: " << 1e3 * perRun[0] << " ms in this process, " << 1e3 * perRun[1]
            << " ms in a child process of its own\n";
}
} // namespace
