// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Problems that would register something else than what was asked for are
// refused before the work: one side of a structure given twice (the second
// would replace the first), and a guidance structure that preprocessing
// drops because it lies outside the crop.
#include "itkMOREAImageIO.h"
#include "itkPreprocessing.h"
#include "itkRegistrationProblem.h"
#include "morea_core/ParameterSet.h"

#include "ItkErrorSupport.h"
#include "TestScratchDir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using namespace itk::morea;

namespace
{
using morea_test::ItkError;

/** A 30^3 grid of 1 mm with a box of voxels [from, to) set. */
template <typename TImage>
typename TImage::Pointer
Grid(int from = 0, int to = 0, typename TImage::PixelType on = 1)
{
  auto image = TImage::New();
  image->SetRegions(typename TImage::SizeType{ { 30, 30, 30 } });
  image->Allocate();
  image->FillBuffer(0);
  for (int k = from; k < to; ++k)
    for (int j = from; j < to; ++j)
      for (int i = from; i < to; ++i)
        image->SetPixel({ { i, j, k } }, on);
  return image;
}

TEST(ProblemValidation, OneSideOfAStructureGivenTwiceIsRefused)
{
  const auto dir = morea_test::TestScratchDir("ProblemValidation");
  WriteImage(Grid<ImageType>(5, 25, 100.0f), (dir / "image.mha").string());
  WriteMask(Grid<MaskType>(10, 20), (dir / "a.mha").string());
  WriteMask(Grid<MaskType>(11, 19), (dir / "b.mha").string());
  std::ofstream(dir / "points.csv") << "x,y,z\n12,12,12\n15,15,15\n";
  const std::string image = (dir / "image.mha").string(), a = (dir / "a.mha").string(),
                    b = (dir / "b.mha").string(), points = (dir / "points.csv").string();

  RegistrationProblem problem;
  problem.LoadImages(image, image);
  const std::string message = ItkError([&] {
    problem.LoadStructures({ { "bladder", true, a }, { "bladder", false, a }, { "bladder", true, b } });
  });
  EXPECT_EQ(message, "ITK ERROR: structure 'bladder' is given twice on the fixed image: '" + a + "' and '" + b +
                       "' both give its mask; give each structure once per image (a mask, and points from a point "
                       "file if wanted), or rename one");
  EXPECT_TRUE(problem.structures.empty()) << "refused before anything was read";

  // A mask and a point file add up; the moving side is another side.
  RegistrationProblem both;
  both.LoadImages(image, image);
  EXPECT_NO_THROW(both.LoadStructures(
    { { "bladder", true, a }, { "bladder", true, points }, { "bladder", false, b }, { "rectum", true, b } }));
  // Twice across calls, and two point files.
  EXPECT_CONTAINS(ItkError([&] { both.LoadStructure("bladder", false, a); }),
                  "structure 'bladder' is given twice on the moving image: one loaded before and '" + a + "'");
  EXPECT_CONTAINS(ItkError([&] { both.LoadStructure("bladder", true, points); }), "both give its points");
}

TEST(ProblemValidation, AGuidanceStructureThatVanishesInPreprocessingIsRefused)
{
  RegistrationProblem problem;
  problem.fixedImage = Grid<ImageType>(2, 28, 200.0f);
  problem.movingImage = Grid<ImageType>(2, 28, 200.0f);
  Structure organ{ "organ", Grid<MaskType>(12, 18), Grid<MaskType>(11, 19), {}, {} };
  Structure corner{ "corner", Grid<MaskType>(0, 3), Grid<MaskType>(0, 3), {}, {} };
  problem.structures = { organ, corner };
  PreprocessOptions options;
  options.isotropicSpacing = 1.0;
  options.rigidStructure = "none";
  options.cropStructure = "organ";
  options.cropMargin = 2.0;
  const auto result = Preprocess(problem, options);
  ASSERT_EQ(result.report.droppedStructures, std::vector<std::string>{ "corner" });
  ASSERT_EQ(result.report.droppedReasons.size(), 1u);
  EXPECT_EQ(result.report.droppedReasons[0],
            "its fixed and moving masks have no voxel inside the crop to 'organ' with a margin of 2 mm");

  morea_core::ParameterSet parameters; // problem_guidance_selection = -1: every structure guides
  EXPECT_EQ(ItkError([&] { CheckGuidanceStructuresKept(result.report, parameters); }),
            "ITK ERROR: structure 'corner' vanished in preprocessing: its fixed and moving masks have no voxel inside the crop to "
            "'organ' with a margin of 2 mm, so the registration would run without it; crop to a region that holds it "
            "(preprocess_crop_structure, preprocess_crop_margin), or leave it out (or name the structures to register "
            "in problem_guidance_selection)");
  parameters.SetFromString("problem_guidance_selection", "organ");
  EXPECT_NO_THROW(CheckGuidanceStructuresKept(result.report, parameters));
  parameters.SetFromString("problem_guidance_selection", "organ, corner");
  EXPECT_CONTAINS(ItkError([&] { CheckGuidanceStructuresKept(result.report, parameters); }),
                  "or leave it out of problem_guidance_selection");
}
} // namespace
