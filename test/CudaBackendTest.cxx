// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The CUDA evaluation backend against the CPU reference (SPEC 6): the same
// solutions and the same partial candidates give the same per-tetrahedron
// values (sample counts and folds exactly, objectives to relative 1e-4), and
// a short seeded run gives a front of the same quality. The GPU tests skip
// themselves when no CUDA device is present; the selection tests run anywhere.
#include "OptimiserTestProblem.h"

#include "morea_core/ComputeDevices.h"
#include "morea_core/Error.h"
#include "morea_core/Random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <numeric>
#include <string>
#include <thread>
#include <vector>

using namespace morea_core;
using morea_test::OptimiserTestProblem;

namespace
{
#define MOREA_REQUIRE_CUDA_DEVICE()                                                                                    \
  if (!CudaUnavailableReason().empty())                                                                                \
  GTEST_SKIP() << CudaUnavailableReason()

/** |cpu - cuda| <= tolerance * max(|cpu|, floor): the floor keeps near-zero
 *  sums (two almost equal intensities squared) from magnifying float rounding. */
void
ExpectRelativelyClose(double cpu, double cuda, double tolerance, const std::string & what, double floor = 1e-12)
{
  EXPECT_LE(std::abs(cpu - cuda), tolerance * std::max(std::abs(cpu), floor)) << what << ": cpu " << cpu << " cuda "
                                                                               << cuda;
}

void
ExpectSameTotals(const std::vector<TetrahedronValues> & cpu, const std::vector<TetrahedronValues> & cuda,
                 const std::string & what, double floor = 1e-12)
{
  ASSERT_EQ(cpu.size(), cuda.size());
  ObjectiveTotals a, b;
  for (std::size_t t = 0; t < cpu.size(); ++t)
  {
    // Sample counts and fold decisions are exact: they depend only on volumes
    // computed with the same rounding.
    EXPECT_EQ(cpu[t].samples, cuda[t].samples) << what << " tetrahedron " << t;
    EXPECT_EQ(cpu[t].folded, cuda[t].folded) << what << " tetrahedron " << t;
    ExpectRelativelyClose(cpu[t].magnitude, cuda[t].magnitude, 1e-9, what + " magnitude");
    ExpectRelativelyClose(cpu[t].foldValue, cuda[t].foldValue, 1e-9, what + " fold value");
    a.Add(cpu[t]);
    b.Add(cuda[t]);
  }
  const Fitness fa = a.ToFitness(cpu.size()), fb = b.ToFitness(cuda.size());
  for (std::size_t m = 0; m < NumberOfObjectives; ++m)
    ExpectRelativelyClose(fa.objectives[m], fb.objectives[m], 1e-4, what + " objective " + std::to_string(m), floor);
  EXPECT_EQ(fa.feasible, fb.feasible);
}

/** Per-tetrahedron values of every solution of `population` from `backend`. */
std::vector<std::vector<TetrahedronValues>>
EvaluateAll(EvaluationBackend & backend, const std::vector<DualMesh> & population)
{
  std::vector<const DualMesh *>                 solutions;
  std::vector<std::vector<TetrahedronValues>>   values(population.size());
  std::vector<std::vector<TetrahedronValues> *> outputs;
  for (std::size_t i = 0; i < population.size(); ++i)
  {
    solutions.push_back(&population[i]);
    outputs.push_back(&values[i]);
  }
  backend.EvaluateSolutions(solutions, outputs);
  return values;
}
/** A seeded run to its end: the archive's entries and the history. */
std::pair<std::vector<ArchiveEntry>, std::vector<GenerationRecord>>
RunToEnd(const OptimiserTestProblem & problem, EvaluationBackend & backend, const GomeaOptions & options)
{
  MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, backend, options);
  optimiser.Initialize(problem.InitialPopulation(options));
  optimiser.Run();
  return std::make_pair(optimiser.Archive().Entries(), optimiser.History());
}

/** Two runs that must have made the same decisions: the same archive (ids
 *  and objectives) and as many acceptances in every generation. */
void
ExpectSameDecisions(const std::pair<std::vector<ArchiveEntry>, std::vector<GenerationRecord>> & a,
                    const std::pair<std::vector<ArchiveEntry>, std::vector<GenerationRecord>> & b,
                    const std::string &                                                       name)
{
  ASSERT_EQ(a.first.size(), b.first.size()) << name;
  for (std::size_t i = 0; i < a.first.size(); ++i)
  {
    EXPECT_EQ(a.first[i].id, b.first[i].id) << name;
    EXPECT_EQ(a.first[i].fitness.objectives, b.first[i].fitness.objectives) << name;
  }
  ASSERT_EQ(a.second.size(), b.second.size()) << name;
  for (std::size_t g = 0; g < a.second.size(); ++g)
    EXPECT_EQ(a.second[g].accepted, b.second[g].accepted) << name << " generation " << g;
}
/** Parents enough for batches of several parts (the backend splits batches
 *  of hundreds of thousands of tetrahedra), each with the elements of one of
 *  `groups` (counted by the group with the fewest tetrahedra), parent after
 *  parent (as the optimiser orders them). */
std::vector<DualMesh>
ParentsForBatchesInParts(const OptimiserTestProblem & problem, const std::vector<std::size_t> & groups)
{
  const auto  population = problem.InitialPopulation(problem.Options());
  std::size_t itemsPerParent = std::numeric_limits<std::size_t>::max();
  for (std::size_t g : groups)
  {
    std::size_t items = 0;
    for (std::uint32_t e : problem.parallel.groups[g])
      items += problem.parallel.elements[e].dependentTetrahedra.size();
    itemsPerParent = std::min(itemsPerParent, items);
  }
  if (groups.empty() || itemsPerParent == 0)
    throw Error("test problem: the groups need dependent tetrahedra");
  std::vector<DualMesh> parents;
  for (std::size_t i = 0; parents.size() * itemsPerParent < 450000; ++i)
    parents.push_back(population[i % population.size()]);
  return parents;
}

/** Fold checks with the repair, on the problem's base mesh. */
FoldHandling
RepairingFoldHandling(const OptimiserTestProblem & problem)
{
  FoldHandling handling;
  handling.constraint = problem.constraint.get();
  handling.base = &problem.base;
  handling.repair = true;
  return handling;
}

/** The first candidates of `next` whose parents (of one array, in order)
 *  come before that of candidate `end` of `first`: those that the hand-over
 *  of `first` up to `end` has finished with. */
std::size_t
HeadFinishedWith(const std::vector<PartialCandidate> & first, std::size_t end,
                 const std::vector<PartialCandidate> & next)
{
  std::size_t head = 0;
  while (head < next.size() && next[head].parent < first[end].parent)
    ++head;
  return head;
}
} // namespace

TEST(CudaEvaluationBackend, WholeSolutionsAgreeWithTheCpu)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  for (double rate : { 0.25, 2.0 })
  {
    OptimiserTestProblem problem;
    problem.data.samplingRate = rate;
    GomeaOptions options = problem.Options(3);
    options.populationSize = 6;
    auto population = problem.InitialPopulation(options);
    // A folded solution too: a point pushed through its neighbours.
    DualMesh folded = population.back();
    folded.target[40][0] += 9.0;
    population.push_back(folded);
    auto cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
    auto cuda = CreateCudaEvaluationBackend(*problem.evaluator, 2);
    EXPECT_EQ(cuda->Name(), "cuda-exact");
    const auto a = EvaluateAll(*cpu, population);
    const auto b = EvaluateAll(*cuda, population);
    for (std::size_t i = 0; i < population.size(); ++i)
      ExpectSameTotals(a[i], b[i], "rate " + std::to_string(rate) + " solution " + std::to_string(i));
    double folds = 0.0;
    for (const auto & v : b.back())
      folds += v.folded;
    EXPECT_GT(folds, 0.0) << "the pushed point should fold the last solution";
  }
}

