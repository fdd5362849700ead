// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The up-front memory estimate: it grows with the population and the mesh,
// a population no machine holds is refused at once naming
// ea_population_size, and the paper's configuration passes.
#include "OptimiserTestProblem.h"

#include "morea_core/Error.h"
#include "morea_core/MemoryEstimate.h"
#include "morea_core/ParameterSet.h"

#include <gtest/gtest.h>

#include <chrono>

namespace
{
using namespace morea_core;

constexpr double GiB = 1024.0 * 1024.0 * 1024.0;

GomeaOptions
PaperOptions()
{
  return GomeaOptions::FromParameters(ParameterSet());
}

double
HostBytes(const RunShape & shape)
{
  return MoRvGomea::MemoryFor(shape).Host(shape.population);
}

std::string
RefusalOf(const ParameterSet & parameters)
{
  try
  {
    CheckRunMemory(parameters);
  }
  catch (const Error & e)
  {
    return e.what();
  }
  return {};
}

TEST(MemoryEstimate, GrowsWithPopulationAndMesh)
{
  GomeaOptions         options = PaperOptions();
  const MemoryEstimate paper = MoRvGomea::MemoryFor(RunShapeAtLeast(options, 600));
  const MemoryEstimate finer = MoRvGomea::MemoryFor(RunShapeAtLeast(options, 1200));
  EXPECT_GT(finer.hostPerSolution, 1.9 * paper.hostPerSolution);
  EXPECT_GT(finer.hostFixed, 1.9 * paper.hostFixed); // the archive's solutions
  // A solution costs at least its two meshes' points.
  EXPECT_GT(paper.hostPerSolution, 600.0 * 2 * sizeof(Vec3));
  EXPECT_GT(paper.Host(1400), paper.Host(700));

  // The real mesh (its tetrahedra, elements and groups) needs more than the
  // least any mesh of its points needs, and checkpoints add their buffers.
  morea_test::OptimiserTestProblem problem;
  options = problem.Options();
  const RunShape real = RunShapeOf(options, problem.topology, problem.parallel);
  EXPECT_EQ(real.points, problem.topology.NumberOfPoints());
  EXPECT_EQ(real.tetrahedra, problem.topology.NumberOfTetrahedra());
  EXPECT_EQ(real.elements, problem.parallel.elements.size());
  EXPECT_GT(real.groupElements, 0u);
  EXPECT_GT(HostBytes(real), HostBytes(RunShapeAtLeast(options, real.points)));
  RunShape withCheckpoints = real;
  withCheckpoints.checkpoints = true;
  EXPECT_GT(HostBytes(withCheckpoints), HostBytes(real));
}

TEST(MemoryEstimate, AbsurdPopulationIsRefusedAtOnce)
{
  ParameterSet parameters;
  parameters.SetFromString("ea_population_size", "10000000");
  const auto        start = std::chrono::steady_clock::now();
  const std::string refusal = RefusalOf(parameters);
  const double      seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 0.5);
  EXPECT_NE(refusal.find("not enough memory"), std::string::npos) << refusal;
  EXPECT_NE(refusal.find("a population of 10000000 (ea_population_size)"), std::string::npos) << refusal;
  EXPECT_NE(refusal.find("lower ea_population_size"), std::string::npos) << refusal;
  EXPECT_NE(refusal.find("GiB of host memory"), std::string::npos) << refusal;
}

TEST(MemoryEstimate, PaperConfigurationPasses)
{
  // 700 solutions, an archive of 2000, 600 points: a few hundred MB.
  EXPECT_EQ(RefusalOf(ParameterSet()), "");
  const double bytes = HostBytes(RunShapeAtLeast(PaperOptions(), 600));
  EXPECT_GT(bytes, 50e6);
  EXPECT_LT(bytes, 1.0 * GiB);
}

TEST(MemoryEstimate, ShortfallNamesTheFiguresAndWhatFits)
{
  const RunShape shape = RunShapeAtLeast(PaperOptions(), 600); // 700 solutions
  MemoryEstimate estimate;
  estimate.hostFixed = 1.0 * GiB;
  estimate.hostPerSolution = GiB / 128; // 6.47 GiB in all
  AvailableMemory available;
  available.host = 10.0 * GiB;
  EXPECT_EQ(MemoryShortfall(shape, estimate, available), "");
  available.host = 4.0 * GiB;
  EXPECT_EQ(MemoryShortfall(shape, estimate, available),
            "not enough memory: the optimisation needs about 6.47 GiB of host memory for a population of 700 "
            "(ea_population_size) and an archive of 2000 (ea_archive_size) on a mesh of 600 points and 597 "
            "tetrahedra, and 4.00 GiB are available; lower ea_population_size (about 384 fit), ea_archive_size or "
            "morea_mesh_num_points, or free memory");
  // Before the mesh: a lower bound of the need, so an upper bound of what fits.
  const std::string atLeast = MemoryShortfall(shape, estimate, available, true);
  EXPECT_NE(atLeast.find("needs at least about 6.47 GiB"), std::string::npos) << atLeast;
  EXPECT_NE(atLeast.find("on a mesh of 600 points (morea_mesh_num_points)"), std::string::npos) << atLeast;
  EXPECT_NE(atLeast.find("lower ea_population_size (at most about 384 fit)"), std::string::npos) << atLeast;

  // The device's part only where the estimate has a device.
  available.host = 10.0 * GiB;
  estimate.devicePerSolution = GiB / 16; // 43.75 GiB
  available.device = 40.0 * GiB;
  EXPECT_EQ(MemoryShortfall(shape, estimate, available), "");
  estimate.device = 0;
  const std::string device = MemoryShortfall(shape, estimate, available);
  EXPECT_NE(device.find("not enough GPU memory: the optimisation needs about 44 GiB on CUDA device 0"),
            std::string::npos)
    << device;
  EXPECT_NE(device.find("40 GiB are free; lower ea_population_size (about 640 fit)"), std::string::npos) << device;
  EXPECT_NE(device.find("run on the cpu backend"), std::string::npos) << device;
}

TEST(MemoryEstimate, MoreClustersThanSolutionsAreRefusedBeforeTheMesh)
{
  ParameterSet parameters;
  parameters.SetFromString("ea_population_size", "8");
  parameters.SetFromString("ea_num_clusters", "9");
  EXPECT_NE(RefusalOf(parameters).find("ea_num_clusters = 9 is more than the population"), std::string::npos);
}
} // namespace
