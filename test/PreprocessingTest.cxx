// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Preprocessing steps (SPEC 4.1-4.2) on shapes with known answers and on the phantom.
#include "itkImageRegionConstIterator.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkMOREAImageIO.h"
#include "itkMinimumMaximumImageCalculator.h"
#include "itkPhantomImages.h"
#include "itkPreprocessing.h"
#include "itkRegistrationMetrics.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>

using namespace itk::morea;

namespace
{
template <typename TImage>
typename TImage::Pointer
MakeGrid(std::array<unsigned, 3> size, std::array<double, 3> spacing, std::array<double, 3> origin = { 0, 0, 0 })
{
  auto                      image = TImage::New();
  typename TImage::SizeType s;
  typename TImage::SpacingType sp;
  typename TImage::PointType   o;
  for (unsigned d = 0; d < 3; ++d)
  {
    s[d] = size[d];
    sp[d] = spacing[d];
    o[d] = origin[d];
  }
  image->SetRegions(typename TImage::RegionType(s));
  image->SetSpacing(sp);
  image->SetOrigin(o);
  image->Allocate();
  image->FillBuffer(0);
  return image;
}

/** A sphere of `radius` mm centred at `c`, sampled at voxel centres. */
MaskType::Pointer
Sphere(MaskType::Pointer mask, const PointType & c, double radius)
{
  for (itk::ImageRegionIteratorWithIndex<MaskType> it(mask, mask->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    PointType p;
    mask->TransformIndexToPhysicalPoint(it.GetIndex(), p);
    it.Set(p.EuclideanDistanceTo(c) <= radius ? 1 : 0);
  }
  return mask;
}

std::size_t
Count(const MaskType * m)
{
  std::size_t n = 0;
  for (itk::ImageRegionConstIterator<MaskType> it(m, m->GetBufferedRegion()); !it.IsAtEnd(); ++it)
    n += it.Get() != 0;
  return n;
}
} // namespace

TEST(Preprocessing, ResampleIsotropicReproducesALinearRampAndKeepsTheExtent)
{
  auto image = MakeGrid<ImageType>({ 20, 20, 8 }, { 1.0, 1.0, 4.0 }, { 10, -5, 100 });
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    PointType p;
    image->TransformIndexToPhysicalPoint(it.GetIndex(), p);
    it.Set(static_cast<float>(2.0 * p[0] - p[1] + 0.5 * p[2]));
  }
  auto out = ResampleIsotropic(image, 2.0);
  EXPECT_EQ(out->GetLargestPossibleRegion().GetSize()[0], 10u);
  EXPECT_EQ(out->GetLargestPossibleRegion().GetSize()[2], 16u);
  for (unsigned d = 0; d < 3; ++d)
    EXPECT_DOUBLE_EQ(out->GetSpacing()[d], 2.0);
  // The outer edge of the first voxel stays put: 10 - 0.5 = 9.5 -> first centre at 10.5.
  EXPECT_NEAR(out->GetOrigin()[0], 10.5, 1e-9);
  EXPECT_NEAR(out->GetOrigin()[2], 100.0 - 2.0 + 1.0, 1e-9);
  // Inside the original sample hull a linear ramp is reproduced exactly by linear interpolation.
  ImageType::IndexType idx{ { 4, 5, 6 } };
  PointType            p;
  out->TransformIndexToPhysicalPoint(idx, p);
  EXPECT_NEAR(out->GetPixel(idx), 2.0 * p[0] - p[1] + 0.5 * p[2], 1e-3);
}