TEST(CudaEvaluationBackend, PartialCandidatesAgreeWithTheCpu)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  GomeaOptions         options = problem.Options(4);
  options.populationSize = 4;
  const auto population = problem.InitialPopulation(options);
  // One parallel group's elements for every solution, the points moved at random.
  const auto &                   group = problem.parallel.groups.front();
  RandomGenerator                random(11);
  std::vector<std::vector<Vec3>> moved;
  std::vector<PartialCandidate>  candidates;
  moved.reserve(2 * group.size() * population.size());
  for (const DualMesh & parent : population)
    for (std::uint32_t e : group)
    {
      const FosElement & element = problem.parallel.elements[e];
      std::vector<Vec3>  source, target;
      for (std::uint32_t p : element.points)
      {
        Vec3 s = parent.source[p], t = parent.target[p];
        for (int a = 0; a < 3; ++a)
        {
          s[a] += random.Normal() * 1.5;
          t[a] += random.Normal() * 1.5;
        }
        source.push_back(s);
        target.push_back(t);
      }
      moved.push_back(std::move(source));
      moved.push_back(std::move(target));
      PartialCandidate c;
      c.parent = &parent;
      c.element = &element;
      c.source = moved[moved.size() - 2].data();
      c.target = moved.back().data();
      candidates.push_back(c);
    }
  std::vector<std::vector<TetrahedronValues>> a(candidates.size()), b(candidates.size());
  auto                                        withValues = [&](std::vector<std::vector<TetrahedronValues>> & out) {
    std::vector<PartialCandidate> batch = candidates;
    for (std::size_t i = 0; i < batch.size(); ++i)
    {
      out[i].resize(batch[i].element->dependentTetrahedra.size());
      batch[i].values = out[i].data();
    }
    return batch;
  };
  CreateCpuEvaluationBackend(*problem.evaluator, 2)->EvaluatePartials(withValues(a));
  auto cuda = CreateCudaEvaluationBackend(*problem.evaluator, 2);
  cuda->EvaluatePartials(withValues(b));
  for (std::size_t i = 0; i < candidates.size(); ++i)
    ExpectSameTotals(a[i], b[i], "candidate " + std::to_string(i), 1e-6); // a few tetrahedra: sums can be ~0

  // A second batch on the same backend, in reverse order and without the
  // first solution's candidates: the device builds the corners from another
  // parent and element layout and must give the same values.
  std::vector<PartialCandidate>               reversed(candidates.rbegin(), candidates.rend() - group.size());
  std::vector<std::vector<TetrahedronValues>> r(reversed.size());
  for (std::size_t i = 0; i < reversed.size(); ++i)
  {
    r[i].resize(reversed[i].element->dependentTetrahedra.size());
    reversed[i].values = r[i].data();
  }
  cuda->EvaluatePartials(reversed);
  for (std::size_t i = 0; i < reversed.size(); ++i)
  {
    const std::size_t original = candidates.size() - 1 - i;
    ASSERT_EQ(r[i].size(), b[original].size());
    for (std::size_t t = 0; t < r[i].size(); ++t)
    {
      EXPECT_EQ(r[i][t].intensity, b[original][t].intensity) << "candidate " << original;
      EXPECT_EQ(r[i][t].magnitude, b[original][t].magnitude) << "candidate " << original;
    }
  }

  // The texture path: same samples and per-tetrahedron constraint values;
  // objectives close over the whole batch (hardware interpolation weights
  // and single precision make a few tetrahedra's near-zero sums noisy).
  std::vector<std::vector<TetrahedronValues>> c(candidates.size());
  CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture)->EvaluatePartials(withValues(c));
  ObjectiveTotals ta, tc;
  std::size_t     count = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i)
    for (std::size_t t = 0; t < a[i].size(); ++t, ++count)
    {
      EXPECT_EQ(a[i][t].samples, c[i][t].samples);
      EXPECT_EQ(a[i][t].folded, c[i][t].folded);
      ExpectRelativelyClose(a[i][t].magnitude, c[i][t].magnitude, 1e-9, "texture magnitude");
      ta.Add(a[i][t]);
      tc.Add(c[i][t]);
    }
  const Fitness fa = ta.ToFitness(count), fc = tc.ToFitness(count);
  for (std::size_t m = 0; m < NumberOfObjectives; ++m)
    ExpectRelativelyClose(fa.objectives[m], fc.objectives[m], 1e-2, "texture objective " + std::to_string(m));

  // A batch large enough to run in parts (the same candidates many times):
  // every part is handed over once, in order, and each copy gets exactly the
  // values of the small batch, whichever part it was sampled in.
  std::size_t smallItems = 0;
  for (const auto & v : c)
    smallItems += v.size();
  const std::size_t                           copies = 1000000 / std::max<std::size_t>(1, smallItems) + 1;
  std::vector<PartialCandidate>               large;
  std::vector<std::vector<TetrahedronValues>> l(copies * candidates.size());
  for (std::size_t k = 0; k < copies; ++k)
    for (std::size_t i = 0; i < candidates.size(); ++i)
    {
      large.push_back(candidates[i]);
      l[large.size() - 1].resize(candidates[i].element->dependentTetrahedra.size());
      large.back().values = l[large.size() - 1].data();
    }
  std::vector<std::pair<std::size_t, std::size_t>> handed;
  CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture)
    ->EvaluatePartials(large, [&](std::size_t begin, std::size_t end) {
      // Every earlier candidate already has its values when a part is handed over.
      if (begin > 0 && !l[begin - 1].empty())
        EXPECT_EQ(l[begin - 1][0].samples, c[(begin - 1) % candidates.size()][0].samples);
      handed.emplace_back(begin, end);
    });
  ASSERT_GT(handed.size(), 1u) << "the batch was not split";
  std::size_t next = 0;
  for (const auto & [begin, end] : handed)
  {
    EXPECT_EQ(begin, next);
    EXPECT_LT(begin, end);
    next = end;
  }
  EXPECT_EQ(next, large.size());
  for (std::size_t j = 0; j < large.size(); ++j)
    for (std::size_t t = 0; t < l[j].size(); ++t)
    {
      const TetrahedronValues & expected = c[j % candidates.size()][t];
      ASSERT_EQ(l[j][t].intensity, expected.intensity) << "copy " << j / candidates.size() << ", candidate " << j % candidates.size();
      ASSERT_EQ(l[j][t].guidance, expected.guidance);
      ASSERT_EQ(l[j][t].samples, expected.samples);
      ASSERT_EQ(l[j][t].magnitude, expected.magnitude);
    }

  // The lean call the optimiser makes: every candidate's sum comes with its
  // part, bit for bit the sum of its values added in order; its values only
  // where FetchValues asks (here every third candidate's), the others'
  // untouched.
  const TetrahedronValues       untouched{ -1.0, -2.0, -3.0, -4.0, -5.0, -6.0 };
  std::vector<TetrahedronValues> sums(large.size(), untouched);
  for (std::size_t j = 0; j < large.size(); ++j)
  {
    std::fill(l[j].begin(), l[j].end(), untouched);
    large[j].sum = &sums[j];
  }
  auto        lean = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
  std::size_t fetched = 0;
  lean->EvaluatePartials(
    large,
    [&](std::size_t begin, std::size_t end) {
      std::vector<std::size_t> which;
      for (std::size_t j = begin; j < end; ++j)
        if (j % 3 == 0)
          which.push_back(j);
      lean->FetchValues(large, which);
      fetched += which.size();
    },
    EvaluationBackend::Meanwhile{});
  ASSERT_GT(fetched, 0u);
  for (std::size_t j = 0; j < large.size(); ++j)
  {
    const std::vector<TetrahedronValues> & expected = c[j % candidates.size()];
    ObjectiveTotals                        total;
    for (const TetrahedronValues & v : expected)
      total.Add(v);
    const std::string what = "candidate " + std::to_string(j);
    ASSERT_EQ(sums[j].intensity, total.sum.intensity) << what;
    ASSERT_EQ(sums[j].guidance, total.sum.guidance) << what;
    ASSERT_EQ(sums[j].samples, total.sum.samples) << what;
    ASSERT_EQ(sums[j].magnitude, total.sum.magnitude) << what;
    ASSERT_EQ(sums[j].foldValue, total.sum.foldValue) << what;
    ASSERT_EQ(sums[j].folded, total.sum.folded) << what;
    for (std::size_t t = 0; t < l[j].size(); ++t)
    {
      const TetrahedronValues & want = j % 3 == 0 ? expected[t] : untouched;
      ASSERT_EQ(l[j][t].intensity, want.intensity) << what << ", tetrahedron " << t;
      ASSERT_EQ(l[j][t].samples, want.samples) << what << ", tetrahedron " << t;
    }
  }
}

TEST(CudaEvaluationBackend, VolumeBoundFoldsAgreeWithTheCpu)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  const FoldConstraint tight(problem.topology, problem.base.points, 0.9);
  const TetrahedronEvaluator evaluator(problem.topology, tight, problem.elasticity, problem.data);
  GomeaOptions               options = problem.Options(8);
  options.populationSize = 5;
  const auto population = problem.InitialPopulation(options);
  const auto a = EvaluateAll(*CreateCpuEvaluationBackend(evaluator, 2), population);
  const auto b = EvaluateAll(*CreateCudaEvaluationBackend(evaluator, 2), population);
  double folds = 0.0;
  for (std::size_t i = 0; i < population.size(); ++i)
  {
    ExpectSameTotals(a[i], b[i], "solution " + std::to_string(i));
    for (const auto & v : a[i])
      folds += v.folded;
  }
  EXPECT_GT(folds, 0.0) << "a fraction of 0.9 should flag some of the random deformations";
}

