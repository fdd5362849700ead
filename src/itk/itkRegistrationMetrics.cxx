// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: registration quality metrics.
 *
 *  Masks are binary with "non-zero = inside". All metrics work on the voxel
 *  grid of their inputs; physical distances use spacing and direction.
 *=========================================================================*/
#include "itkRegistrationMetrics.h"
#include "itkMOREAFail.h"

#include "itkMOREAImageIO.h"
#include "itkSurfaceElements.h"

#include "itkDisplacementFieldTransform.h"
#include "itkIdentityTransform.h"
#include "itkImageRegionConstIteratorWithIndex.h"
#include "itkImageRegionIterator.h"
#include "itkLinearInterpolateImageFunction.h"
#include "itkMultiThreaderBase.h"
#include "itkResampleImageFilter.h"
#include "itkSignedMaurerDistanceMapImageFilter.h"
#include "itkVectorLinearInterpolateImageFunction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <string>
#include <utility>

namespace itk
{
namespace morea
{
namespace
{
using IndexArray = std::array<SizeValueType, Dimension>;
using FieldInterpolatorType = VectorLinearInterpolateImageFunction<DisplacementFieldType, double>;

void
RequireImage(const ImageBase<Dimension> * image, const std::string & what)
{
  if (image == nullptr)
  {
    Fail(what + " is null");
  }
  const auto & region = image->GetLargestPossibleRegion();
  if (region.GetNumberOfPixels() == 0)
  {
    Fail(what + " has no voxels");
  }
  // The raw-buffer loops below assume the whole image is in memory.
  if (image->GetBufferedRegion() != region)
  {
    Fail(what + " is not fully buffered (call Update() on its source)");
  }
}

void
RequireSameGrid(const ImageBase<Dimension> * reference,
                const std::string &          referenceWhat,
                const ImageBase<Dimension> * other,
                const std::string &          otherWhat)
{
  if (other != nullptr && !SameGrid(reference, other))
  {
    Fail(otherWhat + " is not on the voxel grid of " + referenceWhat +
         " (size, spacing, origin and direction must match)");
  }
}

/** Checks the optional region and returns whether voxel `i` (linear offset) is scored. */
class RegionTest
{
public:
  RegionTest(const MaskType * region, const ImageBase<Dimension> * grid, const std::string & gridWhat)
  {
    if (region != nullptr)
    {
      RequireImage(region, "evaluation region");
      RequireSameGrid(grid, gridWhat, region, "the evaluation region");
      m_Buffer = region->GetBufferPointer();
    }
  }
  bool
  operator()(SizeValueType i) const
  {
    return m_Buffer == nullptr || m_Buffer[i] != 0;
  }

private:
  const MaskType::PixelType * m_Buffer{ nullptr };
};

/** Bounding box (inclusive) of the union of two masks' inside voxels. */
bool
UnionBoundingBox(const MaskType * a, const MaskType * b, IndexArray & lower, IndexArray & upper)
{
  const auto size = a->GetLargestPossibleRegion().GetSize();
  const auto * pa = a->GetBufferPointer();
  const auto * pb = b->GetBufferPointer();
  lower.fill(std::numeric_limits<SizeValueType>::max());
  upper.fill(0);
  bool          any{ false };
  SizeValueType i{ 0 };
  for (SizeValueType z = 0; z < size[2]; ++z)
  {
    for (SizeValueType y = 0; y < size[1]; ++y)
    {
      for (SizeValueType x = 0; x < size[0]; ++x, ++i)
      {
        if (pa[i] != 0 || pb[i] != 0)
        {
          any = true;
          const IndexArray idx{ { x, y, z } };
          for (unsigned int d = 0; d < Dimension; ++d)
          {
            lower[d] = std::min(lower[d], idx[d]);
            upper[d] = std::max(upper[d], idx[d]);
          }
        }
      }
    }
  }
  return any;
}

/** Euclidean distance (mm) from every grid point to the nearest point of `set`.
 *  Maurer's transform is exact; outside the set its value is the distance to the
 *  nearest set point (the nearest one always borders the outside), inside the
 *  set it is <= 0 and callers use 0 there. */
ImageType::Pointer
DistanceToSet(const MaskType * set)
{
  using FilterType = SignedMaurerDistanceMapImageFilter<MaskType, ImageType>;
  auto filter = FilterType::New();
  filter->SetInput(set);
  filter->SetSquaredDistance(false);
  filter->SetUseImageSpacing(true);
  filter->SetInsideIsPositive(false);
  filter->SetBackgroundValue(0);
  filter->Update();
  ImageType::Pointer map = filter->GetOutput();
  map->DisconnectPipeline();
  return map;
}

struct DirectedDistances
{
  std::vector<std::pair<double, double>> distanceAndArea; ///< ascending
};

/** Distances from the scored surface elements of `from` to the surface of `to`
 *  (both on one corner grid), with the elements' areas. */
DirectedDistances
Directed(const detail::SurfaceElements & from, const detail::SurfaceElements & to, const ImageType * toDistance)
{
  DirectedDistances result;
  result.distanceAndArea.reserve(from.scored.size());
  const auto * toBuffer = to.grid->GetBufferPointer();
  const auto * distance = toDistance->GetBufferPointer();
  for (const auto & element : from.scored)
  {
    const auto   o = element.offset;
    const double d = toBuffer[o] != 0 ? 0.0 : std::max(0.0, static_cast<double>(distance[o]));
    result.distanceAndArea.emplace_back(d, element.area);
  }
  std::sort(result.distanceAndArea.begin(), result.distanceAndArea.end());
  return result;
}

/** pymia's percentile of a directed distance set: the smallest distance whose
 *  cumulative (area-weighted) share reaches `fraction` (numpy searchsorted, left). */
double
AreaWeightedPercentile(const DirectedDistances & directed, double fraction)
{
  const auto & values = directed.distanceAndArea;
  if (values.empty())
  {
    return 0.0;
  }
  double total{ 0.0 };
  for (const auto & v : values)
  {
    total += v.second;
  }
  double cumulative{ 0.0 };
  for (const auto & v : values)
  {
    cumulative += v.second;
    if (cumulative / total >= fraction)
    {
      return v.first;
    }
  }
  return values.back().first;
}

void
ThresholdInto(const ImageType * source, MaskType * target)
{
  const auto * in = source->GetBufferPointer();
  auto *       out = target->GetBufferPointer();
  const auto   n = source->GetBufferedRegion().GetNumberOfPixels();
  for (SizeValueType i = 0; i < n; ++i)
  {
    out[i] = in[i] >= 0.5f ? 1 : 0;
  }
}

/** The binary mask (non-zero -> 1) as a float image, so masks and images share one resampler. */
ImageType::Pointer
MaskToFloat(const MaskType * mask)
{
  auto image = ImageType::New();
  image->CopyInformation(mask);
  image->SetRegions(mask->GetLargestPossibleRegion());
  image->Allocate();
  const auto * in = mask->GetBufferPointer();
  auto *       out = image->GetBufferPointer();
  const auto   n = mask->GetBufferedRegion().GetNumberOfPixels();
  for (SizeValueType i = 0; i < n; ++i)
  {
    out[i] = in[i] != 0 ? 1.0f : 0.0f;
  }
  return image;
}

/** Linear resampling of `input` onto `grid` through `transform` (output point -> input point). */
ImageType::Pointer
Resample(const ImageType *                          input,
         const ImageBase<Dimension> *               grid,
         const Transform<double, Dimension, Dimension> * transform,
         float                                      defaultValue)
{
  using ResamplerType = ResampleImageFilter<ImageType, ImageType, double>;
  auto resampler = ResamplerType::New();
  resampler->SetInput(input);
  resampler->SetTransform(transform);
  resampler->SetInterpolator(LinearInterpolateImageFunction<ImageType, double>::New());
  resampler->SetOutputParametersFromImage(grid);
  resampler->SetDefaultPixelValue(defaultValue);
  resampler->Update();
  ImageType::Pointer output = resampler->GetOutput();
  output->DisconnectPipeline();
  return output;
}

DisplacementFieldTransform<double, Dimension>::Pointer
MakeFieldTransform(const DisplacementFieldType * field)
{
  auto transform = DisplacementFieldTransform<double, Dimension>::New();
  // The transform only reads the field; its setter is non-const by ITK's API.
  transform->SetDisplacementField(const_cast<DisplacementFieldType *>(field));
  return transform;
}

MaskType::Pointer
ResampleMask(const MaskType *                                 mask,
             const ImageBase<Dimension> *                     grid,
             const Transform<double, Dimension, Dimension> * transform)
{
  const auto resampled = Resample(MaskToFloat(mask), grid, transform, 0.0f);
  auto       output = MaskType::New();
  output->CopyInformation(resampled);
  output->SetRegions(resampled->GetLargestPossibleRegion());
  output->Allocate();
  ThresholdInto(resampled, output);
  return output;
}

FieldInterpolatorType::Pointer
MakeFieldInterpolator(const DisplacementFieldType * field)
{
  auto interpolator = FieldInterpolatorType::New();
  interpolator->SetInputImage(field);
  return interpolator;
}
} // namespace

double
ComputeDice(const MaskType * a, const MaskType * b, const MaskType * region)
{
  RequireImage(a, "first Dice mask");
  RequireImage(b, "second Dice mask");
  RequireSameGrid(a, "the first Dice mask", b, "the second Dice mask");
  const RegionTest inRegion{ region, a, "the Dice masks" };

  const auto * pa = a->GetBufferPointer();
  const auto * pb = b->GetBufferPointer();
  const auto   n = a->GetBufferedRegion().GetNumberOfPixels();
  // Counting directly is as cheap as LabelOverlapMeasuresImageFilter and honours the region.
  SizeValueType countA{ 0 }, countB{ 0 }, both{ 0 };
  for (SizeValueType i = 0; i < n; ++i)
  {
    if (!inRegion(i))
    {
      continue;
    }
    const bool inA = pa[i] != 0;
    const bool inB = pb[i] != 0;
    countA += inA;
    countB += inB;
    both += inA && inB;
  }
  if (countA + countB == 0)
  {
    return 1.0; // both empty: perfect agreement (as pymia's DiceCoefficient)
  }
  return 2.0 * static_cast<double>(both) / static_cast<double>(countA + countB);
}

/* Surface distances, following pymia 0.3.4 (pymia/evaluation/metric/base.py
 * `Distances`, categorical.py `HausdorffDistance`), which ports DeepMind's
 * surface-distance package:
 *  - a mask's surface elements are the voxel corners whose 2x2x2 neighbourhood
 *    holds inside and outside voxels (outside the image counts as outside, like
 *    pymia's zero padding), each weighted by the surface area of its
 *    neighbourhood code (itkSurfaceElements.cxx);
 *  - the directed distances run from every surface element of one mask to the
 *    nearest surface element of the other (an exact Euclidean distance transform
 *    of the other surface on the corner grid, in mm);
 *  - HD_p of one direction is the smallest distance whose cumulative area share
 *    (distances sorted ascending) reaches p/100 (np.searchsorted, side left),
 *    without interpolation; HD_p = max of the two directed values;
 *    HD (p = 100) is the max of both directed maxima.
 * The mean surface distance is the area-weighted mean over both directions
 * together (pymia's package has no such metric; the surface-distance package
 * reports the two directed means).
 * With a region, only the surface elements whose 2x2x2 neighbourhood lies in
 * the region (ignoring voxels beyond the image) are scored, so no scored
 * element depends on a voxel outside the region; they are still measured to
 * the other mask's whole surface. */
SurfaceDistanceScores
ComputeSurfaceDistances(const MaskType * a, const MaskType * b, const MaskType * region)
{
  RequireImage(a, "first surface-distance mask");
  RequireImage(b, "second surface-distance mask");
  RequireSameGrid(a, "the first surface-distance mask", b, "the second surface-distance mask");
  const RegionTest checkRegion{ region, a, "the surface-distance masks" }; // validates `region`

  IndexArray lower;
  IndexArray upper;
  if (!UnionBoundingBox(a, b, lower, upper))
  {
    Fail("surface distances: both masks are empty");
  }
  // Every surface element lies on the corners of the union's bounding box, and
  // Euclidean distances between them do not depend on anything outside it.
  const auto areas = SurfaceElementAreas(a->GetSpacing());
  const auto surfaceA = detail::ExtractSurfaceElements(a, region, lower, upper, areas);
  const auto surfaceB = detail::ExtractSurfaceElements(b, region, lower, upper, areas);
  if (surfaceA.count == 0)
  {
    Fail("surface distances: the first mask is empty");
  }
  if (surfaceB.count == 0)
  {
    Fail("surface distances: the second mask is empty");
  }
  const auto aToB = Directed(surfaceA, surfaceB, DistanceToSet(surfaceB.grid));
  const auto bToA = Directed(surfaceB, surfaceA, DistanceToSet(surfaceA.grid));

  SurfaceDistanceScores scores;
  double                weightedSum{ 0.0 };
  double                totalArea{ 0.0 };
  for (const auto * directed : { &aToB, &bToA })
  {
    if (!directed->distanceAndArea.empty())
    {
      scores.hausdorff = std::max(scores.hausdorff, directed->distanceAndArea.back().first);
    }
    scores.hausdorff95 = std::max(scores.hausdorff95, AreaWeightedPercentile(*directed, 0.95));
    for (const auto & [distance, area] : directed->distanceAndArea)
    {
      weightedSum += distance * area;
      totalArea += area;
    }
  }
  scores.meanSurfaceDistance = totalArea > 0.0 ? weightedSum / totalArea : 0.0;
  return scores;
}

LandmarkErrorScores
ComputeLandmarkErrors(const LandmarkListType &      fixedLandmarks,
                      const LandmarkListType &      movingLandmarks,
                      const DisplacementFieldType * fixedToMoving)
{
  if (fixedLandmarks.empty())
  {
    Fail("landmark errors: no landmarks given");
  }
  if (fixedLandmarks.size() != movingLandmarks.size())
  {
    Fail("landmark errors: " + std::to_string(fixedLandmarks.size()) + " fixed landmarks but " +
         std::to_string(movingLandmarks.size()) + " moving landmarks");
  }
  FieldInterpolatorType::Pointer interpolator;
  if (fixedToMoving != nullptr)
  {
    RequireImage(fixedToMoving, "landmark displacement field");
    interpolator = MakeFieldInterpolator(fixedToMoving);
  }

  LandmarkErrorScores scores;
  scores.errors.reserve(fixedLandmarks.size());
  for (std::size_t i = 0; i < fixedLandmarks.size(); ++i)
  {
    PointType mapped = fixedLandmarks[i];
    if (interpolator)
    {
      if (!interpolator->IsInsideBuffer(mapped))
      {
        Fail("landmark errors: fixed landmark " + std::to_string(i + 1) +
             " lies outside the displacement field's domain");
      }
      const auto u = interpolator->Evaluate(mapped);
      for (unsigned int d = 0; d < Dimension; ++d)
      {
        mapped[d] += u[d];
      }
    }
    scores.errors.push_back(mapped.EuclideanDistanceTo(movingLandmarks[i]));
  }
  const double n = static_cast<double>(scores.errors.size());
  scores.mean = std::accumulate(scores.errors.begin(), scores.errors.end(), 0.0) / n;
  scores.maximum = *std::max_element(scores.errors.begin(), scores.errors.end());
  double squares{ 0.0 };
  for (const double e : scores.errors)
  {
    squares += (e - scores.mean) * (e - scores.mean);
  }
  // Population standard deviation (numpy.std's default), so one landmark gives 0.
  scores.standardDeviation = std::sqrt(squares / n);
  return scores;
}

/* Central differences in index space (one-sided at the image edge), divided by
 * spacing and rotated by the inverse direction, so the gradient is with respect
 * to physical coordinates. ITK's DisplacementFieldJacobianDeterminantFilter with
 * UseImageSpacing gives the same values in the interior for identity directions,
 * but ignores the direction and halves the edge differences (zero-flux boundary). */
double
ComputeNonPositiveJacobianFraction(const DisplacementFieldType * field, const MaskType * region)
{
  RequireImage(field, "Jacobian displacement field");
  const RegionTest inRegion{ region, field, "the displacement field" };

  const auto   size = field->GetLargestPossibleRegion().GetSize();
  const auto   spacing = field->GetSpacing();
  const auto   inverseDirection = field->GetInverseDirection();
  const auto * u = field->GetBufferPointer();
  const std::array<SizeValueType, Dimension> stride{ { 1, size[0], size[0] * size[1] } };

  std::mutex    mutex;
  SizeValueType scored{ 0 };
  SizeValueType folded{ 0 };
  MultiThreaderBase::New()->ParallelizeImageRegion<Dimension>(
    field->GetLargestPossibleRegion(),
    [&](const DisplacementFieldType::RegionType & chunk) {
      SizeValueType localScored{ 0 };
      SizeValueType localFolded{ 0 };
      for (ImageRegionConstIteratorWithIndex<DisplacementFieldType> it(field, chunk); !it.IsAtEnd(); ++it)
      {
        const auto          index = it.GetIndex();
        const SizeValueType i = index[0] + stride[1] * index[1] + stride[2] * index[2];
        if (!inRegion(i))
        {
          continue;
        }
        // g[c][d] = d u_c / d (index_d * spacing_d)
        double g[Dimension][Dimension];
        for (unsigned int d = 0; d < Dimension; ++d)
        {
          const auto    n = static_cast<IndexValueType>(size[d]);
          const bool    hasLower = index[d] > 0;
          const bool    hasUpper = index[d] + 1 < n;
          const auto    lo = hasLower ? i - stride[d] : i;
          const auto    hi = hasUpper ? i + stride[d] : i;
          const double  steps = static_cast<double>(hasLower) + static_cast<double>(hasUpper);
          for (unsigned int c = 0; c < Dimension; ++c)
          {
            g[c][d] = steps > 0.0 ? (u[hi][c] - u[lo][c]) / (steps * spacing[d]) : 0.0;
          }
        }
        // J = I + g * D^-1  (x = origin + D * S * index)
        double j[Dimension][Dimension];
        for (unsigned int c = 0; c < Dimension; ++c)
        {
          for (unsigned int e = 0; e < Dimension; ++e)
          {
            double sum = c == e ? 1.0 : 0.0;
            for (unsigned int d = 0; d < Dimension; ++d)
            {
              sum += g[c][d] * inverseDirection[d][e];
            }
            j[c][e] = sum;
          }
        }
        const double det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) -
                           j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0]) +
                           j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
        ++localScored;
        localFolded += det <= 0.0;
      }
      const std::lock_guard<std::mutex> lock{ mutex };
      scored += localScored;
      folded += localFolded;
    },
    nullptr);
  if (scored == 0)
  {
    Fail("Jacobian fraction: the evaluation region is empty");
  }
  return static_cast<double>(folded) / static_cast<double>(scored);
}

