// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The objective data (SPEC 5) of a synthetic problem: intensity and distance
// channels, guidance weights and the ITK-to-frame conversion.
#include "itkImageRegionIteratorWithIndex.h"
#include "itkMOREAImageIO.h"
#include "itkObjectiveData.h"
#include "itkPreprocessing.h"
#include "morea_core/ParameterSet.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace itk::morea;
using morea_core::Vec3;

namespace
{
constexpr unsigned N = 40;
constexpr double   Spacing = 1.5;
constexpr double   Radius = 8.0;

template <typename TImage>
typename TImage::Pointer
MakeGrid(const DomainFrame & frame = DomainFrame(), const Vec3 & frameOrigin = { { -30.25, 12.5, 100.75 } })
{
  auto                         image = TImage::New();
  typename TImage::SizeType    size;
  typename TImage::SpacingType spacing;
  size.Fill(N);
  spacing.Fill(Spacing);
  image->SetRegions(typename TImage::RegionType(size));
  image->SetSpacing(spacing);
  image->SetOrigin(frame.ToPhysical(frameOrigin));
  image->SetDirection(frame.GetDirection());
  image->Allocate(true);
  return image;
}

PointType
Centre(const itk::ImageBase<3> * grid, long i, long j, long k)
{
  itk::Index<3> index{ { i, j, k } };
  PointType     p;
  grid->TransformIndexToPhysicalPoint(index, p);
  return p;
}

MaskType::Pointer
Sphere(const DomainFrame & frame, const PointType & c, double radius)
{
  auto mask = MakeGrid<MaskType>(frame);
  for (itk::ImageRegionIteratorWithIndex<MaskType> it(mask, mask->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    PointType p;
    mask->TransformIndexToPhysicalPoint(it.GetIndex(), p);
    it.Set(p.EuclideanDistanceTo(c) <= radius ? 1 : 0);
  }
  return mask;
}

/** `n` points spread evenly over a sphere (Fibonacci lattice). */
PointListType
SpherePoints(const PointType & c, double radius, std::size_t n)
{
  PointListType points;
  const double  golden = std::acos(-1.0) * (3.0 - std::sqrt(5.0));
  for (std::size_t i = 0; i < n; ++i)
  {
    const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / static_cast<double>(n);
    const double r = std::sqrt(1.0 - z * z);
    const double a = golden * static_cast<double>(i);
    PointType    p;
    p[0] = c[0] + radius * r * std::cos(a);
    p[1] = c[1] + radius * r * std::sin(a);
    p[2] = c[2] + radius * z;
    points.push_back(p);
  }
  return points;
}

/** A smooth intensity pattern in [ForegroundFloor, 1] with exact-0 background on one face. */
ImageType::Pointer
Pattern(const DomainFrame & frame, double phase)
{
  auto image = MakeGrid<ImageType>(frame);
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    const auto i = it.GetIndex();
    const double v = 0.5 + 0.45 * std::sin(0.3 * i[0] + 0.2 * i[1] - 0.1 * i[2] + phase);
    it.Set(i[0] == 0 ? 0.0f : static_cast<float>(v));
  }
  return image;
}

/** Liver: spheres (masks) on both sides, the moving one shifted; body: a box
 *  (not guidance by default); bladder: contour points only. */
RegistrationProblem
MakeProblem(const DomainFrame & frame = DomainFrame())
{
  RegistrationProblem problem;
  problem.fixedImage = Pattern(frame, 0.0);
  problem.movingImage = Pattern(frame, 0.7);
  const auto * g = problem.fixedImage.GetPointer();

  Structure liver;
  liver.name = "liver";
  liver.fixedMask = Sphere(frame, Centre(g, 20, 20, 20), Radius);
  liver.movingMask = Sphere(frame, Centre(g, 22, 19, 20), Radius);
  problem.structures.push_back(liver);

  Structure body;
  body.name = "body";
  body.fixedMask = Sphere(frame, Centre(g, 20, 20, 20), 25.0);
  body.movingMask = Sphere(frame, Centre(g, 20, 20, 20), 25.0);
  problem.structures.push_back(body);

  Structure bladder;
  bladder.name = "bladder";
  bladder.fixedPoints = SpherePoints(Centre(g, 8, 30, 10), 5.0, 300);
  bladder.movingPoints = SpherePoints(Centre(g, 9, 30, 10), 5.0, 500);
  problem.structures.push_back(bladder);
  return problem;
}

MeshModel
ModelOn(const ImageType * grid)
{
  MeshModel model;
  model.frame = DomainFrame::Of(grid);
  return model;
}

std::size_t
Offset(long i, long j, long k)
{
  return static_cast<std::size_t>(i + N * (j + N * k));
}

/** Max over all voxels of |channel - analytic distance to the sphere (c, r)|. */
double
MaxSphereError(const morea_core::ChannelVolume & volume, std::size_t channel, const itk::ImageBase<3> * grid,
               const PointType & c, double r)
{
  double worst = 0.0;
  for (long k = 0; k < static_cast<long>(N); ++k)
    for (long j = 0; j < static_cast<long>(N); ++j)
      for (long i = 0; i < static_cast<long>(N); ++i)
      {
        const double analytic = std::abs(Centre(grid, i, j, k).EuclideanDistanceTo(c) - r);
        const double stored = volume.data[volume.channels * Offset(i, j, k) + channel];
        worst = std::max(worst, std::abs(stored - analytic));
      }
  return worst;
}
} // namespace

