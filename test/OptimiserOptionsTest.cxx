// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Optimiser options that cannot work as asked are reported, not quietly
// changed: more clusters than solutions.
#include "OptimiserTestProblem.h"

#include "morea_core/Error.h"

#include <gtest/gtest.h>

namespace
{
using namespace morea_core;

TEST(OptimiserOptions, MoreClustersThanSolutionsAreRefused)
{
  morea_test::OptimiserTestProblem problem;
  auto                             backend = CreateCpuEvaluationBackend(*problem.evaluator, 1);
  GomeaOptions                     options = problem.Options();
  options.populationSize = 8;
  options.numberOfClusters = 9;
  try
  {
    MoRvGomea(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options);
    ADD_FAILURE() << "9 clusters of 8 solutions were accepted";
  }
  catch (const Error & e)
  {
    EXPECT_EQ(std::string(e.what()),
              "optimiser: ea_num_clusters = 9 is more than the population (ea_population_size = 8); every cluster "
              "needs solutions of its own: use at most 8 clusters, or a larger population (the paper: 10 clusters of "
              "700 solutions)");
  }
  options.numberOfClusters = 8; // as many as solutions: allowed
  EXPECT_NO_THROW(MoRvGomea(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend, options));
}
} // namespace