TEST(CudaEvaluationBackend, SeededRunsReachFrontsOfTheSameQuality)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  // Runs on the two backends start alike and drift apart (objective values
  // differ in the last digits, so acceptance differs now and then): compare
  // the mean over a few seeds, not one run.
  auto run = [&](EvaluationBackend & backend, std::uint64_t seed) {
    GomeaOptions options = problem.Options(seed, 16);
    options.steeringEnabled = false; // hypervolume against the initial reference stays informative
    MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, backend, options);
    optimiser.Initialize(problem.InitialPopulation(options));
    optimiser.Run();
    // The stored objectives of the CUDA run are those the CPU computes.
    auto cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
    for (const auto & entry : optimiser.Archive().Entries())
    {
      std::vector<TetrahedronValues> values;
      cpu->EvaluateSolutions({ &entry.solution }, { &values });
      ObjectiveTotals totals;
      for (const auto & v : values)
        totals.Add(v);
      const Fitness f = totals.ToFitness(values.size());
      for (std::size_t m = 0; m < NumberOfObjectives; ++m)
        ExpectRelativelyClose(f.objectives[m], entry.fitness.objectives[m], 1e-4, backend.Name() + " archive");
    }
    return optimiser.History().back();
  };
  // Seed-to-seed spread of the final hypervolume here is about 10 % of its
  // mean (measured on the CPU, seeds 13-28: mean 0.514, sd 0.053), so a
  // difference of means is judged against its standard error, with 5 % as
  // the floor of the tolerance.
  auto                cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  auto                cuda = CreateCudaEvaluationBackend(*problem.evaluator, 2);
  std::vector<double> cpuHypervolumes, cudaHypervolumes;
  double              cpuGuidance = 0.0, cudaGuidance = 0.0;
  for (std::uint64_t seed = 13; seed < 25; ++seed)
  {
    const GenerationRecord a = run(*cpu, seed);
    const GenerationRecord b = run(*cuda, seed);
    ASSERT_GT(a.hypervolume, 0.0);
    std::cout << "seed " << seed << ": hypervolume cpu " << a.hypervolume << " cuda " << b.hypervolume
              << ", best guidance cpu " << a.bestGuidance << " cuda " << b.bestGuidance << "\n";
    cpuHypervolumes.push_back(a.hypervolume);
    cudaHypervolumes.push_back(b.hypervolume);
    cpuGuidance += a.bestGuidance;
    cudaGuidance += b.bestGuidance;
  }
  auto mean = [](const std::vector<double> & v) { return std::accumulate(v.begin(), v.end(), 0.0) / v.size(); };
  auto variance = [&](const std::vector<double> & v) {
    const double m = mean(v);
    double       s = 0.0;
    for (const double x : v)
      s += (x - m) * (x - m);
    return s / (v.size() - 1);
  };
  const double n = static_cast<double>(cpuHypervolumes.size());
  const double standardError = std::sqrt((variance(cpuHypervolumes) + variance(cudaHypervolumes)) / n);
  const double tolerance = std::max(0.05 * mean(cpuHypervolumes), 3.0 * standardError);
  std::cout << "mean hypervolume cpu " << mean(cpuHypervolumes) << " cuda " << mean(cudaHypervolumes)
            << ", standard error of the difference " << standardError << "\n";
  EXPECT_NEAR(mean(cudaHypervolumes), mean(cpuHypervolumes), tolerance);
  EXPECT_NEAR(cudaGuidance, cpuGuidance, 0.25 * cpuGuidance);
}

TEST(CudaEvaluationBackend, RefusalBoundsChangeNoDecision)
{
  // The device screens each batch against its archive snapshot; candidates
  // whose bound it refuses go unsampled, and those the optimiser's exact
  // check needs are sampled later on a stream of their own. With the same
  // seed a run must end exactly as one that samples every candidate.
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  const GomeaOptions   options = problem.Options(31, 12);
  GomeaOptions         sampleAll = options;
  sampleAll.boundRefusals = false;
  for (const CudaInterpolation interpolation : { CudaInterpolation::Exact, CudaInterpolation::Texture })
  {
    auto       backend = CreateCudaEvaluationBackend(*problem.evaluator, 2, interpolation);
    const auto run = [&](const GomeaOptions & o) { return RunToEnd(problem, *backend, o); };
    const auto all = run(sampleAll);
    const auto bounded = run(options);
    ASSERT_EQ(all.first.size(), bounded.first.size()) << backend->Name();
    for (std::size_t i = 0; i < all.first.size(); ++i)
    {
      EXPECT_EQ(all.first[i].id, bounded.first[i].id) << backend->Name();
      EXPECT_EQ(all.first[i].fitness.objectives, bounded.first[i].fitness.objectives) << backend->Name();
    }
    std::size_t skipped = 0, later = 0;
    double      spared = 0.0, drawn = 0.0, drawnAll = 0.0;
    for (std::size_t g = 0; g < all.second.size(); ++g)
    {
      EXPECT_EQ(all.second[g].accepted, bounded.second[g].accepted) << backend->Name() << " generation " << g;
      skipped += bounded.second[g].boundSkipped;
      later += bounded.second[g].boundSampledLater;
      spared += bounded.second[g].boundSkippedSamples;
      drawn += bounded.second[g].samples;
      drawnAll += all.second[g].samples;
    }
    std::cout << backend->Name() << ": bound skipped " << skipped << " candidates, " << later
              << " sampled later; " << spared << " of " << drawnAll << " samples spared\n";
    EXPECT_GT(skipped, 100u);
    EXPECT_GT(later, 0u);
    EXPECT_GT(spared, 0.05 * drawnAll);
    EXPECT_NEAR(drawn + spared, drawnAll, 1e-6 * drawnAll);
  }
}

// Rigid structures add their term to the magnitude on the device as on the
// CPU: whole solutions and partial candidates on both paths, and the
// refusal screen's bound (which sums the magnitude on the device) changes no
// decision of a run.
TEST(CudaEvaluationBackend, RigidStructuresAgreeWithTheCpu)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  GomeaOptions         options = problem.Options(9);
  options.populationSize = 4;
  const auto population = problem.InitialPopulation(options);
  double     plain = 0.0;
  for (const auto & v : EvaluateAll(*CreateCpuEvaluationBackend(*problem.evaluator, 2), population)[1])
    plain += v.magnitude;
  // With a strain limit that some candidates exceed: their fold values agree too.
  problem.UseRigidSlab(1000.0, 0.02);
  auto cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  const auto a = EvaluateAll(*cpu, population);
  double     rigid = 0.0;
  for (const auto & v : a[1])
    rigid += v.magnitude;
  EXPECT_GT(rigid, 1.5 * plain) << "the rigid slab's term should weigh in the test";
  std::size_t limited = 0; // candidates' tetrahedra beyond the strain limit
  for (const CudaInterpolation interpolation : { CudaInterpolation::Exact, CudaInterpolation::Texture })
  {
    auto        cuda = CreateCudaEvaluationBackend(*problem.evaluator, 2, interpolation);
    const auto  b = EvaluateAll(*cuda, population);
    for (std::size_t s = 0; s < population.size(); ++s)
      for (std::size_t t = 0; t < a[s].size(); ++t)
        ExpectRelativelyClose(a[s][t].magnitude, b[s][t].magnitude, 1e-9, cuda->Name() + " magnitude");
    for (std::size_t g = 0; g < 2; ++g)
    {
      morea_test::RandomCandidates onCpu(problem, population, problem.parallel.groups[g], 1.5, 41 + g);
      morea_test::RandomCandidates onGpu(problem, population, problem.parallel.groups[g], 1.5, 41 + g);
      cpu->EvaluatePartials(onCpu.candidates);
      cuda->EvaluatePartials(onGpu.candidates);
      for (std::size_t i = 0; i < onCpu.candidates.size(); ++i)
        for (std::size_t t = 0; t < onCpu.values[i].size(); ++t)
        {
          EXPECT_EQ(onCpu.values[i][t].folded, onGpu.values[i][t].folded) << cuda->Name();
          ExpectRelativelyClose(onCpu.values[i][t].magnitude, onGpu.values[i][t].magnitude, 1e-9,
                                cuda->Name() + " candidate magnitude");
          ExpectRelativelyClose(onCpu.values[i][t].foldValue, onGpu.values[i][t].foldValue, 1e-9,
                                cuda->Name() + " candidate fold value");
          limited += onCpu.values[i][t].foldValue > 0.0 ? 1 : 0;
        }
    }
  }
  EXPECT_GT(limited, 0u) << "some candidates should exceed the strain limit";
  const GomeaOptions run = problem.Options(31, 12);
  GomeaOptions       sampleAll = run;
  sampleAll.boundRefusals = false;
  auto       backend = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Exact);
  const auto all = RunToEnd(problem, *backend, sampleAll);
  const auto bounded = RunToEnd(problem, *backend, run);
  ExpectSameDecisions(all, bounded, "rigid slab, refusal bound");
}

