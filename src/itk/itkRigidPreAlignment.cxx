// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkRigidPreAlignment.h"
#include "itkMOREAFail.h"

#include "itkImageRegionConstIteratorWithIndex.h"
#include "itkImageRegionConstIterator.h"
#include "itkImageRegionIterator.h"
#include "itkImageRegistrationMethodv4.h"
#include "itkMeanSquaresImageToImageMetricv4.h"
#include "itkCorrelationImageToImageMetricv4.h"
#include "itkImageMaskSpatialObject.h"
#include "itkPreprocessing.h"
#include "itkRegistrationParameterScalesFromPhysicalShift.h"
#include "itkGradientDescentOptimizerv4.h"
#include "itkRegularStepGradientDescentOptimizerv4.h"
#include "itkSignedMaurerDistanceMapImageFilter.h"
#include "itkMOREAImageIO.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>

namespace itk
{
namespace morea
{
namespace
{
PointType
Centroid(const MaskType * mask)
{
  double                                      sum[3] = { 0, 0, 0 };
  std::size_t                                 n = 0;
  ImageRegionConstIteratorWithIndex<MaskType> it(mask, mask->GetBufferedRegion());
  for (; !it.IsAtEnd(); ++it)
  {
    if (it.Get() == 0)
      continue;
    PointType p;
    mask->TransformIndexToPhysicalPoint(it.GetIndex(), p);
    for (unsigned d = 0; d < Dimension; ++d)
      sum[d] += p[d];
    ++n;
  }
  if (n == 0)
    Fail("rigid pre-alignment: a structure mask is empty");
  PointType c;
  for (unsigned d = 0; d < Dimension; ++d)
    c[d] = sum[d] / static_cast<double>(n);
  return c;
}

/** The mask's clipped signed distance map on a coarse isotropic grid around it. */
ImageType::Pointer
CoarseDistanceMap(const MaskType * mask, const RigidAlignmentOptions & options)
{
  PointType lower, upper;
  MaskBoundingBox(mask, lower, upper);
  const double           pad = options.distanceClip + 2.0 * options.workingSpacing;
  auto                   grid = ImageType::New();
  ImageType::SizeType    size;
  ImageType::SpacingType spacing;
  ImageType::PointType   origin;
  for (unsigned d = 0; d < Dimension; ++d)
  {
    spacing[d] = options.workingSpacing;
    origin[d] = lower[d] - pad;
    size[d] = static_cast<SizeValueType>(std::ceil((upper[d] - lower[d] + 2.0 * pad) / spacing[d]));
  }
  grid->SetSpacing(spacing);
  grid->SetOrigin(origin);
  grid->SetRegions(ImageType::RegionType(size));
  auto coarse = ResampleMask(mask, grid);

  auto distance = SignedMaurerDistanceMapImageFilter<MaskType, ImageType>::New();
  distance->SetInput(coarse);
  distance->SetInsideIsPositive(false);
  distance->SetSquaredDistance(false);
  distance->SetUseImageSpacing(true);
  distance->Update();
  ImageType::Pointer map = distance->GetOutput();
  const float        clip = static_cast<float>(options.distanceClip);
  for (ImageRegionIterator<ImageType> it(map, map->GetBufferedRegion()); !it.IsAtEnd(); ++it)
    it.Set(std::clamp(it.Get(), -clip, clip));
  return map;
}
} // namespace

namespace
{
ImageType::Pointer
Clamped(const ImageType * image, float lo, float hi)
{
  auto copy = ImageType::New();
  copy->CopyInformation(image);
  copy->SetRegions(image->GetLargestPossibleRegion());
  copy->Allocate();
  ImageRegionConstIterator<ImageType> in(image, image->GetLargestPossibleRegion());
  ImageRegionIterator<ImageType>      out(copy, copy->GetLargestPossibleRegion());
  for (; !in.IsAtEnd(); ++in, ++out)
    out.Set(std::clamp(in.Get(), lo, hi));
  return copy;
}

/** Refines `transform` in place on the image intensities near the fixed
 *  structure; returns false (and `skipped` says why) when the structure's
 *  interior holds too few voxels to sample. */
bool
RefineOnIntensities(const ImageType * fixedImage, const ImageType * movingImage, const ImageType * fixedDistance,
                    RigidTransformType * transform, const RigidAlignmentOptions & options, double & metricValue,
                    std::string & skipped)
{
  // The region: the structure's interior, `intensityInset` mm away from its outline. The
  // outline itself moves with breathing or filling; the inner detail (vessels, bone
  // texture) follows the rigid motion (lung pair: mean TRE 3.9 mm inside vs 7.8 mm
  // with the outline included).
  auto region = MaskType::New();
  region->CopyInformation(fixedDistance);
  region->SetRegions(fixedDistance->GetLargestPossibleRegion());
  region->Allocate();
  ImageRegionConstIterator<ImageType> d(fixedDistance, fixedDistance->GetLargestPossibleRegion());
  ImageRegionIterator<MaskType>       r(region, region->GetLargestPossibleRegion());
  std::size_t                         inside = 0;
  for (; !d.IsAtEnd(); ++d, ++r)
  {
    r.Set(d.Get() <= -options.intensityInset ? 1 : 0);
    inside += r.Get();
  }
  // The coarse level sees an eighth of the voxels, of which the metric
  // samples a fraction: too few samples make the stage fail or wander.
  constexpr double MinimumCoarseSamples = 50.0;
  if (static_cast<double>(inside) / 8.0 * options.samplingFraction < MinimumCoarseSamples)
  {
    skipped = "the structure's interior (" + std::to_string(options.intensityInset) + " mm from its outline) holds " +
              std::to_string(inside) + " voxels, too few to sample; the mask stage's alignment is kept";
    return false;
  }
  auto spatialMask = ImageMaskSpatialObject<Dimension>::New();
  spatialMask->SetImage(region);
  spatialMask->Update();

  using MetricType = CorrelationImageToImageMetricv4<ImageType, ImageType>;
  using OptimizerType = GradientDescentOptimizerv4;
  using RegistrationType = ImageRegistrationMethodv4<ImageType, ImageType, RigidTransformType>;
  auto fixed = Clamped(fixedImage, options.intensityClampMin, options.intensityClampMax);
  auto moving = Clamped(movingImage, options.intensityClampMin, options.intensityClampMax);
  auto metric = MetricType::New();
  metric->SetFixedImageMask(spatialMask);
  // Plain gradient descent with a step bounded in mm and a convergence window,
  // as antsRegistration does: robust to the noise of a sampled metric.
  auto optimizer = OptimizerType::New();
  auto scales = RegistrationParameterScalesFromPhysicalShift<MetricType>::New();
  scales->SetMetric(metric);
  optimizer->SetScalesEstimator(scales);
  optimizer->SetMaximumStepSizeInPhysicalUnits(0.5);
  optimizer->SetDoEstimateLearningRateOnce(false);
  optimizer->SetDoEstimateLearningRateAtEachIteration(true);
  optimizer->SetNumberOfIterations(options.iterationsPerLevel);
  optimizer->SetMinimumConvergenceValue(1e-7);
  optimizer->SetConvergenceWindowSize(10);
  auto registration = RegistrationType::New();
  registration->SetFixedImage(fixed);
  registration->SetMovingImage(moving);
  registration->SetMetric(metric);
  registration->SetOptimizer(optimizer);
  registration->SetInitialTransform(transform);
  registration->InPlaceOn();
  RegistrationType::ShrinkFactorsArrayType shrink(2);
  shrink[0] = 2;
  shrink[1] = 1;
  RegistrationType::SmoothingSigmasArrayType sigmas(2);
  sigmas[0] = 2.0;
  sigmas[1] = 0.0;
  registration->SetNumberOfLevels(2);
  registration->SetShrinkFactorsPerLevel(shrink);
  registration->SetSmoothingSigmasPerLevel(sigmas);
  registration->SetSmoothingSigmasAreSpecifiedInPhysicalUnits(true);
  registration->SetMetricSamplingStrategy(RegistrationType::MetricSamplingStrategyType::RANDOM);
  registration->SetMetricSamplingPercentage(options.samplingFraction);
  registration->MetricSamplingReinitializeSeed(12345); // reproducible runs
  try
  {
    registration->Update();
  }
  catch (const ExceptionObject & e)
  {
    Fail(std::string("rigid pre-alignment (intensity stage) failed: ") + e.GetDescription());
  }
  metricValue = optimizer->GetCurrentMetricValue();
  return true;
}
} // namespace

RigidTransformType::Pointer
AlignRigidly(const MaskType * fixedMask, const MaskType * movingMask, const RigidAlignmentOptions & options,
             RigidAlignmentResult * result, const ImageType * fixedImage, const ImageType * movingImage)
{
  const auto start = std::chrono::steady_clock::now();
  if (fixedMask == nullptr || movingMask == nullptr)
    Fail("rigid pre-alignment needs a fixed and a moving mask");

  auto fixedMap = CoarseDistanceMap(fixedMask, options);
  auto movingMap = CoarseDistanceMap(movingMask, options);

  // Start from the centroids: removes the bulk of a table shift at once.
  auto       transform = RigidTransformType::New();
  const auto fixedCentre = Centroid(fixedMask);
  const auto movingCentre = Centroid(movingMask);
  transform->SetCenter(fixedCentre);
  RigidTransformType::OutputVectorType translation;
  for (unsigned d = 0; d < Dimension; ++d)
    translation[d] = movingCentre[d] - fixedCentre[d];
  transform->SetTranslation(translation);

  using MetricType = MeanSquaresImageToImageMetricv4<ImageType, ImageType>;
  using OptimizerType = RegularStepGradientDescentOptimizerv4<double>;
  using RegistrationType = ImageRegistrationMethodv4<ImageType, ImageType, RigidTransformType>;
  auto metric = MetricType::New();
  auto optimizer = OptimizerType::New();
  auto registration = RegistrationType::New();
  auto scales = RegistrationParameterScalesFromPhysicalShift<MetricType>::New();
  scales->SetMetric(metric);
  optimizer->SetScalesEstimator(scales);
  optimizer->SetLearningRate(options.workingSpacing);
  optimizer->SetMinimumStepLength(1e-3);
  optimizer->SetRelaxationFactor(0.6);
  optimizer->SetNumberOfIterations(options.iterationsPerLevel);
  optimizer->SetGradientMagnitudeTolerance(1e-6);
  optimizer->SetDoEstimateLearningRateOnce(false);

  registration->SetFixedImage(fixedMap);
  registration->SetMovingImage(movingMap);
  registration->SetMetric(metric);
  registration->SetOptimizer(optimizer);
  registration->SetInitialTransform(transform);
  registration->InPlaceOn();
  RegistrationType::ShrinkFactorsArrayType shrink(2);
  shrink[0] = 2;
  shrink[1] = 1;
  RegistrationType::SmoothingSigmasArrayType sigmas(2);
  sigmas[0] = 1.0;
  sigmas[1] = 0.0;
  registration->SetNumberOfLevels(2);
  registration->SetShrinkFactorsPerLevel(shrink);
  registration->SetSmoothingSigmasPerLevel(sigmas);
  registration->SetMetricSamplingStrategy(RegistrationType::MetricSamplingStrategyType::NONE);

  double initialMetric = 0.0;
  {
    metric->SetFixedImage(fixedMap);
    metric->SetMovingImage(movingMap);
    metric->SetMovingTransform(transform);
    metric->Initialize();
    initialMetric = metric->GetValue();
  }
  try
  {
    registration->Update();
  }
  catch (const ExceptionObject & e)
  {
    Fail(std::string("rigid pre-alignment failed: ") + e.GetDescription());
  }

  const double maskMetric = optimizer->GetCurrentMetricValue();
  double       intensityMetric = 0.0;
  bool         refined = false;
  std::string  skipped;
  if (fixedImage != nullptr && movingImage != nullptr)
    refined = RefineOnIntensities(fixedImage, movingImage, fixedMap, transform, options, intensityMetric, skipped);

  if (result != nullptr)
  {
    result->initialMetric = initialMetric;
    result->finalMetric = maskMetric;
    result->intensityRefined = refined;
    result->intensitySkipped = skipped;
    result->intensityMetric = intensityMetric;
    result->iterations = static_cast<unsigned>(optimizer->GetCurrentIteration());
    for (unsigned d = 0; d < Dimension; ++d)
      result->translation[d] = transform->GetTranslation()[d];
    result->rotationDegrees = transform->GetVersor().GetAngle() * 180.0 / M_PI;
    result->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return transform;
}

void
WriteRigidTransform(const PreAlignmentTransformType * transform, const std::string & path)
{
  WriteTransformFile(transform, path);
}

} // namespace morea
} // namespace itk