InverseConsistencyScores
ComputeInverseConsistency(const DisplacementFieldType * fixedToMoving,
                          const DisplacementFieldType * movingToFixed,
                          const MaskType *              region)
{
  RequireImage(fixedToMoving, "fixed-to-moving displacement field");
  RequireImage(movingToFixed, "moving-to-fixed displacement field");
  const RegionTest inRegion{ region, fixedToMoving, "the fixed-to-moving field" };
  const auto       interpolator = MakeFieldInterpolator(movingToFixed);
  const auto       size = fixedToMoving->GetLargestPossibleRegion().GetSize();

  std::mutex               mutex;
  InverseConsistencyScores scores;
  double                   sum{ 0.0 };
  MultiThreaderBase::New()->ParallelizeImageRegion<Dimension>(
    fixedToMoving->GetLargestPossibleRegion(),
    [&](const DisplacementFieldType::RegionType & chunk) {
      double        localSum{ 0.0 };
      double        localMax{ 0.0 };
      SizeValueType localEvaluated{ 0 };
      SizeValueType localSkipped{ 0 };
      for (ImageRegionConstIteratorWithIndex<DisplacementFieldType> it(fixedToMoving, chunk); !it.IsAtEnd(); ++it)
      {
        const auto index = it.GetIndex();
        if (!inRegion(index[0] + size[0] * (index[1] + size[1] * index[2])))
        {
          continue;
        }
        PointType x;
        fixedToMoving->TransformIndexToPhysicalPoint(index, x);
        const auto & u = it.Get();
        PointType    y;
        for (unsigned int d = 0; d < Dimension; ++d)
        {
          y[d] = x[d] + u[d];
        }
        // Points mapped off the moving grid have no v to compare with.
        if (!interpolator->IsInsideBuffer(y))
        {
          ++localSkipped;
          continue;
        }
        const auto v = interpolator->Evaluate(y);
        double     squared{ 0.0 };
        for (unsigned int d = 0; d < Dimension; ++d)
        {
          const double r = y[d] + v[d] - x[d];
          squared += r * r;
        }
        const double error = std::sqrt(squared);
        localSum += error;
        localMax = std::max(localMax, error);
        ++localEvaluated;
      }
      const std::lock_guard<std::mutex> lock{ mutex };
      sum += localSum;
      scores.maximum = std::max(scores.maximum, localMax);
      scores.evaluatedPoints += localEvaluated;
      scores.pointsOutside += localSkipped;
    },
    nullptr);
  if (scores.evaluatedPoints == 0)
  {
    Fail("inverse consistency: no scored voxel maps inside the moving-to-fixed field (" +
         std::to_string(scores.pointsOutside) + " mapped outside)");
  }
  scores.mean = sum / static_cast<double>(scores.evaluatedPoints);
  return scores;
}

