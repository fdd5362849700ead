// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MO-RV-GOMEA on a small synthetic problem: the archive stays a front, runs
// are reproducible (seed, threads, evaluation order), checkpoints resume
// exactly, and the optimiser makes progress.
#include "OptimiserTestProblem.h"

#include "morea_core/CheckpointWriter.h"
#include "morea_core/Error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <numeric>
#include <random>
#include <sstream>
#include <thread>
#include <utility>

using namespace morea_core;
using morea_test::OptimiserTestProblem;

namespace
{
/** Forwards to the CPU backend with the batch shuffled, the caller's
 *  meanwhile work at another time. */
class ShufflingBackend final : public EvaluationBackend
{
public:
  /** `pause`: how long it waits between the caller's meanwhile and the
   *  first hand-over, as a device's evaluation may take. */
  explicit ShufflingBackend(const TetrahedronEvaluator & evaluator,
                            std::chrono::milliseconds pause = std::chrono::milliseconds(0))
    : m_Cpu(CreateCpuEvaluationBackend(evaluator, 2))
    , m_Pause(pause)
  {}
  std::string
  Name() const override
  {
    return "shuffling";
  }
  void
  EvaluateSolutions(const std::vector<const DualMesh *> & s,
                    const std::vector<std::vector<TetrahedronValues> *> & v) override
  {
    m_Cpu->EvaluateSolutions(s, v);
  }
  using EvaluationBackend::EvaluatePartials;
  void
  EvaluatePartials(const std::vector<PartialCandidate> & candidates, const ReadyCandidates & ready,
                   const Meanwhile & meanwhile) override
  {
    std::vector<std::size_t> order(candidates.size());
    std::iota(order.begin(), order.end(), std::size_t{ 0 });
    std::shuffle(order.begin(), order.end(), m_Random);
    std::vector<PartialCandidate> shuffled;
    for (std::size_t i : order)
      shuffled.push_back(candidates[i]);
    if (m_HasRefusalScreen)
    {
      // Bounds are filled by the caller's candidate numbers.
      RefusalScreen screen = m_RefusalScreen;
      screen.fill = [fill = m_RefusalScreen.fill, order](std::size_t i) { fill(order[i]); };
      m_Cpu->SetRefusalScreen(screen);
    }
    else
      m_Cpu->ClearRefusalScreen();
    m_Cpu->EvaluatePartials(shuffled);
    // After the evaluation (the CPU backend calls it before).
    if (meanwhile)
      meanwhile();
    std::this_thread::sleep_for(m_Pause);
    // Handed over in parts of random sizes, as a device backend may.
    for (std::size_t begin = 0; ready && begin < candidates.size();)
    {
      const std::size_t end = std::min(candidates.size(), begin + 1 + m_Random() % 64);
      ready(begin, end);
      begin = end;
    }
  }
  void
  SetFoldHandling(const FoldHandling & handling) override
  {
    EvaluationBackend::SetFoldHandling(handling);
    m_Cpu->SetFoldHandling(handling);
  }
  void
  SampleSkipped(const std::vector<PartialCandidate> & candidates, const std::vector<std::size_t> & which) override
  {
    m_Cpu->SampleSkipped(candidates, which);
  }

private:
  std::unique_ptr<EvaluationBackend> m_Cpu;
  std::mt19937                       m_Random{ 99 };
  std::chrono::milliseconds          m_Pause;
};

std::vector<ObjectiveVector>
Front(const MoRvGomea & optimiser)
{
  return optimiser.Archive().Objectives();
}

std::vector<ObjectiveVector>
RunToEnd(const OptimiserTestProblem & problem, EvaluationBackend & backend, const GomeaOptions & options)
{
  MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, backend, options);
  optimiser.Initialize(problem.InitialPopulation(options));
  optimiser.Run();
  return Front(optimiser);
}
} // namespace

