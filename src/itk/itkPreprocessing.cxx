// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkPreprocessing.h"

#include "itkMinimumMaximumImageCalculator.h"
#include "itkMOREAFail.h"

#include "itkImageRegionConstIterator.h"
#include "itkImageRegionConstIteratorWithIndex.h"
#include "itkImageRegionIterator.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkLinearInterpolateImageFunction.h"
#include "itkMOREAImageIO.h"
#include "itkRegionOfInterestImageFilter.h"
#include "itkResampleImageFilter.h"
#include "itkSignedMaurerDistanceMapImageFilter.h"
#include "morea_core/ParameterSet.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <sstream>

namespace itk
{
namespace morea
{
namespace
{

/** Index box of the non-zero voxels; false when there are none. Rows are
 *  scanned in the buffer from both ends: an iterator that tracks every
 *  voxel's index took a tenth of preprocessing on full-size CT masks. */
bool
InsideIndexBox(const MaskType * mask, MaskType::IndexType & lo, MaskType::IndexType & hi)
{
  bool any = false;
  for (unsigned d = 0; d < Dimension; ++d)
  {
    lo[d] = std::numeric_limits<IndexValueType>::max();
    hi[d] = std::numeric_limits<IndexValueType>::lowest();
  }
  const auto                  region = mask->GetBufferedRegion();
  const auto                  size = region.GetSize();
  const auto                  start = region.GetIndex();
  const MaskType::PixelType * row = mask->GetBufferPointer();
  auto                        inside = [](MaskType::PixelType v) { return v != 0; };
  for (SizeValueType z = 0; z < size[2]; ++z)
    for (SizeValueType y = 0; y < size[1]; ++y, row += size[0])
    {
      const MaskType::PixelType * first = std::find_if(row, row + size[0], inside);
      if (first == row + size[0])
        continue;
      const MaskType::PixelType * last =
        std::find_if(std::make_reverse_iterator(row + size[0]), std::make_reverse_iterator(first), inside).base() - 1;
      any = true;
      const IndexValueType from[3] = { start[0] + (first - row), start[1] + static_cast<IndexValueType>(y),
                                       start[2] + static_cast<IndexValueType>(z) };
      const IndexValueType to[3] = { start[0] + (last - row), from[1], from[2] };
      for (unsigned d = 0; d < Dimension; ++d)
      {
        lo[d] = std::min(lo[d], from[d]);
        hi[d] = std::max(hi[d], to[d]);
      }
    }
  return any;
}

ImageType::Pointer
SignedDistance(const MaskType * mask)
{
  auto filter = SignedMaurerDistanceMapImageFilter<MaskType, ImageType>::New();
  filter->SetInput(mask);
  filter->SetInsideIsPositive(false);
  filter->SetSquaredDistance(false);
  filter->SetUseImageSpacing(true);
  filter->SetBackgroundValue(0);
  filter->Update();
  return filter->GetOutput();
}

/** A level set whose zero crossing lies on the voxel faces between inside and
 *  outside voxels (half-way, whatever the spacing along that axis): half the
 *  difference of the distance maps of the mask and of its complement. */
ImageType::Pointer
FaceCenteredLevelSet(const MaskType * mask)
{
  auto complement = MaskType::New();
  complement->CopyInformation(mask);
  complement->SetRegions(mask->GetBufferedRegion());
  complement->Allocate();
  ImageRegionConstIterator<MaskType> in(mask, mask->GetBufferedRegion());
  ImageRegionIterator<MaskType>      out(complement, complement->GetBufferedRegion());
  for (; !in.IsAtEnd(); ++in, ++out)
    out.Set(in.Get() != 0 ? 0 : 1);
  auto inside = SignedDistance(mask);
  auto outside = SignedDistance(complement);
  ImageRegionIterator<ImageType>      a(inside, inside->GetBufferedRegion());
  ImageRegionConstIterator<ImageType> b(outside, outside->GetBufferedRegion());
  for (; !a.IsAtEnd(); ++a, ++b)
    a.Set(0.5f * (a.Get() - b.Get()));
  return inside;
}

template <typename TImage>
typename TImage::Pointer
MakeImageOn(const ImageBase<Dimension> * grid)
{
  auto image = TImage::New();
  image->SetOrigin(grid->GetOrigin());
  image->SetSpacing(grid->GetSpacing());
  image->SetDirection(grid->GetDirection());
  image->SetRegions(grid->GetLargestPossibleRegion());
  image->Allocate();
  return image;
}

ImageType::Pointer
ResampleLinear(const ImageType * image, const ImageBase<Dimension> * grid, const PreAlignmentTransformType * gridToImage,
               float defaultValue)
{
  using FilterType = ResampleImageFilter<ImageType, ImageType>;
  auto filter = FilterType::New();
  filter->SetInput(image);
  filter->SetOutputParametersFromImage(grid);
  if (gridToImage != nullptr)
    filter->SetTransform(gridToImage);
  filter->SetInterpolator(LinearInterpolateImageFunction<ImageType, double>::New());
  filter->SetDefaultPixelValue(defaultValue);
  filter->Update();
  return filter->GetOutput();
}

bool
IsBodyName(std::string name)
{
  std::transform(name.begin(), name.end(), name.begin(), ::tolower);
  return name == "body" || name == "external" || name == "skin";
}

double
SecondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
} // namespace

PreprocessOptions
PreprocessOptions::FromParameters(const morea_core::ParameterSet & p)
{
  PreprocessOptions o;
  o.isotropicSpacing = p.GetReal("preprocess_isotropic_spacing");
  o.rigidStructure = p.GetString("preprocess_rigid_structure");
  o.cropStructure = p.GetString("preprocess_crop_structure");
  o.cropMargin = p.GetReal("preprocess_crop_margin");
  o.windowMin = static_cast<float>(p.GetReal("preprocess_intensity_min"));
  o.windowMax = static_cast<float>(p.GetReal("preprocess_intensity_max"));
  o.fieldOfViewThreshold = static_cast<float>(p.GetReal("preprocess_fov_threshold"));
  return o;
}

ImageType::Pointer
ResampleIsotropic(const ImageType * image, double spacing)
{
  if (!(spacing > 0.0))
    Fail("isotropic spacing must be positive");
  auto       grid = ImageType::New();
  const auto size = image->GetLargestPossibleRegion().GetSize();
  ImageType::SizeType outSize;
  ImageType::SpacingType outSpacing;
  for (unsigned d = 0; d < Dimension; ++d)
  {
    const double extent = image->GetSpacing()[d] * static_cast<double>(size[d]);
    outSize[d] = std::max<SizeValueType>(1, static_cast<SizeValueType>(std::floor(extent / spacing + 1e-6)));
    outSpacing[d] = spacing;
  }
  // Keep the outer edge of the first voxel where it was.
  ImageType::PointType origin;
  ContinuousIndex<double, Dimension> firstEdge;
  for (unsigned d = 0; d < Dimension; ++d)
    firstEdge[d] = -0.5 + 0.5 * spacing / image->GetSpacing()[d];
  image->TransformContinuousIndexToPhysicalPoint(firstEdge, origin);
  grid->SetOrigin(origin);
  grid->SetSpacing(outSpacing);
  grid->SetDirection(image->GetDirection());
  grid->SetRegions(ImageType::RegionType(outSize));
  return ResampleLinear(image, grid, nullptr, 0.0f);
}

MaskType::Pointer
ResampleMask(const MaskType * mask, const ImageBase<Dimension> * grid, const PreAlignmentTransformType * gridToMask)
{
  auto                output = MakeImageOn<MaskType>(grid);
  MaskType::IndexType lo, hi;
  if (!InsideIndexBox(mask, lo, hi))
  {
    output->FillBuffer(0);
    return output;
  }
  // Work on the mask's bounding box (plus a border) only: distance maps are the cost.
  const auto          full = mask->GetLargestPossibleRegion();
  MaskType::IndexType start;
  MaskType::SizeType  size;
  for (unsigned d = 0; d < Dimension; ++d)
  {
    start[d] = std::max<IndexValueType>(full.GetIndex()[d], lo[d] - 3);
    const IndexValueType end =
      std::min<IndexValueType>(full.GetIndex()[d] + static_cast<IndexValueType>(full.GetSize()[d]) - 1, hi[d] + 3);
    size[d] = static_cast<SizeValueType>(end - start[d] + 1);
  }
  auto roi = RegionOfInterestImageFilter<MaskType, MaskType>::New();
  roi->SetInput(mask);
  roi->SetRegionOfInterest(MaskType::RegionType(start, size));
  roi->Update();
  auto level = FaceCenteredLevelSet(roi->GetOutput());
  auto resampled = ResampleLinear(level, grid, gridToMask, std::numeric_limits<float>::max());
  ImageRegionConstIterator<ImageType> in(resampled, resampled->GetBufferedRegion());
  ImageRegionIterator<MaskType>       out(output, output->GetBufferedRegion());
  for (; !in.IsAtEnd(); ++in, ++out)
    out.Set(in.Get() <= 0.0f ? 1 : 0);
  return output;
}

void
MaskBoundingBox(const MaskType * mask, PointType & lower, PointType & upper,
                const PreAlignmentTransformType * frameToMask)
{
  MaskType::IndexType lo, hi;
  if (!InsideIndexBox(mask, lo, hi))
    Fail("cannot take the bounding box of an empty mask");
  PreAlignmentTransformType::InverseTransformBasePointer maskToFrame;
  if (frameToMask != nullptr)
    maskToFrame = frameToMask->GetInverseTransform();
  for (unsigned d = 0; d < Dimension; ++d)
  {
    lower[d] = std::numeric_limits<double>::max();
    upper[d] = std::numeric_limits<double>::lowest();
  }
  for (unsigned corner = 0; corner < 8; ++corner)
  {
    ContinuousIndex<double, Dimension> index;
    for (unsigned d = 0; d < Dimension; ++d)
      index[d] = (corner >> d & 1) ? hi[d] + 0.5 : lo[d] - 0.5;
    PointType p;
    mask->TransformContinuousIndexToPhysicalPoint(index, p);
    if (maskToFrame)
      p = maskToFrame->TransformPoint(p);
    for (unsigned d = 0; d < Dimension; ++d)
    {
      lower[d] = std::min(lower[d], p[d]);
      upper[d] = std::max(upper[d], p[d]);
    }
  }
}

std::string
LargestDeformingStructure(const RegistrationProblem & problem)
{
  std::string best;
  double      bestRatio = 0.0;
  for (const auto & s : problem.structures)
  {
    if (IsBodyName(s.name) || s.fixedMask.IsNull() || s.movingMask.IsNull())
      continue;
    const auto   volume = [](const MaskType * m) {
      const auto & sp = m->GetSpacing();
      return static_cast<double>(CountInside(m)) * sp[0] * sp[1] * sp[2];
    };
    const double vf = volume(s.fixedMask);
    const double vm = volume(s.movingMask);
    const double ratio = std::max(vf, vm) / std::max(1e-9, std::min(vf, vm));
    if (ratio > bestRatio)
    {
      bestRatio = ratio;
      best = s.name;
    }
  }
  return best;
}

ImageType::Pointer
ApplyIntensityWindow(const ImageType * image, const MaskType * foreground, float windowMin, float windowMax)
{
  if (!(windowMax > windowMin))
    Fail("intensity window maximum must exceed its minimum");
  if (foreground != nullptr && !SameGrid(image, foreground))
    Fail("intensity window: the foreground mask is not on the image grid");
  auto                                output = MakeImageOn<ImageType>(image);
  const float                         scale = (1.0f - ForegroundFloor) / (windowMax - windowMin);
  ImageRegionConstIterator<ImageType> in(image, image->GetBufferedRegion());
  ImageRegionIterator<ImageType>      out(output, output->GetBufferedRegion());
  if (foreground == nullptr)
  {
    for (; !in.IsAtEnd(); ++in, ++out)
      out.Set(ForegroundFloor + (std::clamp(in.Get(), windowMin, windowMax) - windowMin) * scale);
    return output;
  }
  ImageRegionConstIterator<MaskType> fg(foreground, foreground->GetBufferedRegion());
  for (; !in.IsAtEnd(); ++in, ++out, ++fg)
    out.Set(fg.Get() != 0 ? ForegroundFloor + (std::clamp(in.Get(), windowMin, windowMax) - windowMin) * scale : 0.0f);
  return output;
}

PointListType
ExtractSurfacePoints(const MaskType * mask)
{
  PointListType                                points;
  const auto                                   region = mask->GetBufferedRegion();
  ImageRegionConstIteratorWithIndex<MaskType> it(mask, region);
  for (; !it.IsAtEnd(); ++it)
  {
    if (it.Get() == 0)
      continue;
    const auto idx = it.GetIndex();
    bool       surface = false;
    for (unsigned d = 0; d < Dimension && !surface; ++d)
      for (int step : { -1, 1 })
      {
        auto n = idx;
        n[d] += step;
        if (!region.IsInside(n) || mask->GetPixel(n) == 0)
        {
          surface = true;
          break;
        }
      }
    if (surface)
    {
      PointType p;
      mask->TransformIndexToPhysicalPoint(idx, p);
      points.push_back(p);
    }
  }
  return points;
}

namespace
{
/** `image` with an identity direction when its direction is a signed
 *  permutation (axes stored flipped or swapped, as DICOM and NIfTI often
 *  are): the same voxels, reordered, so the steps that work in index space
 *  (the rigid stage's shrinking and sampling, bounding boxes) see the same
 *  image whichever way it was stored. Other images are returned as they are
 *  (an oblique direction would need interpolation). */
template <typename TImage>
typename TImage::Pointer
AxisAligned(const TImage * image)
{
  typename TImage::Pointer same(const_cast<TImage *>(image));
  if (image == nullptr)
    return same;
  const auto &                  direction = image->GetDirection();
  std::array<unsigned, Dimension> inputAxisOf{}; // output axis k runs along input axis inputAxisOf[k]
  std::array<bool, Dimension>     flipped{};
  bool                            identity = true;
  for (unsigned j = 0; j < Dimension; ++j)
  {
    unsigned nonZero = 0, k = 0;
    for (unsigned r = 0; r < Dimension; ++r)
      if (std::abs(direction(r, j)) > 1e-9)
      {
        ++nonZero;
        k = r;
      }
    if (nonZero != 1 || std::abs(std::abs(direction(k, j)) - 1.0) > 1e-6)
      return same; // oblique
    inputAxisOf[k] = j;
    flipped[j] = direction(k, j) < 0.0;
    identity = identity && k == j && !flipped[j];
  }
  if (identity)
    return same;
  const auto                    inSize = image->GetLargestPossibleRegion().GetSize();
  const auto                    inStart = image->GetLargestPossibleRegion().GetIndex();
  typename TImage::SizeType     size;
  typename TImage::SpacingType  spacing;
  typename TImage::IndexType    firstInput;
  for (unsigned k = 0; k < Dimension; ++k)
  {
    const unsigned j = inputAxisOf[k];
    size[k] = inSize[j];
    spacing[k] = image->GetSpacing()[j];
  }
  for (unsigned j = 0; j < Dimension; ++j)
    firstInput[j] = inStart[j] + (flipped[j] ? static_cast<IndexValueType>(inSize[j]) - 1 : 0);
  typename TImage::PointType origin;
  image->TransformIndexToPhysicalPoint(firstInput, origin);
  auto out = TImage::New();
  out->SetRegions(typename TImage::RegionType(size));
  out->SetSpacing(spacing);
  out->SetOrigin(origin);
  out->Allocate();
  ImageRegionIteratorWithIndex<TImage> it(out, out->GetLargestPossibleRegion());
  for (; !it.IsAtEnd(); ++it)
  {
    typename TImage::IndexType in;
    for (unsigned k = 0; k < Dimension; ++k)
    {
      const unsigned j = inputAxisOf[k];
      in[j] = flipped[j] ? firstInput[j] - it.GetIndex()[k] : firstInput[j] + it.GetIndex()[k];
    }
    it.Set(image->GetPixel(in));
  }
  return out;
}

/** More voxels than a preprocessed grid can reasonably hold (4 GiB of floats). */
constexpr double MaximumGridVoxels = 1.0e9;

/** The structure a parameter names; an error naming the key otherwise. */
const Structure &
NamedStructure(const RegistrationProblem & problem, const std::string & name, const char * key)
{
  std::string known;
  for (const auto & s : problem.structures)
  {
    if (s.name == name)
      return s;
    known += (known.empty() ? "" : ", ") + s.name;
  }
  Fail(std::string(key) + " = '" + name + "', but there is no structure called '" + name +
       "' (known: " + (known.empty() ? std::string("none") : known) + "); name one of them" +
       (std::string(key) == "preprocess_rigid_structure" ? ", give an initial transform, or set it to none" : ""));
}

/** The problem with every image and mask AxisAligned. */
RegistrationProblem
AxisAlignedProblem(const RegistrationProblem & input)
{
  RegistrationProblem out = input;
  out.fixedImage = AxisAligned(input.fixedImage.GetPointer());
  out.movingImage = AxisAligned(input.movingImage.GetPointer());
  out.fixedBodyMask = AxisAligned(input.fixedBodyMask.GetPointer());
  out.movingBodyMask = AxisAligned(input.movingBodyMask.GetPointer());
  for (auto & s : out.structures)
  {
    s.fixedMask = AxisAligned(s.fixedMask.GetPointer());
    s.movingMask = AxisAligned(s.movingMask.GetPointer());
  }
  return out;
}
/** Windowing images that are windowed already (IsWindowedAlready) with a
 *  window of Hounsfield units would squash them into a sliver of it and leave
 *  the intensity objective nearly flat: refused, with what to do instead. */
void
FailOnWindowedImages(const RegistrationProblem & problem, const PreprocessOptions & options)
{
  constexpr double NarrowestHounsfieldWindow = 100.0;
  if (options.windowMax - options.windowMin < NarrowestHounsfieldWindow || !IsWindowedAlready(problem))
    return;
  std::ostringstream window;
  window << "[" << options.windowMin << ", " << options.windowMax << "]";
  Fail("preprocessing: the images' values lie in [0, 1], as in a problem that `morea preprocess` (or a "
       "registration's preprocessed/ folder) holds, but the intensity window is " + window.str() +
       ": windowing them again would flatten them. Register the original images (registration preprocesses "
       "them itself), or set preprocess_intensity_min = 0 and preprocess_intensity_max = 1 for images "
       "normalised already.");
}
} // namespace

bool
IsWindowedAlready(const RegistrationProblem & problem)
{
  for (const ImageType * image : { problem.fixedImage.GetPointer(), problem.movingImage.GetPointer() })
  {
    auto range = MinimumMaximumImageCalculator<ImageType>::New();
    range->SetImage(image);
    range->Compute();
    if (range->GetMinimum() < 0.0f || range->GetMaximum() > 1.0f)
      return false;
  }
  return true;
}

PreprocessResult
Preprocess(const RegistrationProblem & given, const PreprocessOptions & options)
{
  const auto start = std::chrono::steady_clock::now();
  given.Validate();
  const RegistrationProblem input = AxisAlignedProblem(given);
  if (!(options.isotropicSpacing > 0.0))
    Fail("preprocessing: isotropic spacing must be positive");
  if (!(options.windowMax > options.windowMin))
    Fail("preprocessing: the intensity window maximum must exceed its minimum");
  FailOnWindowedImages(input, options);
  PreprocessResult result;
  auto &           report = result.report;

  // 1. Pre-alignment (moving onto fixed): the transform given, or rigid on the chosen structure.
  PreAlignmentTransformType::Pointer rigid = RigidTransformType::New();
  rigid->SetIdentity();
  if (options.initialTransform)
  {
    if (!options.initialTransform->GetInverseTransform())
      Fail(std::string("the initial moving transform (") + options.initialTransform->GetNameOfClass() +
           ") is not invertible");
    rigid = options.initialTransform->Clone();
    report.initialTransform = options.initialTransform->GetNameOfClass();
  }
  else if (!options.rigidStructure.empty() && options.rigidStructure != "none")
  {
    const Structure & s = NamedStructure(input, options.rigidStructure, "preprocess_rigid_structure");
    if (s.fixedMask.IsNull() || s.movingMask.IsNull())
      Fail("rigid pre-alignment structure '" + s.name + "' needs masks on both images");
    RigidAlignmentOptions rigidOptions;
    rigidOptions.intensityClampMin = std::max(options.windowMin, options.fieldOfViewThreshold);
    rigidOptions.intensityClampMax = options.windowMax;
    try
    {
      rigid = AlignRigidly(s.fixedMask, s.movingMask, rigidOptions, &report.rigid, input.fixedImage, input.movingImage);
    }
    catch (const ExceptionObject & e)
    {
      const std::string what = e.GetDescription();
      // ITK's v4 registration says so when the mask leaves it no sample point.
      const bool tooSmall = what.find("must have 1 or more points") != std::string::npos;
      Fail("rigid pre-alignment on '" + s.name + "' (preprocess_rigid_structure): " +
           (tooSmall ? "the structure is too small to align on these images; name a larger structure, give an "
                       "initial transform, or set preprocess_rigid_structure = none (" + what + ")"
                     : what));
    }
    report.rigidStructure = s.name;
  }
  result.rigidTransform = rigid;

  // 2. The crop box, in the fixed frame: union of the structure's boxes on both images, plus the margin.
  PointType lower, upper;
  {
    const auto & fixedRegion = input.fixedImage->GetLargestPossibleRegion();
    PointType    imageLower, imageUpper;
    auto         fixedAll = MaskType::New();
    fixedAll->CopyInformation(input.fixedImage);
    fixedAll->SetRegions(fixedRegion);
    fixedAll->Allocate();
    fixedAll->FillBuffer(1);
    MaskBoundingBox(fixedAll, imageLower, imageUpper);
    lower = imageLower;
    upper = imageUpper;
    report.cropStructure = options.cropStructure.empty() ? LargestDeformingStructure(input) : options.cropStructure;
    if (!report.cropStructure.empty())
    {
      const Structure & s = NamedStructure(input, report.cropStructure, "preprocess_crop_structure");
      if (s.fixedMask.IsNull() || s.movingMask.IsNull())
        Fail("crop structure '" + s.name + "' needs masks on both images");
      PointType fl, fu, ml, mu;
      MaskBoundingBox(s.fixedMask, fl, fu);
      MaskBoundingBox(s.movingMask, ml, mu, rigid);
      for (unsigned d = 0; d < Dimension; ++d)
      {
        lower[d] = std::max(imageLower[d], std::min(fl[d], ml[d]) - options.cropMargin);
        upper[d] = std::min(imageUpper[d], std::max(fu[d], mu[d]) + options.cropMargin);
      }
    }
  }

  // 3. One isotropic, axis-aligned grid for both images.
  auto                   grid = ImageType::New();
  ImageType::SizeType    size;
  ImageType::SpacingType spacing;
  ImageType::PointType   origin;
  for (unsigned d = 0; d < Dimension; ++d)
  {
    spacing[d] = options.isotropicSpacing;
    size[d] = std::max<SizeValueType>(1, static_cast<SizeValueType>(std::floor((upper[d] - lower[d]) / spacing[d] + 1e-6)));
    origin[d] = lower[d] + 0.5 * spacing[d];
  }
  // A wrong spacing in a header (metres for millimetres, say) makes the grid
  // astronomically large: refuse it with the figures, not an allocation failure.
  const double voxels = static_cast<double>(size[0]) * static_cast<double>(size[1]) * static_cast<double>(size[2]);
  if (voxels > MaximumGridVoxels)
  {
    char text[512];
    std::snprintf(text, sizeof text,
                  "the preprocessed grid would hold %.3g voxels (%.4g x %.4g x %.4g mm at %g mm); check the images' "
                  "spacing (fixed %g x %g x %g mm, moving %g x %g x %g mm), or raise preprocess_isotropic_spacing or "
                  "crop with preprocess_crop_structure",
                  voxels, upper[0] - lower[0], upper[1] - lower[1], upper[2] - lower[2], options.isotropicSpacing,
                  input.fixedImage->GetSpacing()[0], input.fixedImage->GetSpacing()[1],
                  input.fixedImage->GetSpacing()[2], input.movingImage->GetSpacing()[0],
                  input.movingImage->GetSpacing()[1], input.movingImage->GetSpacing()[2]);
    Fail(text);
  }
  grid->SetSpacing(spacing);
  grid->SetOrigin(origin);
  grid->SetRegions(ImageType::RegionType(size));
  report.size = size;
  report.spacing = options.isotropicSpacing;
  report.origin = origin;

  // 4. Images: one interpolation each; outside the original image is outside the field of view.
  const float outside = options.fieldOfViewThreshold - 1.0f;
  auto        fixedRaw = ResampleLinear(input.fixedImage, grid, nullptr, outside);
  auto        movingRaw = ResampleLinear(input.movingImage, grid, rigid, outside);

  const auto foregroundOf = [&](const ImageType * raw, const MaskType * bodyMask, const Structure * body,
                                bool fixedSide) {
    MaskType::Pointer fg = MakeImageOn<MaskType>(grid);
    MaskType::Pointer bodyOnGrid;
    const MaskType *  bodySource = bodyMask != nullptr ? bodyMask
                                   : body != nullptr   ? (fixedSide ? body->fixedMask.GetPointer() : body->movingMask.GetPointer())
                                                       : nullptr;
    if (bodySource != nullptr)
      bodyOnGrid = ResampleMask(bodySource, grid, fixedSide ? nullptr : rigid.GetPointer());
    ImageRegionConstIterator<ImageType> in(raw, raw->GetBufferedRegion());
    ImageRegionIterator<MaskType>       out(fg, fg->GetBufferedRegion());
    for (; !in.IsAtEnd(); ++in, ++out)
    {
      bool on = in.Get() >= options.fieldOfViewThreshold;
      if (on && bodyOnGrid)
        on = bodyOnGrid->GetPixel(out.GetIndex()) != 0;
      out.Set(on ? 1 : 0);
    }
    return fg;
  };
  const Structure * body = nullptr;
  for (const auto & s : input.structures)
    if (IsBodyName(s.name) && s.fixedMask && s.movingMask)
      body = &s;
  auto fixedForeground = foregroundOf(fixedRaw, input.fixedBodyMask, body, true);
  auto movingForeground = foregroundOf(movingRaw, input.movingBodyMask, body, false);

  RegistrationProblem & out = result.problem;
  out.fixedImage = ApplyIntensityWindow(fixedRaw, fixedForeground, options.windowMin, options.windowMax);
  out.movingImage = ApplyIntensityWindow(movingRaw, movingForeground, options.windowMin, options.windowMax);
  out.fixedBodyMask = fixedForeground;
  out.movingBodyMask = movingForeground;

  // 5. Structures: masks on the grid, surface points from the 3D masks.
  const auto movingToFrame = rigid->GetInverseTransform();
  for (const auto & s : input.structures)
  {
    Structure t;
    t.name = s.name;
    if (s.fixedMask)
      t.fixedMask = ResampleMask(s.fixedMask, grid);
    if (s.movingMask)
      t.movingMask = ResampleMask(s.movingMask, grid, rigid);
    const bool emptyFixed = t.fixedMask ? CountInside(t.fixedMask) == 0 : s.fixedPoints.empty();
    const bool emptyMoving = t.movingMask ? CountInside(t.movingMask) == 0 : s.movingPoints.empty();
    if (emptyFixed || emptyMoving)
    {
      report.droppedStructures.push_back(s.name);
      const std::string sides = emptyFixed && emptyMoving ? "fixed and moving masks have"
                                : emptyFixed              ? "fixed mask has"
                                                          : "moving mask has";
      char margin[32];
      std::snprintf(margin, sizeof margin, "%g mm", options.cropMargin);
      report.droppedReasons.push_back(
        "its " + sides + " no voxel inside " +
        (report.cropStructure.empty() ? std::string("the fixed image's domain after the rigid pre-alignment")
                                      : "the crop to '" + report.cropStructure + "' with a margin of " + margin));
      continue;
    }
    t.fixedPoints = t.fixedMask ? ExtractSurfacePoints(t.fixedMask) : s.fixedPoints;
    if (t.movingMask)
      t.movingPoints = ExtractSurfacePoints(t.movingMask);
    else
      for (const auto & p : s.movingPoints)
        t.movingPoints.push_back(movingToFrame->TransformPoint(p));
    out.structures.push_back(std::move(t));
  }

  // 6. Landmarks in the common frame.
  out.fixedLandmarks = input.fixedLandmarks;
  for (const auto & p : input.movingLandmarks)
    out.movingLandmarks.push_back(movingToFrame->TransformPoint(p));

  report.secondsTotal = SecondsSince(start);
  return result;
}

void
CheckGuidanceStructuresKept(const PreprocessReport & report, const morea_core::ParameterSet & parameters)
{
  const std::string &            selection = parameters.GetString("problem_guidance_selection");
  const bool                     all = selection == "-1";
  const std::vector<std::string> named = all ? std::vector<std::string>{} : morea_core::ParseNameList(selection);
  for (std::size_t i = 0; i < report.droppedStructures.size(); ++i)
  {
    const std::string & name = report.droppedStructures[i];
    if (all ? IsBodyName(name) : std::find(named.begin(), named.end(), name) == named.end())
      continue;
    const std::string why = i < report.droppedReasons.size() ? report.droppedReasons[i] : "it left the crop";
    Fail("structure '" + name + "' vanished in preprocessing: " + why +
         ", so the registration would run without it; crop to a region that holds it (preprocess_crop_structure, "
         "preprocess_crop_margin), or leave it out" +
         (all ? " (or name the structures to register in problem_guidance_selection)" : " of problem_guidance_selection"));
  }
}

} // namespace morea
} // namespace itk
