// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The objectives per tetrahedron: exact partial evaluation, the background
// rule, guidance truncation, and CPU backend batches.
#include "OptimiserTestProblem.h"

#include "morea_core/MagnitudeObjective.h"
#include "morea_core/Random.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace morea_core;
using morea_test::OptimiserTestProblem;

namespace
{
ObjectiveTotals
FullTotals(const TetrahedronEvaluator & evaluator, const DualMesh & solution)
{
  ObjectiveTotals totals;
  for (std::size_t t = 0; t < evaluator.Topology().NumberOfTetrahedra(); ++t)
    totals.Add(evaluator.Evaluate(t, solution));
  return totals;
}

void
ExpectRelativelyEqual(double a, double b, double relative)
{
  EXPECT_NEAR(a, b, relative * std::max(std::abs(a), std::abs(b)) + 1e-300);
}
} // namespace

TEST(TetrahedronObjectives, IdenticalImagesAndMeshesCostNothing)
{
  OptimiserTestProblem problem;
  problem.data.moving = problem.data.fixed;
  const TetrahedronEvaluator evaluator(problem.topology, *problem.constraint, problem.elasticity, problem.data);
  const DualMesh             identity = DualMesh::FromBase(problem.base);
  const Fitness              f = FullTotals(evaluator, identity).ToFitness(problem.topology.NumberOfTetrahedra());
  EXPECT_TRUE(f.feasible);
  EXPECT_EQ(f.objectives[0], 0.0);
  EXPECT_EQ(f.objectives[1], 0.0);
  EXPECT_EQ(f.objectives[2], 0.0);
}

TEST(TetrahedronObjectives, MagnitudeMatchesTheWholeObjectiveAndSamplesFollowVolume)
{
  OptimiserTestProblem problem;
  const auto           population = problem.InitialPopulation(problem.Options());
  const DualMesh &     s = population[3];
  const ObjectiveTotals totals = FullTotals(*problem.evaluator, s);
  const Fitness         f = totals.ToFitness(problem.topology.NumberOfTetrahedra());
  ExpectRelativelyEqual(f.objectives[0], MagnitudeObjective(problem.topology, s, problem.elasticity), 1e-12);
  // Both meshes tile the 30 mm box, so each direction draws about
  // rate * 27000 samples (rounding per tetrahedron adds at most 1/2 each).
  const double expected = 2.0 * problem.data.samplingRate * 30.0 * 30.0 * 30.0;
  EXPECT_NEAR(totals.sum.samples, expected, 0.5 * 2.0 * static_cast<double>(problem.topology.NumberOfTetrahedra()));
  EXPECT_GT(f.objectives[1], 0.0);
  EXPECT_GT(f.objectives[2], 0.0);
}

namespace
{
/** Moves every FOS element of a solution in turn, updating its totals by
 *  partial evaluations only, and compares them with a full evaluation. */
void
ExpectPartialEvaluationsSumToTheFullOne(const OptimiserTestProblem & problem)
{
  const auto           population = problem.InitialPopulation(problem.Options());
  DualMesh             solution = population[1];
  ObjectiveTotals      running = FullTotals(*problem.evaluator, solution);
  std::vector<TetrahedronValues> cached(problem.topology.NumberOfTetrahedra());
  for (std::size_t t = 0; t < cached.size(); ++t)
    cached[t] = problem.evaluator->Evaluate(t, solution);
  // Move every FOS element in turn to another solution's positions, updating
  // the totals by partial evaluations only; then compare with a full one.
  auto backend = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  RandomGenerator random(11);
  for (int round = 0; round < 3; ++round)
    for (const auto & element : problem.parallel.elements)
    {
      const DualMesh &  donor = population[2 + static_cast<std::size_t>(random.Uniform() * 20.0)];
      std::vector<Vec3> source, target;
      for (std::uint32_t p : element.points)
      {
        source.push_back(donor.source[p]);
        target.push_back(donor.target[p]);
      }
      std::vector<TetrahedronValues> values(element.dependentTetrahedra.size());
      PartialCandidate               c{ &solution, &element, source.data(), target.data(), values.data() };
      backend->EvaluatePartials({ c });
      for (std::size_t k = 0; k < values.size(); ++k)
      {
        running.Add(cached[element.dependentTetrahedra[k]], -1.0);
        running.Add(values[k]);
        cached[element.dependentTetrahedra[k]] = values[k];
      }
      for (std::size_t k = 0; k < element.points.size(); ++k)
      {
        solution.source[element.points[k]] = source[k];
        solution.target[element.points[k]] = target[k];
      }
    }
  const ObjectiveTotals full = FullTotals(*problem.evaluator, solution);
  const std::size_t     n = problem.topology.NumberOfTetrahedra();
  const Fitness         a = running.ToFitness(n), b = full.ToFitness(n);
  for (std::size_t m = 0; m < NumberOfObjectives; ++m)
    ExpectRelativelyEqual(a.objectives[m], b.objectives[m], 1e-6);
  EXPECT_EQ(running.sum.samples, full.sum.samples);
  EXPECT_EQ(a.feasible, b.feasible);
  ExpectRelativelyEqual(running.sum.foldValue, full.sum.foldValue, 1e-6);
}
} // namespace