/* The image domain is the box bounded by the outer voxel faces; a voxel is kept
 * when its centre is at least marginMm from every face of that box, measured
 * along each index axis ((i + 0.5) * spacing from the low face). */
MaskType::Pointer
MakeBorderMarginRegion(const ImageBase<Dimension> * grid, double marginMm)
{
  if (grid == nullptr)
  {
    Fail("border margin: the grid image is null");
  }
  if (!(marginMm >= 0.0) || !std::isfinite(marginMm))
  {
    Fail("border margin: the margin must be a finite value >= 0 mm, got " + std::to_string(marginMm));
  }
  const auto & largest = grid->GetLargestPossibleRegion();
  if (largest.GetNumberOfPixels() == 0)
  {
    Fail("border margin: the grid has no voxels");
  }
  const auto size = largest.GetSize();
  const auto spacing = grid->GetSpacing();

  auto region = MaskType::New();
  region->CopyInformation(grid);
  region->SetRegions(largest);
  region->Allocate(true);

  // Per axis, the first and last kept index.
  std::array<SizeValueType, Dimension> first{};
  std::array<SizeValueType, Dimension> last{};
  for (unsigned int d = 0; d < Dimension; ++d)
  {
    SizeValueType k{ 0 };
    while (k < size[d] && (static_cast<double>(k) + 0.5) * spacing[d] < marginMm)
    {
      ++k;
    }
    if (2 * k + 1 > size[d])
    {
      Fail("border margin: a margin of " + std::to_string(marginMm) + " mm leaves no voxel of the " +
           std::to_string(size[d]) + "-voxel axis " + std::to_string(d));
    }
    first[d] = k; // the margin is symmetric
    last[d] = size[d] - 1 - k;
  }
  auto * out = region->GetBufferPointer();
  SizeValueType i{ 0 };
  for (SizeValueType z = 0; z < size[2]; ++z)
  {
    for (SizeValueType y = 0; y < size[1]; ++y)
    {
      for (SizeValueType x = 0; x < size[0]; ++x, ++i)
      {
        out[i] = x >= first[0] && x <= last[0] && y >= first[1] && y <= last[1] && z >= first[2] && z <= last[2];
      }
    }
  }
  return region;
}

MaskType::Pointer
WarpMask(const MaskType * movingMask, const DisplacementFieldType * fixedToMoving)
{
  RequireImage(movingMask, "mask to warp");
  RequireImage(fixedToMoving, "warping displacement field");
  return ResampleMask(movingMask, fixedToMoving, MakeFieldTransform(fixedToMoving));
}

ImageType::Pointer
WarpImage(const ImageType * movingImage, const DisplacementFieldType * fixedToMoving, float defaultValue)
{
  RequireImage(movingImage, "image to warp");
  RequireImage(fixedToMoving, "warping displacement field");
  return Resample(movingImage, fixedToMoving, MakeFieldTransform(fixedToMoving), defaultValue);
}

MaskType::Pointer
ResampleMaskOnto(const MaskType * mask, const ImageBase<Dimension> * grid)
{
  RequireImage(mask, "mask to resample");
  if (grid == nullptr || grid->GetLargestPossibleRegion().GetNumberOfPixels() == 0)
  {
    Fail("resampling a mask: the target grid is null or has no voxels");
  }
  return ResampleMask(mask, grid, IdentityTransform<double, Dimension>::New());
}

} // namespace morea
} // namespace itk
