// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The refusal bound's rule (RefusalBound.h): which candidates it shows
// refused before their samples are drawn, and steering.
#include "OptimiserTestProblem.h"

#include "morea_core/Error.h"
#include "morea_core/RefusalBound.h"

#include <gtest/gtest.h>

#include <atomic>
#include <limits>

using namespace morea_core;
using morea_test::OptimiserTestProblem;

namespace
{
/** A bound whose rest has 1000 samples and the given sums; parent feasible. */
RefusalBound
Bound(double magnitude, double intensity, double guidance, const ObjectiveVector & parent)
{
  RefusalBound b;
  b.screened = true;
  b.rest.magnitude = magnitude;
  b.rest.intensity = intensity;
  b.rest.guidance = guidance;
  b.rest.samples = 1000.0;
  b.parent.objectives = parent;
  b.parent.feasible = true;
  return b;
}

RefusalScreen
Screen(std::vector<ObjectiveVector> archive, double limit = std::numeric_limits<double>::infinity())
{
  RefusalScreen s;
  s.archive = std::move(archive);
  s.tetrahedra = 10;
  s.guidanceLimit = limit;
  return s;
}
} // namespace

TEST(RefusalBound, SteeringMakesTooMuchGuidanceInfeasibleAndFoldsWorse)
{
  Fitness f;
  f.objectives = { { 1.0, 0.5, 0.3 } };
  EXPECT_TRUE(SteeredFitness(f, 0.4).feasible);
  const Fitness steered = SteeredFitness(f, 0.2);
  EXPECT_FALSE(steered.feasible);
  EXPECT_NEAR(steered.constraint, 0.1, 1e-15);
  Fitness folded = f;
  folded.feasible = false;
  folded.constraint = 2.0;
  EXPECT_EQ(SteeredFitness(folded, 0.2).constraint, FoldConstraintOffset + 2.0);
  EXPECT_TRUE(ConstraintDominates(steered, SteeredFitness(folded, 0.2)));
}

TEST(RefusalBound, RefusedOnlyWhenAnEntryEqualsOrDominatesTheBoundAndItCannotReplaceTheParent)
{
  // Corners: magnitude 100 over 10 tetrahedra -> objective 0 is (m + 100) / 100.
  TetrahedronValues corners;
  corners.magnitude = 100.0;
  corners.samples = 1000.0; // 2000 samples in all
  // Bound: magnitude (100 + 100) / 100 = 2, intensity 400 / 2000 = 0.2, guidance 200 / 2000 = 0.1.
  const RefusalBound bound = Bound(100.0, 400.0, 200.0, { { 3.0, 0.3, 0.2 } });
  const Fitness      low = BoundFitness(bound, corners, Screen({}));
  EXPECT_DOUBLE_EQ(low.objectives[0], 2.0);
  EXPECT_DOUBLE_EQ(low.objectives[1], 0.2);
  EXPECT_DOUBLE_EQ(low.objectives[2], 0.1);
  // The bound dominates the parent: its samples may make it better still.
  EXPECT_FALSE(RefusedWhateverItsSamples(bound, corners, Screen({ { 1.0, 0.1, 0.05 } })));

  const RefusalBound worseThanParent = Bound(100.0, 400.0, 200.0, { { 1.5, 0.3, 0.2 } });
  EXPECT_TRUE(RefusedWhateverItsSamples(worseThanParent, corners, Screen({ { 1.9, 0.2, 0.1 } })));
  EXPECT_TRUE(RefusedWhateverItsSamples(worseThanParent, corners, Screen({ { 2.0, 0.2, 0.1 } }))); // equal
  // An entry better in two objectives but worse in one refuses nothing.
  EXPECT_FALSE(RefusedWhateverItsSamples(worseThanParent, corners, Screen({ { 1.9, 0.19, 0.11 } })));
  EXPECT_FALSE(RefusedWhateverItsSamples(worseThanParent, corners, Screen({})));
  // Not screened: never refused.
  RefusalBound unscreened = worseThanParent;
  unscreened.screened = false;
  EXPECT_FALSE(RefusedWhateverItsSamples(unscreened, corners, Screen({ { 1.0, 0.1, 0.05 } })));
  // Folded corners: infeasible, so refused against a feasible parent
  // whatever the archive.
  TetrahedronValues folded = corners;
  folded.folded = 1.0;
  folded.foldValue = 0.5;
  EXPECT_TRUE(RefusedWhateverItsSamples(worseThanParent, folded, Screen({})));
  // Guidance beyond the steering limit: infeasible too.
  EXPECT_TRUE(RefusedWhateverItsSamples(worseThanParent, corners, Screen({}, 0.05)));
  // An infeasible parent with a larger constraint could be replaced.
  RefusalBound steeredParent = worseThanParent;
  steeredParent.parent.feasible = false;
  steeredParent.parent.constraint = FoldConstraintOffset + 1.0;
  EXPECT_FALSE(RefusedWhateverItsSamples(steeredParent, folded, Screen({})));
}