TEST(TetrahedronObjectives, SumOfPartialEvaluationsEqualsFullEvaluation)
{
  OptimiserTestProblem problem;
  ExpectPartialEvaluationsSumToTheFullOne(problem);
}

TEST(TetrahedronObjectives, SumOfPartialEvaluationsEqualsFullEvaluationWithRigidStructures)
{
  OptimiserTestProblem problem;
  problem.UseRigidSlab();
  ExpectPartialEvaluationsSumToTheFullOne(problem);
}

TEST(TetrahedronObjectives, AStrainLimitKeepsTheFrontsRigidStructuresWithinIt)
{
  OptimiserTestProblem problem;
  problem.UseRigidSlab(1000.0, 0.02);
  ExpectPartialEvaluationsSumToTheFullOne(problem);
  // Initial deformations strain the slab beyond 0.02: those solutions
  // violate the constraint like folded ones.
  const auto  population = problem.InitialPopulation(problem.Options());
  std::size_t beyond = 0;
  for (const auto & s : population)
    beyond += FullTotals(*problem.evaluator, s).ToFitness(problem.topology.NumberOfTetrahedra()).feasible ? 0 : 1;
  EXPECT_GT(beyond, 0u);
  // The optimiser keeps only solutions within it in its archive; the
  // refusal bound changes none of its decisions.
  auto        backend = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  GomeaOptions options = problem.Options(7, 10);
  MoRvGomea   optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options);
  optimiser.Initialize(problem.InitialPopulation(options));
  optimiser.Run();
  ASSERT_GT(optimiser.Archive().Size(), 0u);
  for (const auto & e : optimiser.Archive().Entries())
    for (std::size_t t = 0; t < problem.topology.NumberOfTetrahedra(); ++t)
    {
      double violated = 0.0;
      const auto & tet = problem.topology.Tetrahedra()[t];
      EXPECT_EQ(TetrahedronRigidViolation(problem.rigidity, t, CornersOf(tet, e.solution.source),
                                          CornersOf(tet, e.solution.target), violated),
                0.0);
    }
  options.boundRefusals = false;
  MoRvGomea unbounded(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options);
  unbounded.Initialize(problem.InitialPopulation(options));
  unbounded.Run();
  ASSERT_EQ(unbounded.Archive().Size(), optimiser.Archive().Size());
  for (std::size_t i = 0; i < optimiser.Archive().Size(); ++i)
    EXPECT_EQ(unbounded.Archive().Entries()[i].fitness.objectives, optimiser.Archive().Entries()[i].fitness.objectives);
}

TEST(TetrahedronObjectives, RigidStructuresAddTheirTermToTheMagnitude)
{
  OptimiserTestProblem problem;
  const auto           population = problem.InitialPopulation(problem.Options());
  const DualMesh &     s = population[3];
  const double         plain = FullTotals(*problem.evaluator, s).ToFitness(problem.topology.NumberOfTetrahedra()).objectives[0];
  problem.UseRigidSlab();
  const Fitness f = FullTotals(*problem.evaluator, s).ToFitness(problem.topology.NumberOfTetrahedra());
  ExpectRelativelyEqual(f.objectives[0],
                        MagnitudeObjective(problem.topology, s, problem.elasticity, problem.rigidity), 1e-12);
  EXPECT_GT(f.objectives[0], plain) << "the initial deformations strain the rigid slab";
  // Emptied, the model the evaluator reads adds nothing; nor did it change
  // the other objectives.
  problem.rigidity = {};
  const Fitness g = FullTotals(*problem.evaluator, s).ToFitness(problem.topology.NumberOfTetrahedra());
  EXPECT_EQ(g.objectives[0], plain);
  EXPECT_EQ(g.objectives[1], f.objectives[1]);
  EXPECT_EQ(g.objectives[2], f.objectives[2]);
}

