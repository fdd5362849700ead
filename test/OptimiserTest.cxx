// MO-RV-GOMEA on a small synthetic problem: the archive stays a front, runs
// are reproducible (seed, threads, evaluation order), checkpoints resume
// exactly, and the optimiser makes progress.
#include "OptimiserTestProblem.h"

#include "morea/Error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>
#include <utility>

using namespace morea;
using morea_test::OptimiserTestProblem;

namespace
{
/** Forwards to the CPU backend with the batch shuffled. */
class ShufflingBackend final : public EvaluationBackend
{
public:
  explicit ShufflingBackend(const TetrahedronEvaluator & evaluator)
    : m_Cpu(CreateCpuEvaluationBackend(evaluator, 2))
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
  void
  EvaluatePartials(const std::vector<PartialCandidate> & candidates) override
  {
    std::vector<PartialCandidate> shuffled = candidates;
    std::shuffle(shuffled.begin(), shuffled.end(), m_Random);
    m_Cpu->EvaluatePartials(shuffled);
  }
  void
  SetFoldHandling(const FoldHandling & handling) override
  {
    EvaluationBackend::SetFoldHandling(handling);
    m_Cpu->SetFoldHandling(handling);
  }

private:
  std::unique_ptr<EvaluationBackend> m_Cpu;
  std::mt19937                       m_Random{ 99 };
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
  optimiser.Run();
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

TEST(MoRvGomea, SeededRunsGiveTheRecordedResults)
{
  // Recorded with the optimiser as it was before its acceptance step judged
  // candidates against the archive in parallel (ElitistArchive::Judge), which
  // must not change any result: the accepted counts and the archive's
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
    { 0, 356, 268, 326, 280, 360, 447, 234, 212, 294, 181 },
    true,
    13,
    36866,
    0.34082973159482194,
    0.051737519319882977,
    { { 0, 2298, { { 0.39555693491660437, 0.0010755913862573083, 0.061767462142242373 } } },
      { 1, 2726, { { 0.18884716252253642, 0.0016029849258790744, 0.091240494355022794 } } },
      { 2, 2738, { { 0.35576571918057387, 0.0011003742446242316, 0.062780048137067918 } } },
      { 3, 2864, { { 0.2032461990560013, 0.0015967071986500961, 0.087691919979401373 } } },
      { 4, 2879, { { 0.20985939439029633, 0.0016117259621372254, 0.085995803331956958 } } },
      { 5, 2894, { { 0.22493955816209316, 0.0014186627341507378, 0.081073608064217539 } } },
      { 6, 2895, { { 0.23345602325608841, 0.0013647386097224413, 0.075400772099714533 } } },
      { 7, 2898, { { 0.28041682025187292, 0.0013136075594678688, 0.073840657979883165 } } },
      { 8, 2901, { { 0.29095375624986597, 0.0012837988859265711, 0.071323489354617173 } } },
      { 9, 2903, { { 0.29709806673664113, 0.0011848209248723346, 0.067520194713702672 } } },
      { 10, 2918, { { 0.16360887249377928, 0.0016363769566233124, 0.091712756553464489 } } },
      { 11, 2971, { { 0.44757978200186616, 0.00097239824228166031, 0.054221790718979188 } } },
      { 12, 2981, { { 0.5180151951642924, 0.00094281835799466852, 0.051737519319882977 } } } }
  };
  // A large archive that is never thinned, so verdicts stay valid across
  // acceptances; without steering.
  GomeaOptions growing = problem.Options(21, 12);
  growing.archiveCapacity = 2000;
  growing.steeringEnabled = false;
  const Expected growingExpected{
    { 0, 716, 509, 439, 491, 444, 434, 581, 460, 428, 415, 399, 385 },
    false,
    621,
    2665782,
    0.59371806248828496,
    0.020916751941671242,
    { { 0, 0, { { 0, 0.0030555015533522672, 0.17348691352031553 } } },
      { 1, 12, { { 0.011801526201092649, 0.0027613695363299549, 0.15779547914188502 } } },
      { 2, 206, { { 0.015604107027562104, 0.0027610943988988293, 0.15778773789298628 } } },
      { 3, 207, { { 0.015910101305023138, 0.002755705889723722, 0.15537225600407795 } } },
      { 617, 5689, { { 0.44069502117445652, 0.00048676097210302132, 0.031221368790843598 } } },
      { 618, 5702, { { 0.44145583602606381, 0.00048666101650976707, 0.031219096336882676 } } },
      { 619, 5703, { { 0.45746983767086208, 0.00046243177942678783, 0.029173320271669918 } } },
      { 620, 5704, { { 0.45760558070501461, 0.00046239670434284968, 0.029181164792009186 } } } }
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
    EXPECT_EQ(history.back().hypervolume, expected.hypervolume) << options.seed;
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
    first.SaveCheckpoint(path);
    first.RunGeneration(); // work after the checkpoint is lost with the "killed" run
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
