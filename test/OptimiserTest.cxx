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