TEST(CudaEvaluationBackend, TheFirstGroupSplitInTwoBatchesChangesNoDecision)
{
  // The generation's first group in two batches of half the population:
  // the same decisions as one batch.
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  GomeaOptions         whole = problem.Options(23, 7);
  whole.firstBatchSplit = 0;
  GomeaOptions split = whole;
  split.firstBatchSplit = 2;
  for (const CudaInterpolation interpolation : { CudaInterpolation::Exact, CudaInterpolation::Texture })
  {
    auto       backend = CreateCudaEvaluationBackend(*problem.evaluator, 2, interpolation);
    const auto run = [&](const GomeaOptions & o) { return RunToEnd(problem, *backend, o); };
    const auto started = backend->Statistics().startedCandidates;
    const auto a = run(whole);
    const auto middle = backend->Statistics().startedCandidates;
    const auto b = run(split);
    ExpectSameDecisions(a, b, backend->Name());
    // (These batches are too small for parts, so none is started early
    // here; at the paper's scale the second half is.)
    std::cout << backend->Name() << ": started early " << middle - started << " candidates whole, "
              << backend->Statistics().startedCandidates - middle << " split\n";
  }
}

TEST(CudaEvaluationBackend, DrawingBatchesAheadChangesNoDecision)
{
  // Batches drawn on threads of their own while the device evaluates the
  // one before: the same decisions as drawing each in the meanwhile.
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  GomeaOptions         here = problem.Options(29, 7);
  here.drawAheadThreads = 0;
  here.firstBatchSplit = 2;
  GomeaOptions ahead = here;
  ahead.drawAheadThreads = 3;
  for (const CudaInterpolation interpolation : { CudaInterpolation::Exact, CudaInterpolation::Texture })
  {
    auto       backend = CreateCudaEvaluationBackend(*problem.evaluator, 2, interpolation);
    const auto a = RunToEnd(problem, *backend, here);
    const auto b = RunToEnd(problem, *backend, ahead);
    ASSERT_FALSE(a.first.empty()) << backend->Name();
    ExpectSameDecisions(a, b, backend->Name());
    // Automatic: on beside a device, where the pool has 8 threads or more.
    GomeaOptions automatic = here;
    automatic.drawAheadThreads = GomeaOptions::DrawAheadAutomatic;
    automatic.threads = 8;
    MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, automatic);
    EXPECT_EQ(optimiser.DrawAheadThreads(), 6u) << backend->Name();
  }
}

TEST(CudaEvaluationBackend, TextureInterpolationStaysCloseToTheCpu)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  problem.data.samplingRate = 2.0;
  GomeaOptions options = problem.Options(9);
  options.populationSize = 4;
  const auto population = problem.InitialPopulation(options);
  auto       cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  auto       texture = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
  EXPECT_EQ(texture->Name(), "cuda-texture");
  for (const DualMesh & s : population)
  {
    std::vector<TetrahedronValues> a, b;
    cpu->EvaluateSolutions({ &s }, { &a });
    texture->EvaluateSolutions({ &s }, { &b });
    ObjectiveTotals ta, tb;
    for (std::size_t t = 0; t < a.size(); ++t)
    {
      EXPECT_EQ(a[t].samples, b[t].samples);
      ta.Add(a[t]);
      tb.Add(b[t]);
    }
    const Fitness fa = ta.ToFitness(a.size()), fb = tb.ToFitness(b.size());
    for (std::size_t m = 0; m < NumberOfObjectives; ++m)
    {
      const double relative = std::abs(fa.objectives[m] - fb.objectives[m]) / std::max(std::abs(fa.objectives[m]), 1e-12);
      std::cout << "texture interpolation, objective " << m << ": relative difference " << relative << "\n";
      EXPECT_LT(relative, 1e-2);
    }
  }
}

// The texture path interpolates along z itself (slice pairs: one bilinear
// fetch of two slices, then a lerp with a single-precision weight), so a
// fixed image that alternates between 0.2 and 0.8 from slice to slice, the
// steepest pattern along z, must sum like the CPU's exact trilinear values
// in every tetrahedron. The target mesh is moved 1.3 mm below and above the
// image, so that samples also fall where both paths clamp to the edge slice
// (in either direction: the sampled and the mapped points).
TEST(CudaEvaluationBackend, TextureInterpolatesAlongZLikeTheCpuUpToTheEdges)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  problem.data.samplingRate = 2.0;
  const std::array<std::size_t, 3> size = problem.data.fixed.size;
  for (std::size_t v = 0; v < size[0] * size[1] * size[2]; ++v)
  {
    const std::size_t slice = v / (size[0] * size[1]);
    problem.data.fixed.data[problem.data.fixed.channels * v] = slice % 2 == 0 ? 0.2f : 0.8f;
    problem.data.moving.data[problem.data.moving.channels * v] = 0.95f;
  }
  auto cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  auto texture = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
  for (const double shift : { -1.3, 1.3 })
  {
    DualMesh solution = DualMesh::FromBase(problem.base);
    for (Vec3 & p : solution.target)
      p[2] += shift;
    std::vector<TetrahedronValues> a, b;
    cpu->EvaluateSolutions({ &solution }, { &a });
    texture->EvaluateSolutions({ &solution }, { &b });
    ASSERT_EQ(a.size(), b.size());
    double worst = 0.0;
    for (std::size_t t = 0; t < a.size(); ++t)
    {
      ASSERT_EQ(a[t].samples, b[t].samples);
      ASSERT_GT(a[t].intensity, 0.0);
      const double relative = std::abs(a[t].intensity - b[t].intensity) / a[t].intensity;
      worst = std::max(worst, relative);
      EXPECT_LT(relative, 1e-4) << "target moved " << shift << " mm, tetrahedron " << t << ": cpu " << a[t].intensity
                                << " cuda " << b[t].intensity;
    }
    std::cout << "slices alternating, target moved " << shift << " mm: largest relative difference " << worst << "\n";
  }
}

// Slice pairs are 2D layered textures, whose layers a device limits (2048
// on an H100): a taller image is a clear error for the texture path, which
// names the way out, and no error for the exact path.
TEST(CudaEvaluationBackend, TexturePathRefusesImagesTallerThanItsLayers)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  for (ChannelVolume * image : { &problem.data.fixed, &problem.data.moving })
  {
    image->size = { 2, 2, 70000 };
    image->data.assign(2 * 2 * 2 * 70000, 0.5f);
  }
  try
  {
    CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
    ADD_FAILURE() << "no error for 70000 slices";
  }
  catch (const Error & e)
  {
    EXPECT_NE(std::string(e.what()).find("exceeds the texture path's limits"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--backend cuda"), std::string::npos) << e.what();
  }
  EXPECT_EQ(CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Exact)->Name(), "cuda-exact");
}

// The texture path sizes each part's sampling without waiting for its number
// of chunks; a part with more than the room guessed is sampled again when
// handed over, to the same values as with room enough.
TEST(CudaEvaluationBackend, PartsWithMoreChunksThanGuessedAreSampledAgain)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  GomeaOptions         options = problem.Options(9);
  options.populationSize = 2;
  const auto                     population = problem.InitialPopulation(options);
  auto                           cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  std::vector<TetrahedronValues> plain;
  cpu->EvaluateSolutions({ &population[0] }, { &plain });
  double samples = 0.0;
  for (const TetrahedronValues & v : plain)
    samples += v.samples;
  // About 16 chunks of 512 samples per tetrahedron, more than the first guess.
  problem.data.samplingRate *= 16.0 * 512.0 / (samples / static_cast<double>(plain.size()));
  auto texture = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
  std::vector<TetrahedronValues> first, second;
  texture->EvaluateSolutions({ &population[0] }, { &first });
  EXPECT_EQ(texture->Statistics().partsSampledAgain, 1u);
  texture->EvaluateSolutions({ &population[0] }, { &second });
  EXPECT_EQ(texture->Statistics().partsSampledAgain, 1u) << "room for all the second time";
  ASSERT_EQ(first.size(), second.size());
  double intensity = 0.0;
  for (std::size_t t = 0; t < first.size(); ++t)
  {
    ASSERT_EQ(first[t].intensity, second[t].intensity) << "tetrahedron " << t;
    ASSERT_EQ(first[t].guidance, second[t].guidance) << "tetrahedron " << t;
    ASSERT_EQ(first[t].samples, second[t].samples) << "tetrahedron " << t;
    intensity += first[t].intensity;
  }
  EXPECT_GT(intensity, 0.0);
}