TEST(Preprocessing, ResampleMaskFillsTheGapsBetweenThickSlices)
{
  // A sphere drawn on 5 mm slices, resampled to 1 mm: the result must be a smooth
  // sphere, not a stack of discs with empty slices between them.
  PointType c;
  c[0] = 20;
  c[1] = 20;
  c[2] = 20;
  auto thick = Sphere(MakeGrid<MaskType>({ 40, 40, 9 }, { 1.0, 1.0, 5.0 }), c, 12.0);
  auto fineGrid = MakeGrid<MaskType>({ 40, 40, 41 }, { 1.0, 1.0, 1.0 });
  auto truth = Sphere(MakeGrid<MaskType>({ 40, 40, 41 }, { 1.0, 1.0, 1.0 }), c, 12.0);
  auto resampled = ResampleMask(thick, fineGrid);
  EXPECT_GT(ComputeDice(resampled, truth), 0.93);
  // Every slice through the sphere's middle 20 mm is filled.
  for (int z = 11; z <= 29; ++z)
  {
    MaskType::IndexType idx{ { 20, 20, z } };
    EXPECT_EQ(resampled->GetPixel(idx), 1) << "slice z=" << z;
  }
  // Nearest-neighbour would make a staircase; the level-set resampling is much closer to the sphere.
  const double expected = 4.0 / 3.0 * M_PI * 12 * 12 * 12;
  EXPECT_NEAR(static_cast<double>(Count(resampled)), expected, 0.08 * expected);
}

TEST(Preprocessing, IntensityWindowMapsToUnitRangeWithExactBackground)
{
  auto image = MakeGrid<ImageType>({ 4, 1, 1 }, { 1, 1, 1 });
  auto fg = MakeGrid<MaskType>({ 4, 1, 1 }, { 1, 1, 1 });
  const float values[4] = { -2000.0f, -1000.0f, 0.0f, 3000.0f };
  for (int i = 0; i < 4; ++i)
  {
    image->SetPixel({ { i, 0, 0 } }, values[i]);
    fg->SetPixel({ { i, 0, 0 } }, 1);
  }
  fg->SetPixel({ { 2, 0, 0 } }, 0); // background inside the window
  auto out = ApplyIntensityWindow(image, fg, -1000.0f, 1000.0f);
  EXPECT_FLOAT_EQ(out->GetPixel({ { 0, 0, 0 } }), ForegroundFloor); // clamped low, still foreground
  EXPECT_FLOAT_EQ(out->GetPixel({ { 1, 0, 0 } }), ForegroundFloor);
  EXPECT_FLOAT_EQ(out->GetPixel({ { 2, 0, 0 } }), 0.0f);
  EXPECT_FLOAT_EQ(out->GetPixel({ { 3, 0, 0 } }), 1.0f);
  EXPECT_THROW(ApplyIntensityWindow(image, fg, 10.0f, 10.0f), itk::ExceptionObject);
}

TEST(Preprocessing, SurfacePointsOfACubeAreItsOuterShell)
{
  auto mask = MakeGrid<MaskType>({ 8, 8, 8 }, { 1.5, 1.5, 1.5 });
  for (int k = 2; k < 6; ++k)
    for (int j = 2; j < 6; ++j)
      for (int i = 2; i < 6; ++i)
        mask->SetPixel({ { i, j, k } }, 1);
  const auto points = ExtractSurfacePoints(mask);
  EXPECT_EQ(points.size(), 64u - 8u);
  for (const auto & p : points)
    for (unsigned d = 0; d < 3; ++d)
    {
      EXPECT_GE(p[d], 2 * 1.5 - 1e-9);
      EXPECT_LE(p[d], 5 * 1.5 + 1e-9);
    }
}