TEST(MoRvGomea, ArchiveHoldsOnlyMutuallyNonDominatedFoldFreeSolutions)
{
  OptimiserTestProblem problem;
  auto                 backend = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  const GomeaOptions   options = problem.Options(5, 10);
  MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options);
  optimiser.Initialize(problem.InitialPopulation(options));
  const double initialSamples = backend->Statistics().samples;
  optimiser.Run();
  // The records account for every sample of the partial evaluations; the
  // CPU backend has no device time.
  double recordedSamples = 0.0;
  for (const GenerationRecord & r : optimiser.History())
  {
    EXPECT_EQ(r.deviceKernelSeconds, 0.0);
    recordedSamples += r.samples;
  }
  EXPECT_GT(optimiser.History().back().samples, 0.0);
  EXPECT_DOUBLE_EQ(recordedSamples, backend->Statistics().samples - initialSamples);
  const auto & entries = optimiser.Archive().Entries();
  ASSERT_GT(entries.size(), 2u);
  EXPECT_LE(entries.size(), options.archiveCapacity);
  for (std::size_t i = 0; i < entries.size(); ++i)
  {
    EXPECT_TRUE(entries[i].fitness.feasible);
    EXPECT_TRUE(problem.constraint->Evaluate(entries[i].solution).Feasible());
    for (std::size_t j = 0; j < entries.size(); ++j)
      if (i != j)
        EXPECT_FALSE(Dominates(entries[i].fitness.objectives, entries[j].fitness.objectives)) << i << " dominates " << j;
    // The stored objectives are those of the stored meshes (to rounding of
    // accumulated partial updates).
    const Fitness fresh = optimiser.EvaluateFully(entries[i].solution);
    for (std::size_t m = 0; m < NumberOfObjectives; ++m)
      EXPECT_NEAR(fresh.objectives[m], entries[i].fitness.objectives[m], 1e-6 * (1.0 + fresh.objectives[m]));
  }
  // One record per generation plus the initial one.
  ASSERT_EQ(optimiser.History().size(), options.generations + 1);
  EXPECT_GT(optimiser.History().back().accepted, 0u);
}

TEST(MoRvGomea, ImprovesGuidanceAndHypervolume)
{
  OptimiserTestProblem problem;
  auto                 backend = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  GomeaOptions         options = problem.Options(7, 20);
  options.steeringEnabled = false;
  MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options);
  optimiser.Initialize(problem.InitialPopulation(options));
  const GenerationRecord first = optimiser.History().front();
  optimiser.Run();
  const GenerationRecord last = optimiser.History().back();
  EXPECT_LT(last.bestGuidance, 0.8 * first.bestGuidance);
  EXPECT_GT(last.hypervolume, first.hypervolume);
}

TEST(MoRvGomea, SameSeedSameFrontWhateverTheThreadsOrEvaluationOrder)
{
  OptimiserTestProblem problem;
  const GomeaOptions   options = problem.Options(21, 6);
  auto                 one = CreateCpuEvaluationBackend(*problem.evaluator, 1);
  auto                 three = CreateCpuEvaluationBackend(*problem.evaluator, 3);
  ShufflingBackend     shuffling(*problem.evaluator);
  const auto           a = RunToEnd(problem, *one, options);
  const auto           b = RunToEnd(problem, *three, options);
  const auto           c = RunToEnd(problem, shuffling, options);
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, c);
  // The optimiser's own host threads (sampling, fold checks) do not matter either.
  GomeaOptions oneHostThread = options;
  oneHostThread.threads = 1;
  GomeaOptions fourHostThreads = options;
  fourHostThreads.threads = 4;
  EXPECT_EQ(a, RunToEnd(problem, *one, oneHostThread));
  EXPECT_EQ(a, RunToEnd(problem, *three, fourHostThreads));
  const auto d = RunToEnd(problem, *one, problem.Options(22, 6));
  EXPECT_NE(a, d);
}

TEST(MoRvGomea, TheFirstGroupSplitInTwoBatchesChangesNoDecision)
{
  // The generation's first parallel group in two batches of half the
  // population each: the same candidates, seeds and acceptance order, so
  // the same front; one more batch per generation reaches the backend.
  OptimiserTestProblem problem;
  GomeaOptions         whole = problem.Options(23, 7);
  whole.firstBatchSplit = 0;
  GomeaOptions split = whole;
  split.firstBatchSplit = 2;
  auto       backend = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  const auto before = backend->Statistics().batches;
  const auto a = RunToEnd(problem, *backend, whole);
  const auto middle = backend->Statistics().batches;
  const auto b = RunToEnd(problem, *backend, split);
  ShufflingBackend shuffling(*problem.evaluator); // handed over in parts of random sizes
  const auto       c = RunToEnd(problem, shuffling, split);
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, c);
  EXPECT_EQ(backend->Statistics().batches - middle, middle - before + whole.generations);
  // A population below the threshold goes whole.
  GomeaOptions large = whole;
  large.firstBatchSplit = whole.populationSize + 1;
  const auto beforeLarge = backend->Statistics().batches;
  EXPECT_EQ(a, RunToEnd(problem, *backend, large));
  EXPECT_EQ(backend->Statistics().batches - beforeLarge, middle - before);
}