// Tetrahedra of more than 512 samples are sampled in whole chunks whose
// lanes take the points in another order (cosets of an index subspace, one
// for each size of aligned block: morea/SampleCosets.h). On
// voxel noise, every tetrahedron's sum must match the CPU's points; as a
// check that the tolerance can fail, another point set (the same mesh moved
// by 1e-9 mm, so other seeds) must differ from the CPU's by more than it.
TEST(CudaEvaluationBackend, TextureWholeChunksSampleTheCpuPoints)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  RandomGenerator      noise(17);
  for (ChannelVolume * image : { &problem.data.fixed, &problem.data.moving })
    for (std::size_t v = 0; v < image->data.size(); v += 2)
      image->data[v] = static_cast<float>(0.2 + 0.8 * noise.Uniform());
  GomeaOptions options = problem.Options(9);
  options.populationSize = 2;
  const auto population = problem.InitialPopulation(options);
  DualMesh   moved = population[1];
  for (Vec3 & p : moved.source)
    p[0] += 1e-9;
  // 16 samples per voxel: many tetrahedra with whole chunks; 128: blocks of
  // 2^11 samples or more, each with its own cosets.
  for (const double rate : { 16.0, 128.0 })
  {
    problem.data.samplingRate = rate;
    auto cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
    auto texture = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
    std::vector<TetrahedronValues> a, b, c;
    cpu->EvaluateSolutions({ &population[1] }, { &a });
    texture->EvaluateSolutions({ &population[1] }, { &b });
    cpu->EvaluateSolutions({ &moved }, { &c });
    ASSERT_EQ(a.size(), b.size());
    std::size_t wholeChunks = 0, largerBlocks = 0, otherPointsDiffer = 0;
    double      worst = 0.0;
    for (std::size_t t = 0; t < a.size(); ++t)
    {
      EXPECT_EQ(a[t].samples, b[t].samples);
      if (a[t].samples < 1100.0) // both directions: at least one whole chunk
        continue;
      ++wholeChunks;
      if (a[t].samples >= 4096.0) // a direction with a block of 2^11 or more
        ++largerBlocks;
      const double relative = std::abs(a[t].intensity - b[t].intensity) / a[t].intensity;
      worst = std::max(worst, relative);
      EXPECT_LT(relative, 3e-3) << "rate " << rate << ", tetrahedron " << t << ": cpu " << a[t].intensity << " cuda "
                                << b[t].intensity;
      if (std::abs(a[t].intensity - c[t].intensity) / a[t].intensity > 3e-3)
        ++otherPointsDiffer;
    }
    std::cout << rate << " samples per voxel: " << wholeChunks << " tetrahedra with whole chunks (" << largerBlocks
              << " with blocks of 2^11 or more), largest relative difference " << worst << ", " << otherPointsDiffer
              << " differ with other points\n";
    if (rate == 16.0)
    {
      EXPECT_GE(wholeChunks, 50u);
      EXPECT_GE(otherPointsDiffer, wholeChunks * 3 / 4);
    }
    else
      EXPECT_GE(largerBlocks, 50u);
  }
}

TEST(EvaluationBackendSelection, NamesAndDeviceAbsence)
{
  EXPECT_EQ(ParseBackendChoice("cpu"), BackendChoice::Cpu);
  EXPECT_EQ(ParseBackendChoice("cuda"), BackendChoice::CudaTexture);
  EXPECT_EQ(ParseBackendChoice("cuda-texture"), BackendChoice::CudaTexture);
  EXPECT_EQ(ParseBackendChoice("cuda-exact"), BackendChoice::CudaExact);
  EXPECT_EQ(ParseBackendChoice("auto"), BackendChoice::Auto);
  for (auto choice : { BackendChoice::Cpu, BackendChoice::CudaTexture, BackendChoice::CudaExact, BackendChoice::Auto })
    EXPECT_EQ(ParseBackendChoice(BackendChoiceName(choice)), choice);
  EXPECT_THROW(ParseBackendChoice("gpu"), Error);
  OptimiserTestProblem problem;
  EXPECT_EQ(CreateEvaluationBackend(BackendChoice::Cpu, *problem.evaluator, 1)->Name(), "cpu");
  const std::string reason = CudaUnavailableReason();
  // Auto takes the fast path on a device and says why it ran where it did.
  BackendRequest request;
  request.threads = 1;
  std::string note;
  auto        automatic = CreateEvaluationBackend(request, *problem.evaluator, &note);
  EXPECT_EQ(automatic->Name(), reason.empty() ? "cuda-texture" : "cpu");
  EXPECT_NE(note.find(reason.empty() ? "texture path" : "the CPU"), std::string::npos) << note;
  // A device index out of range, named on purpose: an error for every CUDA-capable choice.
  request.device = 64;
  EXPECT_THROW(CreateEvaluationBackend(request, *problem.evaluator), Error);
  request.choice = BackendChoice::CudaTexture;
  EXPECT_THROW(CreateEvaluationBackend(request, *problem.evaluator), Error);
  request.choice = BackendChoice::Cpu;
  EXPECT_EQ(CreateEvaluationBackend(request, *problem.evaluator)->Name(), "cpu");
  request.choice = BackendChoice::CudaTexture;
  if (!reason.empty())
  {
    // No device (or no CUDA in the build): a clear error, not a crash.
    try
    {
      CreateEvaluationBackend(BackendChoice::CudaExact, *problem.evaluator, 1);
      ADD_FAILURE() << "expected an error";
    }
    catch (const Error & e)
    {
      EXPECT_NE(std::string(e.what()).find("backend 'cuda-exact'"), std::string::npos) << e.what();
    }
    EXPECT_THROW(CreateEvaluationBackend(BackendChoice::CudaTexture, *problem.evaluator, 1), Error);
  }
  else
  {
    EXPECT_EQ(CreateEvaluationBackend(BackendChoice::CudaTexture, *problem.evaluator, 1)->Name(), "cuda-texture");
    EXPECT_EQ(CreateEvaluationBackend(BackendChoice::CudaExact, *problem.evaluator, 1)->Name(), "cuda-exact");
    // A compute level above any device's: refused by name, the CPU for auto.
    request.device = 0;
    request.minimumComputeLevel = 200;
    EXPECT_THROW(CreateEvaluationBackend(request, *problem.evaluator), Error);
    request.choice = BackendChoice::Auto;
    EXPECT_EQ(CreateEvaluationBackend(request, *problem.evaluator, &note)->Name(), "cpu");
    EXPECT_NE(note.find("cuda_compute_level"), std::string::npos) << note;
  }
}

TEST(CudaEvaluationBackend, CandidatesLeftFoldedThatNeedNoValuesAreNotSampled)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  const auto           population = problem.InitialPopulation(problem.Options());
  const std::vector<DualMesh> parents(population.begin(), population.begin() + 8);
  const auto &                group = problem.parallel.groups[0];
  FoldHandling                handling;
  handling.constraint = problem.constraint.get();
  handling.base = &problem.base;
  handling.repair = true;
  for (auto interpolation : { CudaInterpolation::Exact, CudaInterpolation::Texture })
  {
    const std::string what = interpolation == CudaInterpolation::Exact ? "exact" : "texture";
    // Steps of about a cell's half width: some candidates stay folded.
    morea_test::RandomCandidates all(problem, parents, group, 4.0, 41);
    morea_test::RandomCandidates some(problem, parents, group, 4.0, 41);
    TetrahedronValues            untouched;
    untouched.samples = -1.0;
    for (std::size_t i = 0; i < some.candidates.size(); ++i)
    {
      some.candidates[i].evaluateFolded = false;
      std::fill(some.values[i].begin(), some.values[i].end(), untouched);
    }
    auto everything = CreateCudaEvaluationBackend(*problem.evaluator, 2, interpolation);
    auto skipping = CreateCudaEvaluationBackend(*problem.evaluator, 2, interpolation);
    everything->SetFoldHandling(handling);
    skipping->SetFoldHandling(handling);
    everything->EvaluatePartials(all.candidates);
    skipping->EvaluatePartials(some.candidates);

    std::size_t leftFolded = 0, evaluated = 0;
    double      samples = 0.0;
    for (std::size_t i = 0; i < all.candidates.size(); ++i)
    {
      ASSERT_EQ(all.folds[i].foldedSides, some.folds[i].foldedSides) << what << " candidate " << i;
      ASSERT_EQ(all.folds[i].repairedSides, some.folds[i].repairedSides) << what << " candidate " << i;
      if (all.folds[i].Folded())
      {
        ++leftFolded;
        for (const TetrahedronValues & v : some.values[i])
          EXPECT_EQ(v.samples, -1.0) << what << ": values of candidate " << i << " left alone, as on the CPU";
        continue;
      }
      evaluated += all.values[i].size();
      // Skipping others changes neither the samples nor the sums' order.
      for (std::size_t k = 0; k < all.values[i].size(); ++k)
      {
        samples += all.values[i][k].samples;
        EXPECT_EQ(all.values[i][k].samples, some.values[i][k].samples) << what << " candidate " << i;
        EXPECT_EQ(all.values[i][k].intensity, some.values[i][k].intensity) << what << " candidate " << i;
        EXPECT_EQ(all.values[i][k].guidance, some.values[i][k].guidance) << what << " candidate " << i;
        EXPECT_EQ(all.values[i][k].magnitude, some.values[i][k].magnitude) << what << " candidate " << i;
      }
    }
    EXPECT_GT(leftFolded, 0u) << what;
    EXPECT_LT(leftFolded, all.candidates.size()) << what;
    EXPECT_EQ(skipping->Statistics().samples, samples) << what;
    EXPECT_EQ(skipping->Statistics().tetrahedra, evaluated) << what;
    EXPECT_LT(skipping->Statistics().samples, everything->Statistics().samples) << what;
  }
}