TEST(TetrahedronObjectives, BackgroundAgainstTissueCostsOne)
{
  OptimiserTestProblem problem;
  // Moving image all background, fixed all tissue: every sample costs 1.
  for (std::size_t i = 0; i < problem.data.moving.data.size(); i += 2)
  {
    problem.data.moving.data[i] = 0.0f;
    problem.data.fixed.data[i] = 0.5f;
  }
  const TetrahedronEvaluator evaluator(problem.topology, *problem.constraint, problem.elasticity, problem.data);
  const Fitness f = FullTotals(evaluator, DualMesh::FromBase(problem.base)).ToFitness(problem.topology.NumberOfTetrahedra());
  EXPECT_DOUBLE_EQ(f.objectives[1], 1.0);
  // Both background: nothing.
  for (std::size_t i = 0; i < problem.data.fixed.data.size(); i += 2)
    problem.data.fixed.data[i] = 0.0f;
  const TetrahedronEvaluator both(problem.topology, *problem.constraint, problem.elasticity, problem.data);
  EXPECT_EQ(FullTotals(both, DualMesh::FromBase(problem.base)).ToFitness(problem.topology.NumberOfTetrahedra()).objectives[1],
            0.0);
}

TEST(TetrahedronObjectives, GuidanceCountsOnlySamplesNearAContour)
{
  OptimiserTestProblem problem;
  // Distances everywhere beyond the radius on both sides: no guidance at all,
  // however far the structures disagree.
  for (auto * v : { &problem.data.fixed, &problem.data.moving })
    for (std::size_t i = 1; i < v->data.size(); i += 2)
      v->data[i] = v == &problem.data.fixed ? 50.0f : 3.0f;
  const TetrahedronEvaluator far(problem.topology, *problem.constraint, problem.elasticity, problem.data);
  const DualMesh             base = DualMesh::FromBase(problem.base);
  EXPECT_EQ(FullTotals(far, base).sum.guidance, 0.0);
  // Moving distances 1 mm (within r = 3), fixed 50 mm: only the
  // moving-to-fixed direction counts, each sample (r-d)/r (d-d')^2.
  for (std::size_t i = 1; i < problem.data.moving.data.size(); i += 2)
    problem.data.moving.data[i] = 1.0f;
  const TetrahedronEvaluator near(problem.topology, *problem.constraint, problem.elasticity, problem.data);
  const ObjectiveTotals       totals = FullTotals(near, base);
  const double                perSample = (3.0 - 1.0) / 3.0 * 49.0 * 49.0;
  EXPECT_NEAR(totals.sum.guidance, perSample * totals.sum.samples / 2.0, 1e-6 * totals.sum.guidance);
}

TEST(TetrahedronObjectives, FoldedTetrahedraAreCountedInBothMeshes)
{
  OptimiserTestProblem problem;
  DualMesh             s = DualMesh::FromBase(problem.base);
  // Push an inner point through the opposite face of one of its tetrahedra.
  const std::uint32_t inner = static_cast<std::uint32_t>(1 + 5 * (1 + 5 * 1)); // grid point (1,1,1)
  s.target[inner] = { 25.0, 25.0, 25.0 };
  const Fitness f = FullTotals(*problem.evaluator, s).ToFitness(problem.topology.NumberOfTetrahedra());
  EXPECT_FALSE(f.feasible);
  EXPECT_NEAR(f.constraint, problem.constraint->Evaluate(s).value, 1e-9);
  EXPECT_GT(f.constraint, 0.0);
}

TEST(CpuEvaluationBackend, BatchResultDoesNotDependOnOrderOrThreads)
{
  OptimiserTestProblem problem;
  const auto           population = problem.InitialPopulation(problem.Options());
  // All elements of the first parallel group for 5 solutions.
  std::vector<std::vector<Vec3>>              sources, targets;
  std::vector<std::vector<TetrahedronValues>> one, two;
  std::vector<PartialCandidate>               a, b;
  for (std::size_t s = 0; s < 5; ++s)
    for (std::uint32_t e : problem.parallel.groups[0])
    {
      const auto &      element = problem.parallel.elements[e];
      std::vector<Vec3> src, tgt;
      for (std::uint32_t p : element.points)
      {
        src.push_back(population[10 + s].source[p]);
        tgt.push_back(population[10 + s].target[p]);
      }
      sources.push_back(src);
      targets.push_back(tgt);
      one.emplace_back(element.dependentTetrahedra.size());
      two.emplace_back(element.dependentTetrahedra.size());
    }
  std::size_t i = 0;
  for (std::size_t s = 0; s < 5; ++s)
    for (std::uint32_t e : problem.parallel.groups[0])
    {
      a.push_back({ &population[s], &problem.parallel.elements[e], sources[i].data(), targets[i].data(), one[i].data() });
      b.push_back({ &population[s], &problem.parallel.elements[e], sources[i].data(), targets[i].data(), two[i].data() });
      ++i;
    }
  std::reverse(b.begin(), b.end());
  CreateCpuEvaluationBackend(*problem.evaluator, 1)->EvaluatePartials(a);
  CreateCpuEvaluationBackend(*problem.evaluator, 3)->EvaluatePartials(b);
  for (std::size_t j = 0; j < one.size(); ++j)
    for (std::size_t k = 0; k < one[j].size(); ++k)
    {
      EXPECT_EQ(one[j][k].intensity, two[j][k].intensity);
      EXPECT_EQ(one[j][k].guidance, two[j][k].guidance);
      EXPECT_EQ(one[j][k].magnitude, two[j][k].magnitude);
    }
}