TEST(Preprocessing, PhantomIsAlignedCroppedAndWindowed)
{
  morea_core::PhantomOptions options;
  options.spacing = 2.0;
  const morea_core::PelvisPhantom phantom(options);
  const auto                   problem = MakePhantomProblem(phantom.Generate());
  EXPECT_EQ(LargestDeformingStructure(problem), "bladder");

  PreprocessOptions pre;
  pre.isotropicSpacing = 3.0;
  const auto result = Preprocess(problem, pre);
  const auto & out = result.problem;
  EXPECT_EQ(result.report.cropStructure, "bladder");
  EXPECT_EQ(result.report.rigidStructure, "bones");
  EXPECT_TRUE(itk::morea::SameGrid(out.fixedImage, out.movingImage));

  // The rigid part of the phantom's motion is recovered: bone landmarks map onto
  // their partners (indices 0-8 are on bones, which the deformation hardly moves).
  for (std::size_t i = 0; i < 9; ++i)
  {
    const auto mapped = result.rigidTransform->TransformPoint(problem.fixedLandmarks[i]);
    EXPECT_LT(mapped.EuclideanDistanceTo(problem.movingLandmarks[i]), 1.5) << "landmark " << i;
    std::cout << "bone landmark " << i << " error after rigid: " << mapped.EuclideanDistanceTo(problem.movingLandmarks[i]) << " mm\n";
  }

  // The crop holds the bladder of both images plus the margin (less a voxel of
  // rounding) where the image domain allows it (x and y here; z meets the domain edge).
  const auto & bladder = out.GetStructure("bladder");
  const auto   region = out.fixedImage->GetLargestPossibleRegion();
  PointType    gridLo, gridHi;
  out.fixedImage->TransformIndexToPhysicalPoint(region.GetIndex(), gridLo);
  out.fixedImage->TransformIndexToPhysicalPoint(region.GetUpperIndex(), gridHi);
  for (const MaskType * m : { bladder.fixedMask.GetPointer(), bladder.movingMask.GetPointer() })
  {
    PointType lo, hi;
    MaskBoundingBox(m, lo, hi);
    for (unsigned d = 0; d < 2; ++d)
    {
      EXPECT_GE(lo[d] - gridLo[d], pre.cropMargin - 4.5) << "axis " << d;
      EXPECT_GE(gridHi[d] - hi[d], pre.cropMargin - 4.5) << "axis " << d;
    }
  }
  // The full bladder is several times the small one.
  EXPECT_GT(static_cast<double>(Count(bladder.movingMask)), 4.0 * static_cast<double>(Count(bladder.fixedMask)));
  EXPECT_FALSE(bladder.fixedPoints.empty());
  EXPECT_FALSE(bladder.movingPoints.empty());

  // Background (outside the body) is exactly 0, foreground at least the floor, all within [0,1].
  std::size_t background = 0;
  itk::ImageRegionConstIterator<ImageType> v(out.fixedImage, region);
  itk::ImageRegionConstIterator<MaskType>  f(out.fixedBodyMask, region);
  for (; !v.IsAtEnd(); ++v, ++f)
  {
    ASSERT_GE(v.Get(), 0.0f);
    ASSERT_LE(v.Get(), 1.0f);
    if (f.Get() == 0)
    {
      ASSERT_EQ(v.Get(), 0.0f);
      ++background;
    }
    else
    {
      ASSERT_GE(v.Get(), ForegroundFloor);
    }
  }
  EXPECT_GT(background, 0u);
}

namespace
{
/** The same physical image stored with its x axis reversed and its y and z
 *  axes swapped (direction a signed permutation). */
template <typename TImage>
typename TImage::Pointer
StoredOtherwise(const TImage * image)
{
  const auto size = image->GetLargestPossibleRegion().GetSize();
  // Output axis 0 runs along -x, axis 1 along z, axis 2 along y.
  typename TImage::IndexType last{ { static_cast<itk::IndexValueType>(size[0]) - 1, 0, 0 } };
  typename TImage::PointType origin;
  image->TransformIndexToPhysicalPoint(last, origin);
  typename TImage::DirectionType direction;
  direction.Fill(0.0);
  direction(0, 0) = -1.0;
  direction(2, 1) = 1.0;
  direction(1, 2) = 1.0;
  auto out = TImage::New();
  out->SetRegions(typename TImage::SizeType{ { size[0], size[2], size[1] } });
  out->SetSpacing(typename TImage::SpacingType(
    std::array<double, 3>{ { image->GetSpacing()[0], image->GetSpacing()[2], image->GetSpacing()[1] } }.data()));
  out->SetOrigin(origin);
  out->SetDirection(direction);
  out->Allocate();
  itk::ImageRegionIteratorWithIndex<TImage> it(out, out->GetLargestPossibleRegion());
  for (; !it.IsAtEnd(); ++it)
  {
    const auto & o = it.GetIndex();
    it.Set(image->GetPixel({ { static_cast<itk::IndexValueType>(size[0]) - 1 - o[0], o[2], o[1] } }));
  }
  return out;
}
} // namespace

