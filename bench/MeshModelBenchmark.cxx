// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Times the mesh model's steps at the paper's scale (600 points, population
// 700) on the phantom: mesh generation, parallel structure, initial
// population, fold evaluation and rasterisation. A plain timed program: run it
// on an otherwise idle machine and record its output with the machine's name.
#include "morea_core/FoldConstraint.h"
#include "morea_core/InitialPopulation.h"
#include "morea_core/MeshGenerator.h"
#include "morea_core/MeshPointPlacement.h"
#include "morea_core/MeshRasterizer.h"
#include "morea_core/ParallelStructure.h"
#include "morea_core/Phantom.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

namespace
{
using Clock = std::chrono::steady_clock;

double
Seconds(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}
} // namespace

int
main()
{
  std::printf("threads: %u\n", std::thread::hardware_concurrency());
  morea_core::PhantomOptions phantomOptions;
  phantomOptions.spacing = 1.5;
  auto       start = Clock::now();
  const auto phantom = morea_core::PelvisPhantom(phantomOptions).Generate();
  std::printf("phantom at 1.5 mm: %zu voxels, %.3f s\n", phantom.fixedImage.NumberOfVoxels(), Seconds(start));

  // The domain: the bladder's bounding box plus 30 mm, as preprocessing crops.
  const auto & names = morea_core::PelvisPhantom::StructureNames();
  morea_core::Vec3  lo{ { 1e9, 1e9, 1e9 } }, hi{ { -1e9, -1e9, -1e9 } };
  for (const auto & p : morea_core::MaskBoundaryPoints(phantom.movingMasks[2]))
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  const auto        full = morea_core::MeshDomain::OfGrid(phantom.movingImage);
  morea_core::MeshDomain domain;
  for (int a = 0; a < 3; ++a)
  {
    domain.lower[a] = std::max(full.lower[a], lo[a] - 30.0);
    domain.upper[a] = std::min(full.upper[a], hi[a] + 30.0);
  }
  std::vector<morea_core::MeshStructure> structures;
  start = Clock::now();
  for (std::size_t s = 1; s < names.size(); ++s)
    structures.push_back({ names[s], morea_core::MaskBoundaryPoints(phantom.movingMasks[s]), &phantom.movingMasks[s] });
  std::printf("contour points: %.3f s\n", Seconds(start));

  morea_core::MeshGenerationReport report;
  start = Clock::now();
  const auto mesh = morea_core::GenerateMesh(domain, structures, morea_core::MeshGeneratorOptions{}, &report);
  std::printf("mesh: %zu points, %zu tetrahedra, %zu slivers; %.3f s (surfaces %.3f, placement %.3f, TetGen and "
              "sliver removal %.3f)\n",
              mesh.NumberOfPoints(), mesh.NumberOfTetrahedra(), report.slivers, Seconds(start), report.secondsSurfaces,
              report.secondsPlacement, report.secondsTetrahedralization);

  start = Clock::now();
  const morea_core::MeshTopology topology(mesh.tetrahedra, mesh.NumberOfPoints());
  const auto                parallel = morea_core::BuildParallelStructure(topology);
  std::printf("topology and parallel structure: %zu FOS elements, %zu groups, %.4f s\n", parallel.elements.size(),
              parallel.groups.size(), Seconds(start));

  const morea_core::FoldConstraint constraint(topology, mesh.points);
  start = Clock::now();
  const auto population = morea_core::GenerateInitialPopulation(mesh, constraint, 700, 1);
  std::printf("initial population of 700: %.3f s\n", Seconds(start));

  start = Clock::now();
  std::size_t feasible = 0;
  for (const auto & s : population)
    feasible += constraint.Evaluate(s).Feasible();
  const double foldSeconds = Seconds(start);
  std::printf("fold constraint, 700 solutions x 2 meshes: %zu feasible, %.4f s (%.1f ns per tetrahedron)\n", feasible,
              foldSeconds, 1e9 * foldSeconds / (1400.0 * static_cast<double>(mesh.NumberOfTetrahedra())));

  std::array<std::size_t, 3> size{};
  for (int a = 0; a < 3; ++a)
    size[a] = static_cast<std::size_t>((domain.upper[a] - domain.lower[a]) / 1.5) + 1;
  morea_core::Volume<morea_core::Vec3> field(size, { { 1.5, 1.5, 1.5 } }, domain.lower);
  start = Clock::now();
  morea_core::RasterizeDisplacement(topology, population[1].target, population[1].source, field);
  std::printf("rasterisation on %zux%zux%zu voxels: %.3f s\n", size[0], size[1], size[2], Seconds(start));
  return feasible == population.size() ? 0 : 1;
}