TEST(CudaEvaluationBackend, ParentsWithKeysAreKeptOnTheDevice)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem  problem;
  const auto            population = problem.InitialPopulation(problem.Options());
  std::vector<DualMesh> parents(population.begin(), population.begin() + 4);
  morea_test::RandomCandidates batch(problem, parents, problem.parallel.groups[0], 1.0, 5);
  const auto withKeys = [&](const std::vector<std::uint64_t> & keys) {
    for (PartialCandidate & c : batch.candidates)
      c.parentKey = keys[static_cast<std::size_t>(c.parent - parents.data())];
    return batch.candidates;
  };
  const auto cpuValues = [&] {
    std::vector<std::vector<Vec3>>              source = batch.source, target = batch.target;
    std::vector<std::vector<TetrahedronValues>> values = batch.values;
    std::vector<PartialCandidate>               candidates = batch.candidates;
    for (std::size_t i = 0; i < candidates.size(); ++i)
    {
      candidates[i].source = source[i].data();
      candidates[i].target = target[i].data();
      candidates[i].values = values[i].data();
      candidates[i].folds = nullptr;
    }
    CreateCpuEvaluationBackend(*problem.evaluator, 2)->EvaluatePartials(candidates);
    return values;
  };
  auto cuda = CreateCudaEvaluationBackend(*problem.evaluator, 2);
  cuda->EvaluatePartials(withKeys({ 1, 2, 3, 4 }));
  EXPECT_EQ(cuda->Statistics().parentsUploaded, 4u);
  const auto first = batch.values;
  const auto cpuFirst = cpuValues();
  for (std::size_t i = 0; i < first.size(); ++i)
    ExpectSameTotals(cpuFirst[i], first[i], "candidate " + std::to_string(i), 1e-6);

  // The same keys again: nothing is uploaded, the values are the same.
  cuda->EvaluatePartials(withKeys({ 1, 2, 3, 4 }));
  EXPECT_EQ(cuda->Statistics().parentsUploaded, 4u);
  for (std::size_t i = 0; i < first.size(); ++i)
    for (std::size_t k = 0; k < first[i].size(); ++k)
      ASSERT_EQ(batch.values[i][k].intensity, first[i][k].intensity) << "candidate " << i;

  // Parent 0 changes. Under its old key the device still uses the points it
  // holds (the key is a promise the caller keeps)...
  parents[0] = population[5];
  const auto cpuChanged = cpuValues();
  cuda->EvaluatePartials(withKeys({ 1, 2, 3, 4 }));
  EXPECT_EQ(cuda->Statistics().parentsUploaded, 4u);
  bool differs = false;
  for (std::size_t i = 0; i < first.size(); ++i)
    for (std::size_t k = 0; k < first[i].size(); ++k)
    {
      ASSERT_EQ(batch.values[i][k].intensity, first[i][k].intensity) << "candidate " << i;
      differs = differs || cpuChanged[i][k].intensity != first[i][k].intensity;
    }
  ASSERT_TRUE(differs) << "the change of parent 0 does not matter to its candidates";
  // ... under a new key it is uploaded (it alone) and evaluated as it is now.
  cuda->EvaluatePartials(withKeys({ 9, 2, 3, 4 }));
  EXPECT_EQ(cuda->Statistics().parentsUploaded, 5u);
  for (std::size_t i = 0; i < first.size(); ++i)
    ExpectSameTotals(cpuChanged[i], batch.values[i], "candidate " + std::to_string(i), 1e-6);
  // Without keys every parent goes up each time.
  cuda->EvaluatePartials(withKeys({ 0, 0, 0, 0 }));
  EXPECT_EQ(cuda->Statistics().parentsUploaded, 9u);
  for (std::size_t i = 0; i < first.size(); ++i)
    ExpectSameTotals(cpuChanged[i], batch.values[i], "candidate " + std::to_string(i), 1e-6);
}

TEST(CudaEvaluationBackend, CandidatesStartedEarlyGetTheValuesOfAWholeBatch)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem        problem;
  const std::vector<DualMesh> parents = ParentsForBatchesInParts(problem, { 0, 1 });
  morea_test::RandomCandidates first(problem, parents, problem.parallel.groups[0], 3.0, 41);
  morea_test::RandomCandidates next(problem, parents, problem.parallel.groups[1], 3.0, 42);
  morea_test::RandomCandidates whole(problem, parents, problem.parallel.groups[1], 3.0, 42);
  const auto parentIndex = [&](const PartialCandidate & c) { return static_cast<std::size_t>(c.parent - parents.data()); };
  for (auto * batch : { &first, &next, &whole })
    for (PartialCandidate & c : batch->candidates)
    {
      c.parentKey = parentIndex(c) + 1;
      c.evaluateFolded = parentIndex(c) % 3 != 0;
    }
  const FoldHandling handling = RepairingFoldHandling(problem);
  auto early = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
  auto late = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
  early->SetFoldHandling(handling);
  late->SetFoldHandling(handling);
  // `next` is screened by the screen it is started with, head and rest: an
  // archive entry at 0 refuses every screened bound (every fourth candidate
  // is not screened); the skipped ones are sampled later.
  std::vector<RefusalBound> bounds(next.candidates.size());
  for (std::size_t i = 0; i < bounds.size(); ++i)
    next.candidates[i].bound = &bounds[i];
  RefusalScreen screen;
  screen.archive = { { 0.0, 0.0, 0.0 } };
  screen.witnesses = { 77 };
  screen.tetrahedra = problem.topology.NumberOfTetrahedra();
  screen.guidanceLimit = std::numeric_limits<double>::infinity();
  screen.fill = [&](std::size_t i) {
    bounds[i].screened = i % 4 != 3;
    bounds[i].parent.objectives = { { 0.0, 0.0, 0.0 } };
    bounds[i].parent.feasible = true;
    bounds[i].rest.samples = 1.0;
  };
  // While `first` is handed over, the candidates of `next` whose parents it
  // has finished with start early.
  std::size_t ranges = 0;
  early->EvaluatePartials(
    first.candidates,
    [&](std::size_t, std::size_t end) {
      ++ranges;
      if (end < first.candidates.size())
        early->StartNextPartials(next.candidates, HeadFinishedWith(first.candidates, end, next.candidates), &screen);
    },
    [&] { early->PrepareNextPartials(next.candidates); });
  ASSERT_GE(ranges, 2u) << "the batch was not handed over in parts";
  std::vector<std::size_t> skipped;
  std::size_t              witnessed = 0;
  early->EvaluatePartials(next.candidates, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
    {
      const bool unused = next.folds[i].Folded() && !next.candidates[i].evaluateFolded;
      if (!unused)
        EXPECT_EQ(bounds[i].skipped, i % 4 != 3) << "candidate " << i;
      if (bounds[i].skipped)
      {
        witnessed += bounds[i].witness == 77u ? 1 : 0; // 0: refused as infeasible (folded)
        for (const TetrahedronValues & v : next.values[i])
          EXPECT_EQ(v.intensity, 0.0);
        skipped.push_back(i);
      }
    }
    if (end == next.candidates.size()) // all handed over: sampled now
      early->SampleSkipped(next.candidates, skipped);
  });
  EXPECT_GT(early->Statistics().startedCandidates, 0u);
  EXPECT_LT(early->Statistics().startedCandidates, next.candidates.size());
  EXPECT_GT(skipped.size(), next.candidates.size() / 2);
  EXPECT_GT(witnessed, skipped.size() / 2) << "the entry that refused them";
  EXPECT_EQ(early->Statistics().boundSampledLater, skipped.size());
  EXPECT_GT(early->Statistics().boundSampledLaterSamples, 0.0);
  late->EvaluatePartials(whole.candidates);
  EXPECT_EQ(late->Statistics().startedCandidates, 0u);
  std::size_t folded = 0;
  for (std::size_t i = 0; i < next.candidates.size(); ++i)
  {
    ASSERT_EQ(next.folds[i].foldedSides, whole.folds[i].foldedSides) << "candidate " << i;
    ASSERT_EQ(next.folds[i].repairedSides, whole.folds[i].repairedSides) << "candidate " << i;
    ASSERT_EQ(next.source[i], whole.source[i]) << "candidate " << i;
    ASSERT_EQ(next.target[i], whole.target[i]) << "candidate " << i;
    folded += next.folds[i].foldedSides;
    if (next.folds[i].Folded() && !next.candidates[i].evaluateFolded)
      continue; // not evaluated
    for (std::size_t k = 0; k < next.values[i].size(); ++k)
    {
      ASSERT_EQ(next.values[i][k].intensity, whole.values[i][k].intensity) << "candidate " << i;
      ASSERT_EQ(next.values[i][k].guidance, whole.values[i][k].guidance) << "candidate " << i;
      ASSERT_EQ(next.values[i][k].samples, whole.values[i][k].samples) << "candidate " << i;
    }
  }
  EXPECT_GT(folded, 100u);
  // Outside the hand-over of a next-to-last part a start is ignored.
  for (PartialCandidate & c : next.candidates)
    c.bound = nullptr;
  const std::uint64_t started = early->Statistics().startedCandidates;
  early->PrepareNextPartials(whole.candidates);
  early->StartNextPartials(whole.candidates, 10, nullptr);
  early->EvaluatePartials(whole.candidates);
  EXPECT_EQ(early->Statistics().startedCandidates, started);
}

