// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Mesh refinement between resolution levels: conforming bisection, exact
// carry-over of solutions, objective values kept, and the level plan.
#include "OptimiserTestProblem.h"

#include "morea_core/EvaluationBackend.h"
#include "morea_core/Error.h"
#include "morea_core/MeshRefinement.h"
#include "morea_core/ParameterSet.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <sstream>

namespace
{
using morea_test::OptimiserTestProblem;

/** Every triangle of a conforming mesh is shared by at most two
 *  tetrahedra, and the boundary triangles cover exactly the box's six faces. */
void
ExpectConforming(const morea_core::TetrahedralMesh & mesh)
{
  std::map<std::array<std::uint32_t, 3>, int> faces;
  for (const auto & t : mesh.tetrahedra)
    for (int skip = 0; skip < 4; ++skip)
    {
      std::array<std::uint32_t, 3> f;
      int                          n = 0;
      for (int c = 0; c < 4; ++c)
        if (c != skip)
          f[n++] = t[c];
      std::sort(f.begin(), f.end());
      ++faces[f];
    }
  double boundaryArea = 0.0;
  for (const auto & [f, count] : faces)
  {
    ASSERT_LE(count, 2) << "a triangle shared by " << count << " tetrahedra";
    if (count == 1)
    {
      const auto & a = mesh.points[f[0]];
      const auto & b = mesh.points[f[1]];
      const auto & c = mesh.points[f[2]];
      const morea_core::Vec3 u{ b[0] - a[0], b[1] - a[1], b[2] - a[2] }, v{ c[0] - a[0], c[1] - a[1], c[2] - a[2] };
      const morea_core::Vec3 n{ u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
      boundaryArea += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
  }
  const morea_core::Vec3 e = mesh.domain.Extent();
  EXPECT_NEAR(boundaryArea, 2.0 * (e[0] * e[1] + e[1] * e[2] + e[0] * e[2]), 1e-6); // no hanging node leaves a hole
}

double
TotalVolume(const morea_core::TetrahedralMesh & mesh)
{
  double v = 0.0;
  for (const auto & t : mesh.tetrahedra)
    v += morea_core::SignedVolume(t, mesh.points);
  return v;
}

TEST(MeshRefinement, BisectsToTheTargetConformingAndPositive)
{
  const OptimiserTestProblem problem;
  const std::vector<double>  uniform(problem.base.NumberOfTetrahedra(), 1.0);
  const auto                 refinement = morea_core::RefineMesh(problem.base, uniform, 3 * problem.base.NumberOfPoints());
  const auto &               mesh = refinement.mesh;
  EXPECT_EQ(mesh.NumberOfPoints(), 3 * problem.base.NumberOfPoints());
  EXPECT_EQ(refinement.midpointOf.size(), 2 * problem.base.NumberOfPoints());
  EXPECT_EQ(refinement.parentTetrahedron.size(), mesh.NumberOfTetrahedra());
  EXPECT_EQ(mesh.pins.size(), mesh.NumberOfPoints());
  EXPECT_EQ(mesh.origins.back(), morea_core::PointOrigin::Midpoint);
  for (std::size_t p = 0; p < problem.base.NumberOfPoints(); ++p)
    EXPECT_EQ(mesh.points[p], problem.base.points[p]); // the coarse points keep their indices
  for (const auto & t : mesh.tetrahedra)
    EXPECT_GT(morea_core::SignedVolume(t, mesh.points), 0.0);
  EXPECT_NEAR(TotalVolume(mesh), TotalVolume(problem.base), 1e-9);
  ExpectConforming(mesh);
  // Pins: a midpoint lies on a face only when its pin says so, and then exactly.
  for (std::size_t p = 0; p < mesh.NumberOfPoints(); ++p)
    for (int a = 0; a < 3; ++a)
    {
      if (mesh.pins[p][a] < 0)
        EXPECT_EQ(mesh.points[p][a], mesh.domain.lower[a]);
      if (mesh.pins[p][a] > 0)
        EXPECT_EQ(mesh.points[p][a], mesh.domain.upper[a]);
    }
  // Longest-edge bisection keeps shapes: no tetrahedron much worse than the coarse mesh's worst.
  double coarseWorst = 1.0, fineWorst = 1.0;
  for (const auto & t : problem.base.tetrahedra)
    coarseWorst = std::min(coarseWorst, morea_core::TetrahedronQuality(problem.base.points[t[0]], problem.base.points[t[1]],
                                                                  problem.base.points[t[2]], problem.base.points[t[3]]));
  for (const auto & t : mesh.tetrahedra)
    fineWorst = std::min(fineWorst, morea_core::TetrahedronQuality(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]],
                                                              mesh.points[t[3]]));
  EXPECT_GT(fineWorst, 0.3 * coarseWorst);
}

TEST(MeshRefinement, PointsGoWhereTheDensityIsHigh)
{
  const OptimiserTestProblem problem;
  std::vector<double>        density(problem.base.NumberOfTetrahedra(), 1.0);
  // Ten times the need in the half x < 15 mm.
  for (std::size_t t = 0; t < density.size(); ++t)
  {
    double x = 0.0;
    for (auto p : problem.base.tetrahedra[t])
      x += 0.25 * problem.base.points[p][0];
    density[t] = x < 15.0 ? 10.0 : 1.0;
  }
  const auto  refinement = morea_core::RefineMesh(problem.base, density, 2 * problem.base.NumberOfPoints());
  std::size_t low = 0, high = 0;
  for (std::size_t p = problem.base.NumberOfPoints(); p < refinement.mesh.NumberOfPoints(); ++p)
    (refinement.mesh.points[p][0] < 15.0 ? low : high) += 1;
  EXPECT_GT(low, 2 * high);
  EXPECT_THROW(morea_core::RefineMesh(problem.base, std::vector<double>(3, 1.0), 200), morea_core::Error);
  density[0] = 0.0;
  EXPECT_THROW(morea_core::RefineMesh(problem.base, density, 200), morea_core::Error);
}

TEST(MeshRefinement, CarriedSolutionsKeepTheirDeformationFoldsAndObjectives)
{
  OptimiserTestProblem problem;
  problem.data.samplingRate = 2.0; // enough samples per refined tetrahedron to compare means
  const auto            options = problem.Options(11);
  const auto            population = problem.InitialPopulation(options);
  const std::vector<double> uniform(problem.base.NumberOfTetrahedra(), 1.0);
  const auto            refinement = morea_core::RefineMesh(problem.base, uniform, 4 * problem.base.NumberOfPoints());

  // The fine model, as a level's would be.
  const morea_core::MeshTopology       topology(refinement.mesh.tetrahedra, refinement.mesh.NumberOfPoints());
  const morea_core::FoldConstraint     constraint(topology, refinement.mesh.points);
  const std::vector<double>       elasticity(topology.NumberOfTetrahedra(), 1.0);
  const morea_core::TetrahedronEvaluator fine(topology, constraint, elasticity, problem.data);
  const morea_core::TetrahedronEvaluator & coarse = *problem.evaluator;

  auto totals = [](const morea_core::TetrahedronEvaluator & evaluator, const morea_core::DualMesh & solution) {
    morea_core::ObjectiveTotals sum;
    for (std::size_t t = 0; t < evaluator.Topology().NumberOfTetrahedra(); ++t)
      sum.Add(evaluator.Evaluate(t, solution));
    return sum;
  };
  std::size_t compared = 0;
  for (const auto & solution : population)
  {
    const morea_core::DualMesh carried = morea_core::CarryOver(refinement, solution);
    ASSERT_EQ(carried.source.size(), refinement.mesh.NumberOfPoints());
    // The same map: each fine point's target is the coarse map of its source.
    for (std::size_t f = 0; f < topology.NumberOfTetrahedra(); ++f)
    {
      const auto & child = topology.Tetrahedra()[f];
      const auto & parent = problem.base.tetrahedra[refinement.parentTetrahedron[f]];
      // Source and target volume ratios of child to parent agree (one affine map).
      const double sourceRatio = morea_core::SignedVolume(child, carried.source) / morea_core::SignedVolume(parent, solution.source);
      const double targetRatio = morea_core::SignedVolume(child, carried.target) / morea_core::SignedVolume(parent, solution.target);
      ASSERT_NEAR(sourceRatio, targetRatio, 1e-9);
    }
    const bool coarseFeasible = problem.constraint->Evaluate(solution).Feasible();
    EXPECT_EQ(constraint.Evaluate(carried).Feasible(), coarseFeasible);
    if (!coarseFeasible)
      continue;
    const auto a = totals(coarse, solution).ToFitness(problem.topology.NumberOfTetrahedra());
    const auto b = totals(fine, carried).ToFitness(topology.NumberOfTetrahedra());
    // Intensity and guidance are means over samples: the same up to where the samples fall.
    EXPECT_NEAR(b.objectives[1], a.objectives[1], 0.05 * a.objectives[1] + 1e-4);
    EXPECT_NEAR(b.objectives[2], a.objectives[2], 0.05 * a.objectives[2] + 1e-4);
    ++compared;
  }
  EXPECT_GT(compared, population.size() / 2);
}

TEST(MeshRefinement, DensityFollowsMismatch)
{
  const OptimiserTestProblem                         problem;
  std::vector<std::vector<morea_core::TetrahedronValues>> values(1, std::vector<morea_core::TetrahedronValues>(
                                                                  problem.base.NumberOfTetrahedra()));
  for (auto & v : values[0])
  {
    v.samples = 10.0;
    v.intensity = 1.0;
  }
  values[0][5].intensity = 50.0;
  const auto density = morea_core::RefinementDensity(problem.base, values);
  ASSERT_EQ(density.size(), problem.base.NumberOfTetrahedra());
  EXPECT_GT(density[5], 2.0 * density[6]);
  for (double d : density)
    EXPECT_GE(d, 1.0);
}

TEST(MeshLevelPlan, SplitsTheGenerationsAndRefusesPlansWithoutRoom)
{
  auto plan = morea_core::MeshLevelPlan::FromParameters(morea_core::ParameterSet::FromToml(
    "ea_num_generations = 100\nmorea_max_num_mesh_levels = 3\nmorea_num_generations_per_level = 30\n"));
  EXPECT_EQ(plan.FirstGeneration(0), 0u);
  EXPECT_EQ(plan.EndGeneration(0), 30u);
  EXPECT_EQ(plan.FirstGeneration(2), 60u);
  EXPECT_EQ(plan.EndGeneration(2), 100u);
  EXPECT_EQ(plan.PointsAt(2, 600), 3174u);
  EXPECT_EQ(morea_core::MeshLevelPlan::FromParameters(morea_core::ParameterSet{}).levels, 1u);
  EXPECT_THROW(morea_core::MeshLevelPlan::FromParameters(morea_core::ParameterSet::FromToml(
                 "ea_num_generations = 60\nmorea_max_num_mesh_levels = 3\nmorea_num_generations_per_level = 30\n")),
               morea_core::Error);
  EXPECT_THROW(morea_core::MeshLevelPlan::FromParameters(morea_core::ParameterSet::FromToml("morea_max_num_mesh_levels = 2\n")),
               morea_core::Error);
  EXPECT_THROW(
    morea_core::MeshLevelPlan::FromParameters(morea_core::ParameterSet::FromToml("morea_num_generations_per_level = 20\n")),
    morea_core::Error);
}

TEST(MeshRefinement, AnOptimiserContinuesFromACarriedPopulation)
{
  // Level 1 on the coarse mesh, then level 2 on the refined one from the
  // carried population and archive: generations number on, the archive
  // starts from the carried front, and every archived solution is fold-free.
  OptimiserTestProblem problem;
  auto                 options = problem.Options(3, 6);
  options.generations = 4;
  auto coarseBackend = morea_core::CreateCpuEvaluationBackend(*problem.evaluator, 1);
  morea_core::MoRvGomea coarse(problem.base, problem.topology, problem.parallel, *problem.constraint, *coarseBackend, options);
  coarse.Initialize(problem.InitialPopulation(options));
  coarse.Run();

  const std::vector<double> uniform(problem.base.NumberOfTetrahedra(), 1.0);
  const auto                refinement = morea_core::RefineMesh(problem.base, uniform, 2 * problem.base.NumberOfPoints());
  const morea_core::MeshTopology topology(refinement.mesh.tetrahedra, refinement.mesh.NumberOfPoints());
  const auto                parallel = morea_core::BuildParallelStructure(topology);
  const morea_core::FoldConstraint constraint(topology, refinement.mesh.points);
  const std::vector<double>   elasticity(topology.NumberOfTetrahedra(), 1.0);
  const morea_core::TetrahedronEvaluator evaluator(topology, constraint, elasticity, problem.data);
  auto fineBackend = morea_core::CreateCpuEvaluationBackend(evaluator, 1);
  auto fineOptions = options;
  fineOptions.firstGeneration = 4;
  fineOptions.generations = 6;
  morea_core::MoRvGomea             fine(refinement.mesh, topology, parallel, constraint, *fineBackend, fineOptions);
  std::vector<morea_core::DualMesh> population, archived;
  for (const auto & s : coarse.Population())
    population.push_back(morea_core::CarryOver(refinement, s));
  for (const auto & e : coarse.Archive().Entries())
    archived.push_back(morea_core::CarryOver(refinement, e.solution));
  fine.Initialize(population, archived);
  EXPECT_EQ(fine.Generation(), 4u);
  EXPECT_GE(fine.Archive().Size(), 1u);
  fine.Run();
  EXPECT_EQ(fine.Generation(), 6u);
  EXPECT_EQ(fine.History().front().generation, 4u);
  EXPECT_EQ(fine.History().back().generation, 6u);
  for (const auto & e : fine.Archive().Entries())
    EXPECT_TRUE(constraint.Evaluate(e.solution).Feasible());
  // Its checkpoint loads into an optimiser of the same level only.
  const std::string bytes = fine.CheckpointBytes();
  morea_core::MoRvGomea  again(refinement.mesh, topology, parallel, constraint, *fineBackend, fineOptions);
  std::istringstream in(bytes);
  EXPECT_NO_THROW(again.Load(in));
  EXPECT_EQ(again.Generation(), 6u);
}
} // namespace