TEST(Preprocessing, HowTheAxesAreStoredDoesNotChangeTheResult)
{
  morea_core::PhantomOptions options;
  options.spacing = 4.0;
  const auto problem = MakePhantomProblem(morea_core::PelvisPhantom(options).Generate());
  auto       other = problem;
  other.fixedImage = StoredOtherwise(problem.fixedImage.GetPointer());
  other.movingImage = StoredOtherwise(problem.movingImage.GetPointer());
  for (auto & s : other.structures)
  {
    s.fixedMask = StoredOtherwise(s.fixedMask.GetPointer());
    s.movingMask = StoredOtherwise(s.movingMask.GetPointer());
  }
  PreprocessOptions pre;
  pre.isotropicSpacing = 4.0;
  const auto a = Preprocess(problem, pre);
  const auto b = Preprocess(other, pre);
  ASSERT_EQ(a.report.size, b.report.size);
  EXPECT_EQ(a.report.origin, b.report.origin);
  for (unsigned r = 0; r < 3; ++r)
  {
    EXPECT_NEAR(a.rigidTransform->GetOffset()[r], b.rigidTransform->GetOffset()[r], 1e-9);
    for (unsigned c = 0; c < 3; ++c)
      EXPECT_NEAR(a.rigidTransform->GetMatrix()(r, c), b.rigidTransform->GetMatrix()(r, c), 1e-9);
  }
  itk::ImageRegionConstIterator<ImageType> u(a.problem.movingImage, a.problem.movingImage->GetBufferedRegion());
  itk::ImageRegionConstIterator<ImageType> v(b.problem.movingImage, b.problem.movingImage->GetBufferedRegion());
  for (; !u.IsAtEnd(); ++u, ++v)
    ASSERT_NEAR(u.Get(), v.Get(), 1e-5);
}

TEST(Preprocessing, UnknownStructuresAndBadOptionsAreErrors)
{
  morea_core::PhantomOptions options;
  options.spacing = 5.0;
  const auto problem = MakePhantomProblem(morea_core::PelvisPhantom(options).Generate());
  PreprocessOptions pre;
  // Errors name the parameter key that named the structure.
  const auto messageOf = [&](const PreprocessOptions & o) {
    try
    {
      Preprocess(problem, o);
    }
    catch (const itk::ExceptionObject & e)
    {
      return std::string(e.GetDescription());
    }
    return std::string();
  };
  pre.rigidStructure = "femur";
  EXPECT_NE(messageOf(pre).find("preprocess_rigid_structure = 'femur'"), std::string::npos) << messageOf(pre);
  pre.rigidStructure = "none";
  pre.cropStructure = "kidney";
  EXPECT_NE(messageOf(pre).find("preprocess_crop_structure = 'kidney'"), std::string::npos) << messageOf(pre);
  pre.cropStructure = "";
  pre.windowMin = 100.0f;
  pre.windowMax = -100.0f;
  EXPECT_THROW(Preprocess(problem, pre), itk::ExceptionObject);
}

