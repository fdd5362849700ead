// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Preprocessing on the real patient pairs in ../shared/data (skipped when absent).
#include "itkMOREAImageIO.h"
#include "itkMeshModel.h"
#include "itkPreprocessing.h"
#include "itkRegistrationEvaluation.h"
#include "morea_core/FoldConstraint.h"
#include "morea_core/InitialPopulation.h"
#include "morea_core/ParameterSet.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>

using namespace itk::morea;
namespace fs = std::filesystem;

namespace
{
const fs::path kData(MOREA_SHARED_DATA_DIR);
}

TEST(RealData, LungPairRigidPreAlignmentOnLungMasksBringsTreUnderFiveMillimetres)
{
  const fs::path dir = kData / "lung-ct-pair";
  if (!fs::exists(dir / "baseline.mha"))
    GTEST_SKIP() << "lung pair not present at " << dir;
  RegistrationProblem problem;
  problem.LoadImages((dir / "baseline.mha").string(), (dir / "followup.mha").string());
  problem.LoadStructure("lungs", true, (dir / "baseline_lung_mask.mha").string());
  problem.LoadStructure("lungs", false, (dir / "followup_lung_mask.mha").string());
  problem.LoadLandmarks((dir / "baseline_landmarks51_mm.txt").string(), (dir / "followup_landmarks51_mm.txt").string());
  ASSERT_EQ(problem.fixedLandmarks.size(), 51u);

  const auto before = ComputeLandmarkErrors(problem.fixedLandmarks, problem.movingLandmarks);
  PreprocessOptions options;
  options.rigidStructure = "lungs";
  const auto result = Preprocess(problem, options);
  const auto after = EvaluateRegistration(result.problem, nullptr, nullptr, 0.0);
  std::cout << "lung pair TRE: before " << before.mean << " mm, after rigid on lungs " << after.landmarks.mean
            << " mm (sd " << after.landmarks.standardDeviation << ", max " << after.landmarks.maximum << "), "
            << after.landmarks.errors.size() << " landmarks, lung Dice " << after.structures.at(0).dice << "\n";
  EXPECT_GT(before.mean, 30.0);
  EXPECT_EQ(after.landmarksOutside, 0u);
  EXPECT_LT(after.landmarks.mean, 5.0);
  EXPECT_GT(after.structures.at(0).dice, 0.85);

  // The 600-point mesh model with the lung surface as a constraint.
  morea_core::ParameterSet parameters;
  parameters.SetFromString("morea_mesh_surface_structures", "lungs");
  const MeshModel model = BuildMeshModel(result.problem, parameters);
  const auto &    g = model.report.generation;
  for (const auto & note : g.notes)
    EXPECT_EQ(note.find("instead"), std::string::npos) << note;
  EXPECT_EQ(model.base.NumberOfPoints(), 600u + g.steinerPoints);
  EXPECT_GT(g.surfacePoints, 300u);
  EXPECT_FALSE(model.base.constrainedFaces.empty());
  EXPECT_GE(model.report.parallelGroups, 2u);
  const morea_core::FoldConstraint constraint(model.topology, model.base.points);
  for (const auto & s : morea_core::GenerateInitialPopulation(model.base, constraint, 20, 1))
    EXPECT_TRUE(constraint.Evaluate(s).Feasible());
  std::cout << "lung mesh: " << model.base.NumberOfPoints() << " points (" << g.surfacePoints << " on the lung surface, "
            << g.surfaceTriangles << " constraining triangles, " << g.steinerPoints << " Steiner), "
            << model.base.NumberOfTetrahedra() << " tetrahedra (" << g.slivers << " slivers), "
            << model.report.fosElements << " FOS elements, " << model.report.parallelGroups
            << " parallel groups; seconds: contour points " << model.report.secondsContourPoints << ", surface "
            << g.secondsSurfaces << ", placement " << g.secondsPlacement << ", TetGen and sliver removal "
            << g.secondsTetrahedralization << ", parallel structure " << model.report.secondsParallelStructure
            << ", elasticity " << model.report.secondsElasticity << "\n";
}

TEST(RealData, AbdomenPairLoadsFromLabelMapsAndCropsToTheStomach)
{
  const fs::path dir = kData / "abdomen-cbct-pair";
  if (!fs::exists(dir / "CB02.mha"))
    GTEST_SKIP() << "abdomen pair not present at " << dir;
  RegistrationProblem problem;
  problem.LoadImages((dir / "CB02.mha").string(), (dir / "CB07.mha").string());
  for (const char * name : { "Stomach_duo_CBCT", "Bowel_sm_CBCT" })
  {
    problem.LoadStructure(name, true, (dir / "CB02_labels.mha").string() + ":" + name);
    problem.LoadStructure(name, false, (dir / ("CB07_masks/" + std::string(name) + ".mha")).string());
  }
  EXPECT_EQ(LargestDeformingStructure(problem), "Stomach_duo_CBCT");
  PreprocessOptions options;
  options.rigidStructure = "none"; // the provider already aligned the pair
  const auto result = Preprocess(problem, options);
  EXPECT_EQ(result.report.cropStructure, "Stomach_duo_CBCT");
  EXPECT_TRUE(SameGrid(result.problem.fixedImage, result.problem.movingImage));
  const auto scores = EvaluateRegistration(result.problem, nullptr, nullptr, 0.0);
  for (const auto & s : scores.structures)
  {
    std::cout << "abdomen baseline " << s.name << ": Dice " << s.dice << ", HD95 " << s.hausdorff95 << " mm\n";
    EXPECT_GT(s.dice, 0.0);
    EXPECT_LT(s.dice, 0.9); // large deformation: far from matched before registration
  }
}