TEST(MoRvGomea, DrawingBatchesAheadChangesNoDecision)
{
  // Batches drawn on threads of their own, the one after next while the
  // current one is evaluated: the same seeds in the same order, so the same
  // front, whatever the threads and the backend's hand-over.
  OptimiserTestProblem problem;
  GomeaOptions         here = problem.Options(29, 7);
  here.drawAheadThreads = 0;
  here.firstBatchSplit = 2; // the first group in two batches
  auto       backend = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  const auto a = RunToEnd(problem, *backend, here);
  ASSERT_FALSE(a.empty());
  for (const std::size_t threads : { 1, 2, 3 })
  {
    GomeaOptions ahead = here;
    ahead.drawAheadThreads = threads;
    {
      MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, ahead);
      EXPECT_EQ(optimiser.DrawAheadThreads(), threads);
    }
    EXPECT_EQ(a, RunToEnd(problem, *backend, ahead)) << threads << " draw-ahead threads";
    ShufflingBackend shuffling(*problem.evaluator); // handed over in parts of random sizes
    EXPECT_EQ(a, RunToEnd(problem, shuffling, ahead)) << threads << " draw-ahead threads, shuffled";
  }
  // The draw-ahead threads done before the acceptance starts, as beside a
  // device on a quiet machine, and (above) late, as on a busy one: the
  // models they draw from must not depend on how far the acceptance is.
  GomeaOptions     ahead = here;
  ahead.drawAheadThreads = 2;
  ShufflingBackend pausing(*problem.evaluator, std::chrono::milliseconds(5));
  EXPECT_EQ(a, RunToEnd(problem, pausing, ahead)) << "draw-ahead threads with the acceptance after a pause";
  // Without the split of the first group, too (a generation's first two
  // batches are then two groups, and the batches are fewer).
  GomeaOptions whole = here;
  whole.firstBatchSplit = 0;
  GomeaOptions wholeAhead = whole;
  wholeAhead.drawAheadThreads = 2;
  EXPECT_EQ(RunToEnd(problem, *backend, whole), RunToEnd(problem, *backend, wholeAhead));
  // Automatic: none beside a backend that evaluates on the host's cores.
  GomeaOptions automatic = here;
  automatic.drawAheadThreads = GomeaOptions::DrawAheadAutomatic;
  MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, automatic);
  EXPECT_EQ(optimiser.DrawAheadThreads(), 0u);
}

TEST(MoRvGomea, RefusalBoundsSpareSamplesAndChangeNoDecision)
{
  // Candidates whose bound (RefusalBound.h) is refused go unsampled; the
  // optimiser samples those its exact check does not refuse. The fronts,
  // ids and acceptance counts must be those of a run that samples all.
  OptimiserTestProblem problem;
  GomeaOptions         options = problem.Options(31, 12);
  GomeaOptions         sampleAll = options;
  sampleAll.boundRefusals = false;
  const auto run = [&](EvaluationBackend & backend, const GomeaOptions & o) {
    MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, backend, o);
    optimiser.Initialize(problem.InitialPopulation(o));
    optimiser.Run();
    return std::make_pair(optimiser.Archive().Entries(), optimiser.History());
  };
  auto       cpu = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  const auto all = run(*cpu, sampleAll);
  const auto bounded = run(*cpu, options);
  ShufflingBackend shuffling(*problem.evaluator); // handed over in parts of random sizes
  const auto       shuffled = run(shuffling, options);
  ASSERT_EQ(all.first.size(), bounded.first.size());
  ASSERT_EQ(all.first.size(), shuffled.first.size());
  for (std::size_t i = 0; i < all.first.size(); ++i)
  {
    EXPECT_EQ(all.first[i].id, bounded.first[i].id);
    EXPECT_EQ(all.first[i].fitness.objectives, bounded.first[i].fitness.objectives);
    EXPECT_EQ(all.first[i].fitness.objectives, shuffled.first[i].fitness.objectives);
    EXPECT_EQ(all.first[i].solution.source, bounded.first[i].solution.source);
  }
  std::size_t skipped = 0, later = 0;
  double      spared = 0.0, drawn = 0.0, drawnAll = 0.0;
  for (std::size_t g = 0; g < all.second.size(); ++g)
  {
    EXPECT_EQ(all.second[g].accepted, bounded.second[g].accepted);
    EXPECT_EQ(all.second[g].boundSkipped, 0u);
    skipped += bounded.second[g].boundSkipped;
    later += bounded.second[g].boundSampledLater;
    spared += bounded.second[g].boundSkippedSamples;
    drawn += bounded.second[g].samples;
    drawnAll += all.second[g].samples;
  }
  std::cout << "bound skipped " << skipped << " candidates, " << later << " sampled later; " << spared
            << " of " << drawnAll << " samples spared\n";
  EXPECT_GT(skipped, 100u);
  EXPECT_GT(later, 0u);
  EXPECT_GT(spared, 0.05 * drawnAll);
  // Every sample is either drawn or spared.
  EXPECT_NEAR(drawn + spared, drawnAll, 1e-6 * drawnAll);
}