TEST(Preprocessing, ImagesWindowedAlreadyAreRefusedUnderAHounsfieldWindow)
{
  morea_core::PhantomOptions options;
  options.spacing = 5.0;
  const auto problem = MakePhantomProblem(morea_core::PelvisPhantom(options).Generate());
  PreprocessOptions pre;
  pre.isotropicSpacing = 5.0;
  const auto once = Preprocess(problem, pre).problem; // values in [0, 1] now
  try
  {
    Preprocess(once, pre);
    FAIL() << "a problem preprocessed already was windowed again";
  }
  catch (const itk::ExceptionObject & e)
  {
    const std::string message = e.GetDescription();
    EXPECT_NE(message.find("values lie in [0, 1]"), std::string::npos) << message;
    EXPECT_NE(message.find("preprocess_intensity_max = 1"), std::string::npos) << message;
  }
  // Normalised images under their own window are fine, and keep their contrast.
  pre.windowMin = 0.0f;
  pre.windowMax = 1.0f;
  const auto twice = Preprocess(once, pre).problem;
  auto range = itk::MinimumMaximumImageCalculator<ImageType>::New();
  range->SetImage(twice.fixedImage);
  range->Compute();
  EXPECT_GT(range->GetMaximum() - range->GetMinimum(), 0.5f);
}

TEST(Preprocessing, AnAbsurdSpacingIsRefusedWithTheFigures)
{
  morea_core::PhantomOptions options;
  options.spacing = 5.0;
  auto problem = MakePhantomProblem(morea_core::PelvisPhantom(options).Generate());
  // A header in metres read as millimetres, a thousandfold: the grid would be astronomically large.
  auto huge = problem.fixedImage->GetSpacing();
  huge.Fill(5000.0);
  problem.fixedImage->SetSpacing(huge);
  PreprocessOptions pre;
  pre.rigidStructure = "none";
  pre.cropStructure = "bladder";
  for (auto & s : problem.structures)
    if (s.fixedMask)
      s.fixedMask->SetSpacing(huge);
  try
  {
    Preprocess(problem, pre);
    FAIL() << "an absurd spacing was accepted";
  }
  catch (const itk::ExceptionObject & e)
  {
    const std::string what = e.GetDescription();
    EXPECT_NE(what.find("the preprocessed grid would hold"), std::string::npos) << what;
    EXPECT_NE(what.find("fixed 5000 x 5000 x 5000 mm"), std::string::npos) << what;
  }
}

TEST(Preprocessing, MaskBoundingBoxOfVoxelsAtRowEndsInARegionNotAtTheOrigin)
{
  // A buffer whose region starts at (3, -2, 5), 1 mm voxels at the origin 0:
  // the box must hold the index offset, and voxels at the first and the last
  // place of their rows.
  auto                      mask = MaskType::New();
  const MaskType::IndexType start{ { 3, -2, 5 } };
  const MaskType::SizeType  size{ { 7, 6, 4 } };
  mask->SetRegions(MaskType::RegionType(start, size));
  mask->Allocate(true);
  PointType lower, upper;
  EXPECT_THROW(MaskBoundingBox(mask, lower, upper), itk::ExceptionObject); // empty
  mask->SetPixel({ { 3, 1, 6 } }, 1); // first and last of one row
  mask->SetPixel({ { 9, 1, 6 } }, 1);
  mask->SetPixel({ { 5, -2, 8 } }, 1); // first row, last slice
  MaskBoundingBox(mask, lower, upper);
  const double expectedLower[3] = { 3 - 0.5, -2 - 0.5, 6 - 0.5 };
  const double expectedUpper[3] = { 9 + 0.5, 1 + 0.5, 8 + 0.5 };
  for (unsigned d = 0; d < 3; ++d)
  {
    EXPECT_DOUBLE_EQ(lower[d], expectedLower[d]) << d;
    EXPECT_DOUBLE_EQ(upper[d], expectedUpper[d]) << d;
  }
  // One voxel alone gives its own box, wherever it lies in its row.
  mask->FillBuffer(0);
  mask->SetPixel({ { 6, 3, 7 } }, 255);
  MaskBoundingBox(mask, lower, upper);
  for (unsigned d = 0; d < 3; ++d)
  {
    const double centre = d == 0 ? 6 : d == 1 ? 3 : 7;
    EXPECT_DOUBLE_EQ(lower[d], centre - 0.5) << d;
    EXPECT_DOUBLE_EQ(upper[d], centre + 0.5) << d;
  }
}