TEST(CpuEvaluationBackend, FoldChecksRepairCandidatesInPlace)
{
  OptimiserTestProblem problem;
  const auto           population = problem.InitialPopulation(problem.Options());
  const std::vector<DualMesh> parents(population.begin(), population.begin() + 8);
  const auto &                group = problem.parallel.groups[0];
  // Steps of about a cell's half width: many candidates fold.
  morea_test::RandomCandidates sampled(problem, parents, group, 4.0, 21);
  morea_test::RandomCandidates repaired(problem, parents, group, 4.0, 21);
  morea_test::RandomCandidates again(problem, parents, group, 4.0, 21);
  for (auto & c : repaired.candidates)
    c.evaluateFolded = false;

  FoldHandling handling;
  handling.constraint = problem.constraint.get();
  handling.base = &problem.base;
  handling.repair = true;
  auto backend = CreateCpuEvaluationBackend(*problem.evaluator, 1);
  backend->SetFoldHandling(handling);
  backend->EvaluatePartials(repaired.candidates);
  EXPECT_GT(backend->Statistics().foldSeconds, 0.0);

  std::size_t foldedSides = 0, repairedSides = 0, stillFolded = 0;
  for (std::size_t i = 0; i < sampled.candidates.size(); ++i)
  {
    const auto & dependent = sampled.candidates[i].element->dependentTetrahedra;
    std::uint8_t folded = 0;
    for (int side = 0; side < 2; ++side)
    {
      const bool before = !problem.constraint->Partial(sampled.Side(i, side), dependent).Feasible();
      const bool after = !problem.constraint->Partial(repaired.Side(i, side), dependent).Feasible();
      folded += before;
      if (!before)
        EXPECT_EQ(sampled.Side(i, side), repaired.Side(i, side)) << "an unfolded side is left alone, candidate " << i;
      else if (!after)
        ++repairedSides;
    }
    EXPECT_EQ(repaired.folds[i].foldedSides, folded) << "candidate " << i;
    foldedSides += folded;
    stillFolded += repaired.folds[i].Folded();
  }
  EXPECT_GT(foldedSides, 10u);
  EXPECT_GT(repairedSides, foldedSides / 2) << "most folds are repaired";
  std::size_t reported = 0;
  for (const auto & f : repaired.folds)
    reported += f.repairedSides;
  EXPECT_EQ(reported, repairedSides);

  // Without fold handling, the repaired candidates evaluate to the same values;
  // the still folded ones (evaluateFolded false) were skipped.
  std::vector<std::vector<TetrahedronValues>> plain(repaired.values.size());
  std::vector<PartialCandidate>               batch = repaired.candidates;
  for (std::size_t i = 0; i < batch.size(); ++i)
  {
    plain[i].resize(repaired.values[i].size());
    batch[i].values = plain[i].data();
    batch[i].folds = nullptr;
  }
  CreateCpuEvaluationBackend(*problem.evaluator, 2)->EvaluatePartials(batch);
  for (std::size_t i = 0; i < batch.size(); ++i)
  {
    if (repaired.folds[i].Folded())
      continue;
    for (std::size_t k = 0; k < plain[i].size(); ++k)
    {
      EXPECT_EQ(plain[i][k].intensity, repaired.values[i][k].intensity);
      EXPECT_EQ(plain[i][k].folded, 0.0);
    }
  }

  // The repair is a function of the candidate's seed: other threads, same points.
  auto other = CreateCpuEvaluationBackend(*problem.evaluator, 3);
  other->SetFoldHandling(handling);
  other->EvaluatePartials(again.candidates);
  for (std::size_t i = 0; i < again.candidates.size(); ++i)
  {
    EXPECT_EQ(again.source[i], repaired.source[i]);
    EXPECT_EQ(again.target[i], repaired.target[i]);
  }
  EXPECT_LT(stillFolded, foldedSides);
}