TEST(MoRvGomea, SeededRunsGiveTheRecordedResults)
{
  // Recorded with the optimiser that batches each parallel group's candidates
  // of the whole population and sums a candidate's change as its new values
  // less its parent's element sum (MoRvGomea::ElementSum); changes that keep
  // the arithmetic (e.g. parallel archive verdicts) must not change any
  // result: the accepted counts and the archive's
  // identifiers (handed out in acceptance order) pin every acceptance
  // decision, the objective values the arithmetic. Recorded on x86-64 with GCC
  // (Release); a compiler that rounds differently would need new values.
  struct Entry
  {
    std::size_t     index;
    std::uint64_t   id;
    ObjectiveVector objectives;
  };
  struct Expected
  {
    std::vector<std::size_t> accepted; ///< per generation, the initial record first
    bool                     discretised;
    std::size_t              size;
    std::uint64_t            idSum;
    double                   hypervolume, bestGuidance;
    std::vector<Entry>       entries;
  };
  OptimiserTestProblem problem;
  auto                 backend = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  // A small archive, thinned time and again, with adaptive steering.
  const GomeaOptions thinned = problem.Options(5, 10);
  const Expected     thinnedExpected{
    { 0, 314, 264, 302, 231, 297, 313, 335, 326, 348, 288 },
    true,
    16,
    44976,
    0.50411710795396592,
    0.049008656009977489,
    { { 0, 2070, { { 0.3141647096427454, 0.0014353617592583964, 0.082719732010503783 } } },
      { 1, 2140, { { 0.23137910353086927, 0.0014517493200249894, 0.079516741178363617 } } },
      { 2, 2267, { { 0.25867303501017652, 0.0014449520546539114, 0.079269440236986816 } } },
      { 3, 2840, { { 0.17968541697871968, 0.0015981222182920301, 0.091100388204911717 } } },
      { 4, 2850, { { 0.34845781209439591, 0.0013036023130679035, 0.07220964558138776 } } },
      { 5, 2904, { { 0.38130189001784748, 0.0010594031891323099, 0.0655704763991172 } } },
      { 6, 2925, { { 0.20351411981022546, 0.0015083157541683394, 0.083525281853679495 } } },
      { 7, 2956, { { 0.18942318341698514, 0.0015159742268417071, 0.083941480232527163 } } },
      { 8, 2961, { { 0.36442411171740918, 0.0010718730493250552, 0.06592834478595036 } } },
      { 9, 2967, { { 0.22871184571282532, 0.0014973691687682532, 0.089093645752942499 } } },
      { 10, 2997, { { 0.35569309517026254, 0.0010723904588244863, 0.06595812358151866 } } } }
  };
  // A large archive that is never thinned, so verdicts stay valid across
  // acceptances; without steering.
  GomeaOptions growing = problem.Options(21, 12);
  growing.archiveCapacity = 2000;
  growing.steeringEnabled = false;
  const Expected growingExpected{
    { 0, 746, 446, 433, 552, 391, 447, 462, 420, 380, 342, 390, 330 },
    false,
    601,
    2447198,
    0.72318775329885854,
    0.029722374477884197,
    { { 0, 0, { { 0, 0.0030555015533522672, 0.17348691352031553 } } },
      { 1, 12, { { 0.011801526201092649, 0.0027613695363299549, 0.15779547914188502 } } },
      { 2, 65, { { 0.011801104566209338, 0.00276136956768541, 0.15779547914188502 } } },
      { 3, 66, { { 0.011800344638514267, 0.0027615739909352044, 0.1578071607734472 } } },
      { 419, 4873, { { 0.52000560079997982, 0.00059521998921216067, 0.038404886214551764 } } },
      { 420, 4874, { { 0.52003136165546515, 0.000595219987149181, 0.038404886214551764 } } },
      { 421, 4875, { { 0.52652741319196117, 0.00059379427660547629, 0.038303661818095421 } } },
      { 422, 4885, { { 0.1768736103744537, 0.001352452833892093, 0.078711748931363651 } } } }
  };
  for (const auto & [options, expected] :
       { std::make_pair(thinned, thinnedExpected), std::make_pair(growing, growingExpected) })
  {
    MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options);
    optimiser.Initialize(problem.InitialPopulation(options));
    optimiser.Run();
    const auto & history = optimiser.History();
    std::vector<std::size_t> accepted;
    for (const GenerationRecord & r : history)
      accepted.push_back(r.accepted);
    EXPECT_EQ(accepted, expected.accepted) << options.seed;
    EXPECT_EQ(history.back().hypervolume, expected.hypervolume)
      << options.seed << ": " << std::setprecision(17) << history.back().hypervolume;
    EXPECT_EQ(history.back().bestGuidance, expected.bestGuidance) << options.seed;
    const ElitistArchive & archive = optimiser.Archive();
    EXPECT_EQ(archive.IsDiscretised(), expected.discretised) << options.seed;
    ASSERT_EQ(archive.Size(), expected.size) << options.seed;
    std::uint64_t idSum = 0;
    for (const ArchiveEntry & e : archive.Entries())
      idSum += e.id;
    EXPECT_EQ(idSum, expected.idSum) << options.seed;
    for (const Entry & e : expected.entries)
    {
      EXPECT_EQ(archive.Entries()[e.index].id, e.id) << options.seed << " " << e.index;
      EXPECT_EQ(archive.Entries()[e.index].fitness.objectives, e.objectives) << options.seed << " " << e.index;
    }
  }
}