TEST(ObjectiveData, ChannelsHoldTheIntensitiesAndTheGuidanceDistances)
{
  const RegistrationProblem problem = MakeProblem();
  const MeshModel           model = ModelOn(problem.fixedImage);
  morea_core::ParameterSet       parameters;
  parameters.SetFromString("morea_sampling_rate", "2.5");
  const morea_core::ObjectiveData data = BuildObjectiveData(problem, model, parameters);

  ASSERT_EQ(data.guidanceNames, (std::vector<std::string>{ "liver", "bladder" }));
  ASSERT_EQ(data.NumberOfGuidanceStructures(), 2u);
  for (const morea_core::ChannelVolume * v : { &data.fixed, &data.moving })
  {
    ASSERT_EQ(v->channels, 3u);
    ASSERT_EQ(v->data.size(), 3u * N * N * N);
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_EQ(v->size[a], N);
      EXPECT_DOUBLE_EQ(v->spacing[a], Spacing);
      EXPECT_DOUBLE_EQ(v->origin[a], problem.fixedImage->GetOrigin()[a]);
    }
  }

  // Channel 0 is the image, voxel for voxel (ITK's buffer order is the core's).
  const float * fixedBuffer = problem.fixedImage->GetBufferPointer();
  const float * movingBuffer = problem.movingImage->GetBufferPointer();
  for (std::size_t v = 0; v < std::size_t{ N } * N * N; ++v)
  {
    ASSERT_EQ(data.fixed.data[3 * v], fixedBuffer[v]) << v;
    ASSERT_EQ(data.moving.data[3 * v], movingBuffer[v]) << v;
  }
  EXPECT_EQ(data.fixed.data[3 * Offset(0, 5, 7)], 0.0f); // background stays exactly 0

  // Liver (mask): centre ~ radius, surface voxels within a voxel, everywhere within a voxel of the truth.
  const auto * g = problem.fixedImage.GetPointer();
  EXPECT_NEAR(data.fixed.data[3 * Offset(20, 20, 20) + 1], Radius, 0.5 * Spacing);
  EXPECT_NEAR(data.moving.data[3 * Offset(22, 19, 20) + 1], Radius, 0.5 * Spacing);
  const PointListType surface = ExtractSurfacePoints(problem.structures[0].fixedMask);
  ASSERT_FALSE(surface.empty());
  for (const PointType & p : surface)
  {
    itk::Index<3> index;
    g->TransformPhysicalPointToIndex(p, index);
    EXPECT_LT(data.fixed.data[3 * Offset(index[0], index[1], index[2]) + 1], Spacing);
  }
  EXPECT_NEAR(data.fixed.data[3 * Offset(0, 0, 0) + 1],
              Centre(g, 0, 0, 0).EuclideanDistanceTo(Centre(g, 20, 20, 20)) - Radius, Spacing);
  EXPECT_LT(MaxSphereError(data.fixed, 1, g, Centre(g, 20, 20, 20), Radius), Spacing);
  EXPECT_LT(MaxSphereError(data.moving, 1, g, Centre(g, 22, 19, 20), Radius), Spacing);

  // Bladder (points only): rasterised to the nearest voxels, within half a voxel diagonal more.
  const double pointsTolerance = Spacing * (1.0 + 0.5 * std::sqrt(3.0));
  EXPECT_LT(MaxSphereError(data.fixed, 2, g, Centre(g, 8, 30, 10), 5.0), pointsTolerance);
  EXPECT_LT(MaxSphereError(data.moving, 2, g, Centre(g, 9, 30, 10), 5.0), pointsTolerance);
  EXPECT_NEAR(data.fixed.data[3 * Offset(8, 30, 10) + 2], 5.0, Spacing);

  // Weights: shares of the moving contour points (liver: its mask's surface points).
  const double liverPoints = static_cast<double>(ExtractSurfacePoints(problem.structures[0].movingMask).size());
  const double bladderPoints = 500.0;
  ASSERT_EQ(data.guidanceWeights.size(), 2u);
  EXPECT_NEAR(data.guidanceWeights[0] + data.guidanceWeights[1], 1.0, 1e-12);
  EXPECT_NEAR(data.guidanceWeights[0], liverPoints / (liverPoints + bladderPoints), 1e-12);
  EXPECT_NEAR(data.guidanceWeights[1], bladderPoints / (liverPoints + bladderPoints), 1e-12);

  EXPECT_NEAR(data.guidanceRadius, 0.025 * (N - 1) * Spacing, 1e-12);
  EXPECT_DOUBLE_EQ(data.samplingRate, 2.5);
  EXPECT_NEAR(data.voxelVolume, Spacing * Spacing * Spacing, 1e-12);
}