TEST(RefusalBound, ChoiceNamesAndWhichBackendsUseItByDefault)
{
  EXPECT_EQ(ParseRefusalBoundChoice("auto"), RefusalBoundChoice::Auto);
  EXPECT_EQ(ParseRefusalBoundChoice("on"), RefusalBoundChoice::On);
  EXPECT_EQ(ParseRefusalBoundChoice("off"), RefusalBoundChoice::Off);
  EXPECT_THROW(ParseRefusalBoundChoice("yes"), Error);
  OptimiserTestProblem problem;
  auto                 cpu = CreateCpuEvaluationBackend(*problem.evaluator, 1);
  EXPECT_TRUE(UsesRefusalBounds(RefusalBoundChoice::Auto, *cpu));
  EXPECT_FALSE(UsesRefusalBounds(RefusalBoundChoice::Off, *cpu));
}

TEST(RefusalBound, CpuBackendSkipsRefusedCandidatesAndSamplesThemLaterAlike)
{
  // Candidates with bounds that every one is refused (an archive entry at 0)
  // come back with their corners' values only; sampled later, their values
  // equal a plain evaluation's bit for bit.
  OptimiserTestProblem problem;
  GomeaOptions         options = problem.Options(5);
  options.populationSize = 3;
  const auto   population = problem.InitialPopulation(options);
  const auto & group = problem.parallel.groups.front();
  // The same points twice (one seed): evaluated plainly and with bounds.
  morea_test::RandomCandidates plain(problem, population, group, 0.1, 7);
  morea_test::RandomCandidates bounded(problem, population, group, 0.1, 7);
  const std::vector<PartialCandidate> & candidates = plain.candidates;
  auto                                  backend = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  backend->EvaluatePartials(plain.candidates);

  std::vector<RefusalBound> bounds(candidates.size());
  RefusalScreen             screen = Screen({ { 0.0, 0.0, 0.0 } });
  screen.witnesses = { 77 };
  std::atomic<std::size_t>  filled{ 0 };
  screen.fill = [&](std::size_t i) {
    bounds[i].screened = i % 4 != 3; // every fourth one is not screened
    bounds[i].parent.objectives = { { 0.0, 0.0, 0.0 } };
    bounds[i].parent.feasible = true;
    bounds[i].rest.samples = 1.0;
    ++filled;
  };
  backend->SetRefusalScreen(screen);
  std::vector<PartialCandidate> & batch = bounded.candidates;
  for (std::size_t i = 0; i < batch.size(); ++i)
    batch[i].bound = &bounds[i];
  backend->EvaluatePartials(batch);
  backend->ClearRefusalScreen();
  EXPECT_EQ(filled.load(), candidates.size());
  std::vector<std::size_t> skipped;
  for (std::size_t i = 0; i < candidates.size(); ++i)
  {
    EXPECT_EQ(bounds[i].skipped, i % 4 != 3) << i;
    const auto & p = plain.values[i];
    const auto & v = bounded.values[i];
    for (std::size_t k = 0; k < p.size(); ++k)
    {
      EXPECT_EQ(v[k].magnitude, p[k].magnitude);
      EXPECT_EQ(v[k].samples, p[k].samples);
      EXPECT_EQ(v[k].folded, p[k].folded);
      if (bounds[i].skipped)
        EXPECT_EQ(v[k].intensity, 0.0);
      else
        EXPECT_EQ(v[k].intensity, p[k].intensity);
    }
    if (bounds[i].skipped)
    {
      skipped.push_back(i);
      EXPECT_EQ(bounds[i].witness, 77u) << "the entry that refused it";
    }
  }
  ASSERT_FALSE(skipped.empty());
  EXPECT_GT(backend->Statistics().boundSkippedSamples, 0.0);
  const double spared = backend->Statistics().boundSkippedSamples;
  EXPECT_EQ(backend->Statistics().boundSampledLaterSamples, 0.0);
  backend->SampleSkipped(batch, skipped);
  EXPECT_EQ(backend->Statistics().boundSampledLater, skipped.size());
  EXPECT_EQ(backend->Statistics().boundSkippedSamples, 0.0);
  EXPECT_EQ(backend->Statistics().boundSampledLaterSamples, spared) << "the samples the bound had spared";
  for (std::size_t i : skipped)
  {
    EXPECT_FALSE(bounds[i].skipped);
    for (std::size_t k = 0; k < plain.values[i].size(); ++k)
    {
      EXPECT_EQ(bounded.values[i][k].intensity, plain.values[i][k].intensity);
      EXPECT_EQ(bounded.values[i][k].guidance, plain.values[i][k].guidance);
    }
  }
  // Only skipped candidates can be sampled later.
  EXPECT_THROW(backend->SampleSkipped(batch, { skipped.front() }), Error);
}
