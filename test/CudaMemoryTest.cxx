// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The CUDA backend and the device's memory: its estimate grows with the
// population, a batch larger than the device is reported as out of GPU memory
// (morea_core::OutOfDeviceMemory, which RegisterMeshes completes with the run's
// figures), and the backend goes on afterwards. Skips without a device.
#include "OptimiserTestProblem.h"

#include "morea_core/ComputeDevices.h"
#include "morea_core/Error.h"
#include "morea_core/MemoryEstimate.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace
{
using namespace morea_core;
using morea_test::OptimiserTestProblem;

TEST(CudaMemory, EstimateNamesTheDeviceAndGrowsWithThePopulation)
{
  if (const std::string why = CudaUnavailableReason(); !why.empty())
    GTEST_SKIP() << why;
  OptimiserTestProblem problem;
  for (const CudaInterpolation interpolation : { CudaInterpolation::Exact, CudaInterpolation::Texture })
  {
    auto                 cuda = CreateCudaEvaluationBackend(*problem.evaluator, 2, interpolation);
    const RunShape       shape = RunShapeOf(problem.Options(), problem.topology, problem.parallel);
    const MemoryEstimate estimate = cuda->MemoryFor(shape);
    EXPECT_EQ(estimate.device, 0);
    // At least the corners of every tetrahedron of a whole population.
    EXPECT_GT(estimate.devicePerSolution, static_cast<double>(shape.tetrahedra) * 24 * sizeof(double));
    EXPECT_GT(estimate.Device(2 * shape.population), estimate.Device(shape.population));
    ASSERT_TRUE(cuda->FreeDeviceMemory().has_value());
    EXPECT_GT(*cuda->FreeDeviceMemory(), 0.0);
    EXPECT_NO_THROW(CheckRunMemory(shape, *cuda));

    // A whole evaluation fills one of the two flights the estimate counts:
    // what it takes is below the estimate, and not far below.
    constexpr std::size_t          population = 2048;
    const DualMesh                                 solution = DualMesh::FromBase(problem.base);
    std::vector<std::vector<TetrahedronValues>>    values(population);
    std::vector<std::vector<TetrahedronValues> *> outputs;
    for (auto & v : values)
      outputs.push_back(&v);
    const std::size_t before = CudaMemoryInUse();
    cuda->EvaluateSolutions(std::vector<const DualMesh *>(population, &solution), outputs);
    const double taken = static_cast<double>(CudaMemoryInUse() - before);
    const double estimated = estimate.Device(population);
    EXPECT_LT(taken, estimated);
    EXPECT_GT(taken, 0.35 * estimated) << "estimated " << estimated << " bytes, taken " << taken;
  }
}

TEST(CudaMemory, ABatchLargerThanTheDeviceIsOutOfGpuMemory)
{
  if (const std::string why = CudaUnavailableReason(); !why.empty())
    GTEST_SKIP() << why;
  OptimiserTestProblem problem;
  auto                 cuda = CreateCudaEvaluationBackend(*problem.evaluator, 2);
  const DualMesh       solution = DualMesh::FromBase(problem.base);
  std::vector<TetrahedronValues> values;
  // One solution many times over: the corners of its tetrahedra alone
  // (24 doubles each) need more than the device has free.
  const double      free = static_cast<double>(CudaFreeMemory(0));
  const double      cornerBytes = static_cast<double>(problem.topology.NumberOfTetrahedra()) * 24 * sizeof(double);
  const std::size_t copies = static_cast<std::size_t>(free / cornerBytes) + 1;
  const std::vector<const DualMesh *>                 solutions(copies, &solution);
  const std::vector<std::vector<TetrahedronValues> *> outputs(copies, &values);
  try
  {
    cuda->EvaluateSolutions(solutions, outputs);
    ADD_FAILURE() << copies << " solutions fitted in " << free << " free bytes";
  }
  catch (const OutOfDeviceMemory & e)
  {
    EXPECT_EQ(std::string(e.what()).rfind("CUDA backend: out of GPU memory (", 0), 0u) << e.what();
  }
  // The failed allocation leaves the backend usable.
  std::vector<TetrahedronValues> one;
  ASSERT_NO_THROW(cuda->EvaluateSolutions({ &solution }, { &one }));
  EXPECT_EQ(one.size(), problem.topology.NumberOfTetrahedra());
}
} // namespace