TEST(ObjectiveData, SampleInterpolatesTheStoredChannels)
{
  const RegistrationProblem  problem = MakeProblem();
  const morea_core::ObjectiveData data = BuildObjectiveData(problem, ModelOn(problem.fixedImage), morea_core::ParameterSet());
  const morea_core::ChannelVolume & v = data.moving;
  std::mt19937                 random(7);
  std::uniform_int_distribution<long> index(0, N - 2);
  for (int trial = 0; trial < 200; ++trial)
  {
    const long i = index(random), j = index(random), k = index(random);
    const int  axis = trial % 3;
    Vec3       p{ { v.origin[0] + Spacing * i, v.origin[1] + Spacing * j, v.origin[2] + Spacing * k } };
    float      at[3], next[3], mid[3];
    v.Sample(p, at);
    p[axis] += Spacing;
    v.Sample(p, next);
    p[axis] -= 0.5 * Spacing;
    v.Sample(p, mid);
    const std::size_t o = Offset(i, j, k);
    const std::size_t n = Offset(i + (axis == 0), j + (axis == 1), k + (axis == 2));
    for (std::size_t c = 0; c < 3; ++c)
    {
      EXPECT_NEAR(at[c], v.data[3 * o + c], 1e-5);
      EXPECT_NEAR(next[c], v.data[3 * n + c], 1e-5);
      EXPECT_NEAR(mid[c], 0.5 * (v.data[3 * o + c] + v.data[3 * n + c]), 1e-5);
    }
  }
}

TEST(ObjectiveData, GuidanceSelectionAndDisabling)
{
  const RegistrationProblem problem = MakeProblem();
  const MeshModel           model = ModelOn(problem.fixedImage);

  morea_core::ParameterSet disabled;
  disabled.SetFromString("problem_guidance_enabled", "false");
  const morea_core::ObjectiveData none = BuildObjectiveData(problem, model, disabled);
  EXPECT_EQ(none.fixed.channels, 1u);
  EXPECT_EQ(none.moving.channels, 1u);
  EXPECT_EQ(none.fixed.data.size(), std::size_t{ N } * N * N);
  EXPECT_TRUE(none.guidanceNames.empty());
  EXPECT_EQ(none.NumberOfGuidanceStructures(), 0u);

  // An explicit selection sets the channel order; "body" can be chosen by name.
  morea_core::ParameterSet selected;
  selected.SetFromString("problem_guidance_selection", "bladder,body");
  const morea_core::ObjectiveData two = BuildObjectiveData(problem, model, selected);
  ASSERT_EQ(two.guidanceNames, (std::vector<std::string>{ "bladder", "body" }));
  EXPECT_EQ(two.fixed.channels, 3u);
  EXPECT_NEAR(two.fixed.data[3 * Offset(20, 20, 20) + 2], 25.0, 0.5 * Spacing);
  EXPECT_NEAR(two.fixed.data[3 * Offset(8, 30, 10) + 1], 5.0, Spacing);
}