TEST(CudaEvaluationBackend, ABatchStartedEarlyKeepsItsRestWhenTheNextBatchStartsEarly)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem        problem;
  const std::vector<DualMesh> parents = ParentsForBatchesInParts(problem, { 1 });
  // Three batches in a row, as the optimiser runs them: `next` starts early
  // behind `first` and its rest follows in one part; `third` starts early
  // behind the head of `next`, whole.
  morea_test::RandomCandidates first(problem, parents, problem.parallel.groups[0], 3.0, 41);
  morea_test::RandomCandidates next(problem, parents, problem.parallel.groups[1], 3.0, 42);
  // The third takes the parents in reverse order: its candidates' parents lie
  // in other slots of the device's store than those of `next` at the same place.
  const std::vector<DualMesh>  reversed(parents.rbegin(), parents.rend());
  morea_test::RandomCandidates third(problem, reversed, problem.parallel.groups[0], 3.0, 43);
  morea_test::RandomCandidates whole(problem, parents, problem.parallel.groups[1], 3.0, 42);
  const auto parentIndex = [&](const PartialCandidate & c) { return static_cast<std::size_t>(c.parent - parents.data()); };
  for (auto * batch : { &first, &next, &whole })
    for (PartialCandidate & c : batch->candidates)
      c.parentKey = parentIndex(c) + 1;
  for (PartialCandidate & c : third.candidates)
    c.parentKey = parents.size() - static_cast<std::size_t>(c.parent - reversed.data());
  for (auto * batch : { &first, &next, &third, &whole })
    for (PartialCandidate & c : batch->candidates)
      c.evaluateFolded = true;
  // The sums: what the optimiser's acceptance reads of every candidate.
  std::vector<TetrahedronValues> nextSums(next.candidates.size()), wholeSums(whole.candidates.size());
  for (std::size_t i = 0; i < next.candidates.size(); ++i)
  {
    next.candidates[i].sum = &nextSums[i];
    whole.candidates[i].sum = &wholeSums[i];
  }
  const FoldHandling handling = RepairingFoldHandling(problem);
  auto backend = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
  auto reference = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
  backend->SetFoldHandling(handling);
  reference->SetFoldHandling(handling);
  reference->EvaluatePartials(whole.candidates);
  // The repair moves the points in place: each round starts from the drawn ones.
  const auto drawnSource = next.source, drawnTarget = next.target;
  for (int round = 0; round < 8; ++round)
  {
    for (std::size_t i = 0; i < next.candidates.size(); ++i)
    {
      std::copy(drawnSource[i].begin(), drawnSource[i].end(), next.source[i].begin());
      std::copy(drawnTarget[i].begin(), drawnTarget[i].end(), next.target[i].begin());
    }
    std::size_t headOfNext = 0;
    backend->EvaluatePartials(
      first.candidates,
      [&](std::size_t, std::size_t end) {
        if (end == first.candidates.size())
          return;
        headOfNext = HeadFinishedWith(first.candidates, end, next.candidates);
        backend->StartNextPartials(next.candidates, headOfNext, nullptr);
      },
      [&] { backend->PrepareNextPartials(next.candidates); });
    // The device reaches the rest of `next` only once the third batch has
    // started (as when other processes' work shares the device): the rest's
    // uploads wait while the host stages the third's head. A watchdog
    // releases the device should that hand-over never come.
    std::atomic<bool> release{ false };
    bool              releasedByTheHandOver = false;
    HoldCudaEvaluationStream(*backend, release);
    struct Watchdog
    {
      std::atomic<bool> & release;
      std::thread         thread;
      ~Watchdog()
      {
        release.store(true);
        thread.join();
      }
    } watchdog{ release, std::thread([&release] {
                  for (int wait = 0; wait < 1000 && !release.load(); ++wait)
                    std::this_thread::sleep_for(std::chrono::milliseconds(10));
                  release.store(true);
                }) };
    const std::uint64_t startedBefore = backend->Statistics().startedCandidates;
    backend->EvaluatePartials(
      next.candidates,
      [&](std::size_t, std::size_t end) {
        if (end != headOfNext)
          return;
        backend->StartNextPartials(third.candidates, third.candidates.size(), nullptr);
        releasedByTheHandOver = !release.load();
        release.store(true);
      },
      [&] { backend->PrepareNextPartials(third.candidates); });
    ASSERT_TRUE(releasedByTheHandOver) << "round " << round << ": the head of `next` was not handed over alone";
    const std::uint64_t startedNext = backend->Statistics().startedCandidates - startedBefore;
    backend->EvaluatePartials(third.candidates);
    ASSERT_GT(startedNext, 0u) << "round " << round << ": the second batch did not start early";
    ASSERT_LT(startedNext, next.candidates.size()) << "round " << round << ": it has no rest";
    ASSERT_EQ(backend->Statistics().startedCandidates - startedBefore, startedNext + third.candidates.size())
      << "round " << round << ": the third batch did not start early";
    for (std::size_t i = 0; i < next.candidates.size(); ++i)
    {
      ASSERT_EQ(next.folds[i].foldedSides, whole.folds[i].foldedSides) << "round " << round << " candidate " << i;
      ASSERT_EQ(next.folds[i].repairedSides, whole.folds[i].repairedSides) << "round " << round << " candidate " << i;
      ASSERT_EQ(nextSums[i].magnitude, wholeSums[i].magnitude) << "round " << round << " candidate " << i;
      ASSERT_EQ(nextSums[i].intensity, wholeSums[i].intensity) << "round " << round << " candidate " << i;
      ASSERT_EQ(nextSums[i].guidance, wholeSums[i].guidance) << "round " << round << " candidate " << i;
      ASSERT_EQ(nextSums[i].samples, wholeSums[i].samples) << "round " << round << " candidate " << i;
    }
    nextSums.assign(nextSums.size(), TetrahedronValues{});
  }
}

