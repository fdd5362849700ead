// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Resuming RegisterMeshes from its checkpoint: allowed with what it was
// written with (also for more generations), refused with other objective or
// preprocessing parameters or other images, naming the first key that differs.
#include "itkMeshRegistration.h"
#include "itkPhantomImages.h"
#include "itkPreprocessing.h"
#include "morea_core/Error.h"
#include "morea_core/FoldConstraint.h"
#include "morea_core/ParallelStructure.h"
#include "morea_core/ParameterSet.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace
{
using namespace itk::morea;

struct SmallRun
{
  RegistrationProblem   problem;
  morea_core::ParameterSet parameters;
  std::string           checkpoint;

  SmallRun()
  {
    morea_core::PhantomOptions phantom;
    phantom.spacing = 4.0;
    PreprocessOptions pre;
    pre.isotropicSpacing = 4.0;
    pre.rigidStructure = "none";
    problem = Preprocess(MakePhantomProblem(morea_core::PelvisPhantom(phantom).Generate()), pre).problem;
    for (const auto & [key, value] : std::vector<std::pair<std::string, std::string>>{
           { "ea_population_size", "8" },
           { "ea_num_clusters", "2" },
           { "ea_archive_size", "20" },
           { "ea_num_generations", "2" },
           { "morea_mesh_num_points", "40" },
           { "morea_sampling_rate", "0.3" },
           { "seed", "4" } })
      parameters.SetFromString(key, value);
    std::filesystem::create_directories(MOREA_TEST_OUTPUT_DIR);
    // One file per test: CTest runs the tests of this file side by side.
    checkpoint = std::string(MOREA_TEST_OUTPUT_DIR) + "/resume_checkpoint_" +
                 ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".bin";
    std::filesystem::remove(checkpoint);
  }
  ~SmallRun()
  {
    std::filesystem::remove(checkpoint);
    std::filesystem::remove(checkpoint + ".level0");
  }

  MeshRegistrationResult
  Run(const morea_core::ParameterSet & p, const RegistrationProblem & on) const
  {
    MeshRegistrationOptions options;
    options.checkpointPath = checkpoint;
    options.checkpointInterval = 1;
    options.resume = true;
    options.backend = morea_core::BackendChoice::Cpu;
    options.threads = 2;
    return RegisterMeshes(on, p, options);
  }
  /** The message of the resume's refusal; "" when it resumed. */
  std::string
  Refusal(const morea_core::ParameterSet & p, const RegistrationProblem & on) const
  {
    try
    {
      Run(p, on);
    }
    catch (const std::exception & e)
    {
      return e.what();
    }
    return {};
  }
};

TEST(CheckpointResume, OtherParametersOrImagesAreRefusedNamingTheKey)
{
  SmallRun run;
  EXPECT_EQ(run.Run(run.parameters, run.problem).resumedAtGeneration, 0u);
  ASSERT_TRUE(std::filesystem::exists(run.checkpoint));
  const std::string prefix = "checkpoint " + run.checkpoint + ": it was written by a run with other inputs or parameters (";

  morea_core::ParameterSet rate = run.parameters;
  rate.SetFromString("morea_sampling_rate", "0.5");
  EXPECT_EQ(run.Refusal(rate, run.problem),
            prefix + "morea_sampling_rate: 0.3 in the checkpoint, 0.5 in this run); resume with those it was written "
                     "with, or start afresh");

  morea_core::ParameterSet factors = run.parameters;
  factors.SetFromString("morea_elasticity_factors", "bones=10, bladder=2");
  EXPECT_EQ(run.Refusal(factors, run.problem),
            prefix + "morea_elasticity_factors: \"bones=10, bladder=0.5\" in the checkpoint, \"bones=10, bladder=2\" "
                     "in this run); resume with those it was written with, or start afresh");

  // Other voxels of the same size: the image's hash differs.
  RegistrationProblem other = run.problem;
  other.movingImage = ImageType::New();
  other.movingImage->CopyInformation(run.problem.movingImage);
  other.movingImage->SetRegions(run.problem.movingImage->GetLargestPossibleRegion());
  other.movingImage->Allocate();
  const auto n = run.problem.movingImage->GetPixelContainer()->Size();
  std::copy_n(run.problem.movingImage->GetBufferPointer(), n, other.movingImage->GetBufferPointer());
  other.movingImage->GetBufferPointer()[n / 2] += 0.25f;
  const std::string image = run.Refusal(run.parameters, other);
  EXPECT_EQ(image.rfind(prefix + "moving image voxels: xxh64:", 0), 0u) << image;

  // A run that ends before the checkpoint's generation.
  morea_core::ParameterSet shorter = run.parameters;
  shorter.SetFromString("ea_num_generations", "1");
  EXPECT_EQ(run.Refusal(shorter, run.problem),
            "checkpoint " + run.checkpoint + ": it holds generation 2, beyond this run's 1 (ea_num_generations)");

  // The same, for longer: resumes.
  morea_core::ParameterSet longer = run.parameters;
  longer.SetFromString("ea_num_generations", "3");
  const auto resumed = run.Run(longer, run.problem);
  EXPECT_EQ(resumed.resumedAtGeneration, 2u);
  EXPECT_EQ(resumed.history.size(), 4u);
}

TEST(CheckpointResume, ADurationWritesNoCheckpointBeforeItHasPassedAndOneAfter)
{
  SmallRun                 run;
  morea_core::ParameterSet p = run.parameters;
  p.SetFromString("ea_num_generations", "5");
  const auto stoppedAfter = [&](double seconds) {
    std::filesystem::remove(run.checkpoint);
    MeshRegistrationOptions options;
    options.checkpointPath = run.checkpoint;
    options.checkpointSeconds = seconds; // and no count of generations
    options.resume = true;
    options.backend = morea_core::BackendChoice::Cpu;
    options.threads = 2;
    options.onGeneration = [](const morea_core::GenerationRecord & record, std::size_t) {
      if (record.generation == 3)
        throw std::runtime_error("stopped");
    };
    EXPECT_THROW(RegisterMeshes(run.problem, p, options), std::runtime_error);
    options.onGeneration = {};
    return RegisterMeshes(run.problem, p, options).resumedAtGeneration;
  };
  EXPECT_EQ(stoppedAfter(3600.0), 0u); // an hour had not passed: nothing to resume from
  EXPECT_EQ(stoppedAfter(1e-9), 3u);   // passed at every generation's end
}

/** Two mesh levels, two generations on the first, on the CPU with 2 threads. */
morea_core::ParameterSet
TwoLevels(const morea_core::ParameterSet & base, const std::string & generations, const std::string & refinement)
{
  morea_core::ParameterSet p = base;
  p.SetFromString("ea_num_generations", generations);
  p.SetFromString("morea_max_num_mesh_levels", "2");
  p.SetFromString("morea_num_generations_per_level", "2");
  p.SetFromString("morea_mesh_refinement_factor", refinement);
  return p;
}

MeshRegistrationOptions
OnTheCpu()
{
  MeshRegistrationOptions options;
  options.backend = morea_core::BackendChoice::Cpu;
  options.threads = 2;
  return options;
}

TEST(CheckpointResume, MultiLevelRunsRefineCarryOverAndResumeAcrossLevels)
{
  SmallRun                      run;
  const morea_core::ParameterSet   p = TwoLevels(run.parameters, "4", "2");
  const MeshRegistrationOptions plain = OnTheCpu();
  const MeshRegistrationResult whole = RegisterMeshes(run.problem, p, plain);
  const auto &                 mesh = whole.model.base;
  const auto midpoints = std::count(mesh.origins.begin(), mesh.origins.end(), morea_core::PointOrigin::Midpoint);
  EXPECT_EQ(2 * (mesh.NumberOfPoints() - static_cast<std::size_t>(midpoints)), mesh.NumberOfPoints());
  ASSERT_EQ(whole.history.size(), 5u); // generations 0 to 4, once each
  for (std::size_t g = 0; g < whole.history.size(); ++g)
    EXPECT_EQ(whole.history[g].generation, g);
  const morea_core::FoldConstraint constraint(whole.model.topology, mesh.points);
  ASSERT_FALSE(whole.front.empty());
  for (const auto & s : whole.front)
  {
    EXPECT_EQ(s.mesh.source.size(), mesh.NumberOfPoints());
    EXPECT_TRUE(constraint.Evaluate(s.mesh).Feasible());
  }

  // Stopped in the second level, then resumed: level 0 from its own file,
  // the refinement again, level 1 from the run's checkpoint; the same front.
  MeshRegistrationOptions options = plain;
  options.checkpointPath = run.checkpoint;
  options.checkpointInterval = 1;
  options.resume = true;
  options.onGeneration = [](const morea_core::GenerationRecord & record, std::size_t total) {
    EXPECT_EQ(total, 4u);
    if (record.generation == 3)
      throw std::runtime_error("stopped");
  };
  EXPECT_THROW(RegisterMeshes(run.problem, p, options), std::runtime_error);
  EXPECT_TRUE(std::filesystem::exists(run.checkpoint + ".level0"));
  EXPECT_TRUE(std::filesystem::exists(run.checkpoint));
  options.onGeneration = {};
  const MeshRegistrationResult resumed = RegisterMeshes(run.problem, p, options);
  EXPECT_EQ(resumed.resumedAtGeneration, 3u);
  EXPECT_EQ(resumed.model.base.points, mesh.points);
  ASSERT_EQ(resumed.front.size(), whole.front.size());
  for (std::size_t i = 0; i < whole.front.size(); ++i)
  {
    EXPECT_EQ(resumed.front[i].fitness.objectives, whole.front[i].fitness.objectives);
    EXPECT_EQ(resumed.front[i].mesh.target, whole.front[i].mesh.target);
  }
}

TEST(CheckpointResume, GroupedFosElementsOnTheRefinedLevel)
{
  SmallRun                run;
  morea_core::ParameterSet p = TwoLevels(run.parameters, "3", "3");
  p.SetFromString("morea_fos_type", "coarse-groups");
  const MeshRegistrationResult result = RegisterMeshes(run.problem, p, OnTheCpu());
  const auto &                 model = result.model;
  // Groups (about the first level's element count): far fewer than the refined
  // mesh's edges; every point in one of them.
  const morea_core::ParallelStructure edges = morea_core::BuildParallelStructure(model.topology);
  EXPECT_LT(model.parallel.elements.size(), edges.elements.size() / 2);
  std::vector<int> coveredBy(model.base.NumberOfPoints(), 0);
  for (const auto & e : model.parallel.elements)
  {
    EXPECT_GE(e.points.size(), 2u);
    for (auto q : e.points)
      ++coveredBy[q];
  }
  EXPECT_EQ(std::count(coveredBy.begin(), coveredBy.end(), 1), static_cast<std::ptrdiff_t>(coveredBy.size()));
  EXPECT_NE(std::find_if(model.report.notes.begin(), model.report.notes.end(),
                         [](const std::string & n) { return n.find("coarse-groups") != std::string::npos; }),
            model.report.notes.end());
  ASSERT_EQ(result.history.size(), 4u);
  const morea_core::FoldConstraint constraint(model.topology, model.base.points);
  ASSERT_FALSE(result.front.empty());
  for (const auto & s : result.front)
    EXPECT_TRUE(constraint.Evaluate(s.mesh).Feasible());
}

TEST(CheckpointResume, AFinishedRunGoesOnForLongerToTheLongerRunsFront)
{
  // A run that ended at its budget, resumed with a larger one, reaches the
  // front the larger budget reaches from the start (what docs/parameters.md
  // tells users who find their run not converged).
  SmallRun                     run;
  const MeshRegistrationResult finished = run.Run(run.parameters, run.problem);
  ASSERT_EQ(finished.history.size(), 3u);
  morea_core::ParameterSet longer = run.parameters;
  longer.SetFromString("ea_num_generations", "4");
  const MeshRegistrationResult extended = run.Run(longer, run.problem);
  EXPECT_EQ(extended.resumedAtGeneration, 2u);
  const MeshRegistrationResult straight = RegisterMeshes(run.problem, longer, OnTheCpu());
  ASSERT_EQ(extended.history.size(), straight.history.size());
  for (std::size_t g = 0; g < straight.history.size(); ++g)
    EXPECT_EQ(extended.history[g].hypervolume, straight.history[g].hypervolume) << "generation " << g;
  ASSERT_FALSE(straight.front.empty());
  ASSERT_EQ(extended.front.size(), straight.front.size());
  for (std::size_t i = 0; i < straight.front.size(); ++i)
  {
    EXPECT_EQ(extended.front[i].fitness.objectives, straight.front[i].fitness.objectives);
    EXPECT_EQ(extended.front[i].mesh.target, straight.front[i].mesh.target);
  }
}
} // namespace