TEST(ObjectiveData, MissingGuidanceDataThrows)
{
  const MeshModel model = ModelOn(MakeProblem().fixedImage);

  morea_core::ParameterSet unknown;
  unknown.SetFromString("problem_guidance_selection", "liver,stomach");
  EXPECT_THROW(BuildObjectiveData(MakeProblem(), model, unknown), itk::ExceptionObject);

  RegistrationProblem noMovingSide = MakeProblem();
  noMovingSide.structures[2].movingPoints.clear();
  try
  {
    BuildObjectiveData(noMovingSide, model, morea_core::ParameterSet());
    FAIL() << "a guidance structure without moving data was accepted";
  }
  catch (const itk::ExceptionObject & e)
  {
    const std::string message = e.GetDescription();
    EXPECT_NE(message.find("bladder"), std::string::npos) << message;
    EXPECT_NE(message.find("moving"), std::string::npos) << message;
  }

  // An empty mask without points is as good as none.
  RegistrationProblem emptyMask = MakeProblem();
  emptyMask.structures[0].fixedMask->FillBuffer(0);
  EXPECT_THROW(BuildObjectiveData(emptyMask, model, morea_core::ParameterSet()), itk::ExceptionObject);

  // Not preprocessed: the images on different grids.
  RegistrationProblem otherGrid = MakeProblem();
  auto                origin = otherGrid.movingImage->GetOrigin();
  origin[1] += 3.0;
  otherGrid.movingImage->SetOrigin(origin);
  EXPECT_THROW(BuildObjectiveData(otherGrid, model, morea_core::ParameterSet()), itk::ExceptionObject);

  // Guidance disabled: structures are not looked at.
  morea_core::ParameterSet disabled;
  disabled.SetFromString("problem_guidance_enabled", "false");
  EXPECT_NO_THROW(BuildObjectiveData(noMovingSide, model, disabled));
}

TEST(ObjectiveData, RotatedGridIsSampledInTheDomainFrame)
{
  DomainFrame::DirectionType d;
  d.Fill(0.0);
  d[0][1] = -1.0; // 90 degrees about z
  d[1][0] = 1.0;
  d[2][2] = 1.0;
  const DomainFrame         frame(d);
  const RegistrationProblem problem = MakeProblem(frame);
  const MeshModel           model = ModelOn(problem.fixedImage);
  const auto                data = BuildObjectiveData(problem, model, morea_core::ParameterSet());

  const auto * g = problem.fixedImage.GetPointer();
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(data.fixed.origin[a], frame.ToFrame(g->GetOrigin())[a], 1e-9);
  float out[3];
  for (const auto & [i, j, k] : { std::array<long, 3>{ 3, 4, 5 }, std::array<long, 3>{ 30, 12, 27 } })
  {
    data.fixed.Sample(frame.ToFrame(Centre(g, i, j, k)), out);
    itk::Index<3> index{ { i, j, k } };
    EXPECT_NEAR(out[0], problem.fixedImage->GetPixel(index), 1e-6);
  }
  data.moving.Sample(frame.ToFrame(Centre(g, 22, 19, 20)), out);
  EXPECT_NEAR(out[1], Radius, 0.5 * Spacing);

  // A model in another frame does not fit.
  EXPECT_THROW(BuildObjectiveData(problem, MeshModel(), morea_core::ParameterSet()), itk::ExceptionObject);
}

TEST(ObjectiveData, DistanceMapOfAMaskFillingTheGridIsToItsEdge)
{
  Structure full;
  full.name = "everything";
  full.fixedMask = MakeGrid<MaskType>();
  full.fixedMask->FillBuffer(1);
  const ImageType::Pointer map = StructureDistanceMap(full, true, full.fixedMask);
  EXPECT_TRUE(SameGrid(map, full.fixedMask));
  EXPECT_NEAR(map->GetPixel({ { 5, 20, 20 } }), 5 * Spacing, 1e-4);
  EXPECT_NEAR(map->GetPixel({ { 0, 20, 20 } }), 0.0, 1e-4);
  EXPECT_THROW(StructureDistanceMap(full, false, full.fixedMask), itk::ExceptionObject);
}