TEST(CudaEvaluationBackend, FoldChecksAndRepairAgreeWithTheCpu)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  OptimiserTestProblem problem;
  const auto           population = problem.InitialPopulation(problem.Options());
  const std::vector<DualMesh> parents(population.begin(), population.begin() + 8);
  for (bool repair : { true, false })
    for (std::size_t g = 0; g < 2; ++g)
    {
      const auto & group = problem.parallel.groups[g];
      const std::string what = (repair ? "repair, group " : "check only, group ") + std::to_string(g);
      morea_test::RandomCandidates onCpu(problem, parents, group, 4.0, 31 + g);
      morea_test::RandomCandidates onGpu(problem, parents, group, 4.0, 31 + g);
      FoldHandling                 handling;
      handling.constraint = problem.constraint.get();
      handling.base = &problem.base;
      handling.repair = repair;
      auto cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
      auto cuda = CreateCudaEvaluationBackend(*problem.evaluator, 2);
      cpu->SetFoldHandling(handling);
      cuda->SetFoldHandling(handling);
      cpu->EvaluatePartials(onCpu.candidates);
      cuda->EvaluatePartials(onGpu.candidates);
      EXPECT_GT(cuda->Statistics().foldSeconds, 0.0);
      std::size_t folded = 0, repaired = 0;
      for (std::size_t i = 0; i < onCpu.candidates.size(); ++i)
      {
        EXPECT_EQ(onCpu.folds[i].foldedSides, onGpu.folds[i].foldedSides) << what << " candidate " << i;
        EXPECT_EQ(onCpu.folds[i].repairedSides, onGpu.folds[i].repairedSides) << what << " candidate " << i;
        folded += onCpu.folds[i].foldedSides;
        repaired += onCpu.folds[i].repairedSides;
        // The same moves (RepairNoise.h), rounded the same way: the same
        // bits (they seed the tetrahedra's samples).
        EXPECT_EQ(onCpu.source[i], onGpu.source[i]) << what << " candidate " << i;
        EXPECT_EQ(onCpu.target[i], onGpu.target[i]) << what << " candidate " << i;
        if (!onCpu.folds[i].Folded())
          ExpectSameTotals(onCpu.values[i], onGpu.values[i], what + " candidate " + std::to_string(i), 1e-6);
      }
      EXPECT_GT(folded, 10u) << what;
      if (repair)
        EXPECT_GT(repaired, folded / 2) << what;
      else
        EXPECT_EQ(repaired, 0u) << what;
    }
}

// The texture path reads each structure's distances from textures of its own,
// only near its contour (a near-block mask of 4, 8 or 16 bits per block), for
// up to cuda::MaxTextureStructures structures: with 1, 3, 4, 5, 8 and 16 crossing
// spheres (each mask width and kernel instance), whole solutions and partial
// candidates agree with the CPU as the one-structure texture tests do: the
// same sample counts and folds, magnitudes to 1e-9, objectives to 1e-2.
TEST(CudaEvaluationBackend, TexturePathAgreesWithTheCpuForManyStructures)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  for (const std::size_t structures : { 1u, 3u, 4u, 5u, 8u, 16u })
  {
    const std::string what = std::to_string(structures) + " structures";
    OptimiserTestProblem problem;
    problem.UseStructures(structures);
    problem.data.samplingRate = 2.0;
    GomeaOptions options = problem.Options(9);
    options.populationSize = 4;
    const auto population = problem.InitialPopulation(options);
    auto       cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
    auto       texture = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
    EXPECT_EQ(texture->Name(), "cuda-texture") << what;
    EXPECT_EQ(texture->PathNote(), "") << what;

    const auto a = EvaluateAll(*cpu, population);
    const auto b = EvaluateAll(*texture, population);
    for (std::size_t s = 0; s < population.size(); ++s)
    {
      ObjectiveTotals ta, tb;
      for (std::size_t t = 0; t < a[s].size(); ++t)
      {
        EXPECT_EQ(a[s][t].samples, b[s][t].samples) << what;
        EXPECT_EQ(a[s][t].folded, b[s][t].folded) << what;
        ExpectRelativelyClose(a[s][t].magnitude, b[s][t].magnitude, 1e-9, what + " magnitude");
        ta.Add(a[s][t]);
        tb.Add(b[s][t]);
      }
      const Fitness fa = ta.ToFitness(a[s].size()), fb = tb.ToFitness(b[s].size());
      EXPECT_GT(fa.objectives[2], 0.0) << what << ": no guidance to compare";
      for (std::size_t m = 0; m < NumberOfObjectives; ++m)
        ExpectRelativelyClose(fa.objectives[m], fb.objectives[m], 1e-2,
                              what + ", solution " + std::to_string(s) + ", objective " + std::to_string(m));
      if (s == 0)
        std::cout << what << ": guidance cpu " << fa.objectives[2] << " texture " << fb.objectives[2] << "\n";
    }

    // Partial candidates of the first two groups (through the batch path:
    // corners built on the device, the parts' schedule), the same check
    // over each batch.
    for (std::size_t g = 0; g < 2; ++g)
    {
      const auto &                 group = problem.parallel.groups[g];
      morea_test::RandomCandidates onCpu(problem, population, group, 1.5, 41 + g);
      morea_test::RandomCandidates onGpu(problem, population, group, 1.5, 41 + g);
      cpu->EvaluatePartials(onCpu.candidates);
      texture->EvaluatePartials(onGpu.candidates);
      ObjectiveTotals ta, tb;
      std::size_t     count = 0;
      for (std::size_t i = 0; i < onCpu.candidates.size(); ++i)
        for (std::size_t t = 0; t < onCpu.values[i].size(); ++t, ++count)
        {
          const TetrahedronValues &x = onCpu.values[i][t], &y = onGpu.values[i][t];
          EXPECT_EQ(x.samples, y.samples) << what << ", group " << g << ", candidate " << i;
          EXPECT_EQ(x.folded, y.folded) << what << ", group " << g << ", candidate " << i;
          ExpectRelativelyClose(x.magnitude, y.magnitude, 1e-9, what + " candidate magnitude");
          ta.Add(x);
          tb.Add(y);
        }
      ASSERT_GT(count, 0u);
      const Fitness fa = ta.ToFitness(count), fb = tb.ToFitness(count);
      EXPECT_GT(fa.objectives[2], 0.0) << what << ": no guidance to compare";
      for (std::size_t m = 0; m < NumberOfObjectives; ++m)
        ExpectRelativelyClose(fa.objectives[m], fb.objectives[m], 1e-2,
                              what + ", candidates of group " + std::to_string(g) + ", objective " +
                                std::to_string(m));
    }
  }
}

// Candidates a refusal bound skipped and the optimiser needs after all are
// sampled chunk by chunk (LaunchSampleListedChunks, the kernel instance for
// the structures too): with 5 and 16 structures, the same sums as the
// batches' sampling, so a run ends exactly as one that samples everything.
TEST(CudaEvaluationBackend, TexturePathWithManyStructuresSamplesSkippedCandidatesAlike)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  for (const std::size_t structures : { 5u, 16u })
  {
    OptimiserTestProblem problem;
    problem.UseStructures(structures);
    const GomeaOptions options = problem.Options(31, 12);
    GomeaOptions       sampleAll = options;
    sampleAll.boundRefusals = false;
    auto       backend = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
    const auto all = RunToEnd(problem, *backend, sampleAll);
    const auto bounded = RunToEnd(problem, *backend, options);
    ExpectSameDecisions(all, bounded, std::to_string(structures) + " structures");
    std::size_t later = 0;
    for (const GenerationRecord & g : bounded.second)
      later += g.boundSampledLater;
    EXPECT_GT(later, 0u) << structures << " structures: no skipped candidate was sampled later";
  }
}

// Asked for, the texture path runs up to cuda::MaxTextureStructures (16)
// structures and says nothing; with more, the backend runs the exact kernels
// (named "cuda-exact", agreeing with the CPU to the exact path's 1e-4) and says
// which path it took and why, rather than falling back silently.
TEST(CudaEvaluationBackend, TexturePathRunsUpToSixteenStructuresAndNamesItsFallback)
{
  MOREA_REQUIRE_CUDA_DEVICE();
  for (const std::size_t structures : { 5u, 8u, 16u })
  {
    OptimiserTestProblem problem;
    problem.UseStructures(structures);
    auto texture = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
    EXPECT_EQ(texture->Name(), "cuda-texture") << structures << " structures";
    EXPECT_EQ(texture->PathNote(), "") << structures << " structures";
    EXPECT_EQ(CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Exact)->PathNote(), "");
  }
  OptimiserTestProblem problem;
  problem.UseStructures(17);
  auto fallback = CreateCudaEvaluationBackend(*problem.evaluator, 2, CudaInterpolation::Texture);
  EXPECT_EQ(fallback->Name(), "cuda-exact");
  const std::string note = fallback->PathNote();
  EXPECT_NE(note.find("exact CUDA kernels instead of the texture path"), std::string::npos) << note;
  EXPECT_NE(note.find("17 guidance structures"), std::string::npos) << note;
  EXPECT_NE(note.find("at most 16"), std::string::npos) << note;
  GomeaOptions options = problem.Options(9);
  options.populationSize = 2;
  const auto population = problem.InitialPopulation(options);
  auto       cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  const auto a = EvaluateAll(*cpu, population);
  const auto b = EvaluateAll(*fallback, population);
  for (std::size_t s = 0; s < population.size(); ++s)
    ExpectSameTotals(a[s], b[s], "17 structures, solution " + std::to_string(s));
}