TEST(MoRvGomea, ResumedRunEndsWithTheSameFront)
{
  OptimiserTestProblem problem;
  const GomeaOptions   options = problem.Options(33, 9);
  auto                 backend = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  const auto           uninterrupted = RunToEnd(problem, *backend, options);

  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "morea-optimiser-test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "state.ckpt").string();
  {
    MoRvGomea first(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options);
    first.Initialize(problem.InitialPopulation(options));
    for (int g = 0; g < 5; ++g) // across the steering start and a full re-evaluation
      first.RunGeneration();
    // Written behind the next generation, as `morea register` writes it.
    CheckpointWriter writer;
    std::string      reused(123, 'x'); // filled afresh, whatever it held
    first.CheckpointBytes(reused);
    writer.Write(std::move(reused), path);
    first.SaveCheckpoint(path + ".direct");
    first.RunGeneration(); // work after the checkpoint is lost with the "killed" run
    writer.Wait();
    std::ifstream a(path, std::ios::binary), b(path + ".direct", std::ios::binary);
    const std::string behind((std::istreambuf_iterator<char>(a)), std::istreambuf_iterator<char>());
    const std::string direct((std::istreambuf_iterator<char>(b)), std::istreambuf_iterator<char>());
    EXPECT_GT(behind.size(), 1000u);
    EXPECT_EQ(behind, direct) << "the same state, written behind or at once";
  }
  MoRvGomea resumed(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options);
  resumed.LoadCheckpoint(path);
  EXPECT_EQ(resumed.Generation(), 5u);
  resumed.Run();
  EXPECT_EQ(Front(resumed), uninterrupted);
  EXPECT_EQ(resumed.History().size(), options.generations + 1);

  // A checkpoint of another configuration is refused with a clear error.
  MoRvGomea other(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend,
                  problem.Options(34, 9));
  EXPECT_THROW(other.LoadCheckpoint(path), Error);
  // A truncated checkpoint too, and the optimiser is left untouched.
  {
    std::ifstream in(path, std::ios::binary);
    std::string   bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  MoRvGomea truncated(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options);
  EXPECT_THROW(truncated.LoadCheckpoint(path), Error);
  EXPECT_EQ(truncated.Generation(), 0u);
  std::filesystem::remove_all(dir);
}

TEST(MoRvGomea, BadUseGivesClearErrors)
{
  OptimiserTestProblem problem;
  auto                 backend = CreateCpuEvaluationBackend(*problem.evaluator, 1);
  GomeaOptions         options = problem.Options();
  MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options);
  EXPECT_THROW(optimiser.RunGeneration(), Error);
  EXPECT_THROW(optimiser.Initialize(std::vector<DualMesh>(3, DualMesh::FromBase(problem.base))), Error);
  options.populationSize = 1;
  EXPECT_THROW(MoRvGomea(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options),
               Error);
}
