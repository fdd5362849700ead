// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: PNG renders of a slice with structure contours.
 *
 *  The slice is sampled straight from the 3D image onto a square-pixel output
 *  grid (bilinear for intensities, nearest voxel for masks), so no 2D ITK
 *  pipeline is instantiated. Screen axes follow the radiological convention
 *  for LPS physical axes:
 *    axial    (constant z): columns run to +x (patient left),  rows to +y (posterior)
 *    coronal  (constant y): columns run to +x (patient left),  rows to -z (inferior)
 *    sagittal (constant x): columns run to +y (posterior),     rows to -z (inferior)
 *  i.e. the patient's right is on the viewer's left, anterior (axial) and
 *  superior (coronal, sagittal) are at the top.
 *=========================================================================*/
#include "itkContourOverlayRenderer.h"

#include "itkMOREAImageIO.h"

#include "itkImageFileWriter.h"
#include "itkRGBPixel.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

namespace fs = std::filesystem;

namespace itk
{
namespace morea
{
namespace
{
[[noreturn]] void
Fail(const std::string & message)
{
  itkGenericExceptionMacro(<< "contour overlay: " << message);
}

using RGBPixelType = RGBPixel<unsigned char>;
using RGBImageType = Image<RGBPixelType, 2>;

/** Largest output side, in pixels; guards against a mistyped pixelsPerMm. */
constexpr SizeValueType MaximumOutputSide = 16384;

/** One screen axis: which index axis it walks along and in which direction. */
struct ScreenAxis
{
  unsigned int indexAxis{ 0 };
  bool         reversed{ false }; ///< walk from the last index to the first
  SizeValueType voxels{ 1 };
  double        spacing{ 1.0 };
  SizeValueType pixels{ 1 };

  /** Continuous index along `indexAxis` at the centre of output pixel `p`. */
  double
  IndexAt(SizeValueType p) const
  {
    const double c = (static_cast<double>(p) + 0.5) * static_cast<double>(voxels) / static_cast<double>(pixels) - 0.5;
    return reversed ? static_cast<double>(voxels) - 1.0 - c : c;
  }
};

/** The in-plane index axis (of `first`, `second`) that best follows physical axis
 *  `physical` in direction `sign`, for images whose direction is a (signed) permutation. */
ScreenAxis
ChooseAxis(const ImageType * image, unsigned int first, unsigned int second, unsigned int physical, double sign)
{
  const auto & direction = image->GetDirection();
  const unsigned int axis =
    std::abs(direction[physical][first]) >= std::abs(direction[physical][second]) ? first : second;
  ScreenAxis screen;
  screen.indexAxis = axis;
  screen.reversed = direction[physical][axis] * sign < 0.0;
  screen.voxels = image->GetLargestPossibleRegion().GetSize()[axis];
  screen.spacing = image->GetSpacing()[axis];
  return screen;
}

std::string
LowerCaseExtension(const std::string & path)
{
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

long
CentroidSlice(const MaskType * mask, unsigned int axis)
{
  const auto   size = mask->GetLargestPossibleRegion().GetSize();
  const auto * buffer = mask->GetBufferPointer();
  double        sum{ 0.0 };
  SizeValueType count{ 0 };
  SizeValueType i{ 0 };
  for (SizeValueType z = 0; z < size[2]; ++z)
  {
    for (SizeValueType y = 0; y < size[1]; ++y)
    {
      for (SizeValueType x = 0; x < size[0]; ++x, ++i)
      {
        if (buffer[i] != 0)
        {
          const SizeValueType index[3]{ x, y, z };
          sum += static_cast<double>(index[axis]);
          ++count;
        }
      }
    }
  }
  if (count == 0)
  {
    return static_cast<long>(size[axis] / 2); // an empty structure: the middle slice
  }
  return std::lround(sum / static_cast<double>(count));
}
} // namespace

long
RenderContourOverlay(const ImageType *                 image,
                     const std::vector<ContourLayer> & layers,
                     const SliceRenderOptions &        options,
                     const std::string &               pngPath)
{
  if (image == nullptr || image->GetLargestPossibleRegion().GetNumberOfPixels() == 0)
  {
    Fail("the image is null or has no voxels");
  }
  if (image->GetBufferedRegion() != image->GetLargestPossibleRegion())
  {
    Fail("the image is not fully buffered");
  }
  for (std::size_t l = 0; l < layers.size(); ++l)
  {
    const std::string what = "layer " + std::to_string(l + 1) + (layers[l].label.empty() ? "" : " ('" + layers[l].label + "')");
    if (layers[l].mask == nullptr)
    {
      Fail(what + " has no mask");
    }
    if (!SameGrid(image, layers[l].mask) || layers[l].mask->GetBufferedRegion() != image->GetBufferedRegion())
    {
      Fail("the mask of " + what + " is not on the image's voxel grid");
    }
  }
  if (!(options.windowMax > options.windowMin))
  {
    Fail("the intensity window is empty (windowMax must exceed windowMin)");
  }
  if (!(options.pixelsPerMm > 0.0) || !std::isfinite(options.pixelsPerMm))
  {
    Fail("pixelsPerMm must be a positive number");
  }
  if (pngPath.empty() || LowerCaseExtension(pngPath) != ".png")
  {
    Fail("the output path '" + pngPath + "' must end in .png");
  }

  const auto         size = image->GetLargestPossibleRegion().GetSize();
  const unsigned int sliceAxis = static_cast<unsigned int>(options.axis);
  long               slice = options.sliceIndex;
  if (slice < 0)
  {
    slice = layers.empty() ? static_cast<long>(size[sliceAxis] / 2) : CentroidSlice(layers.front().mask, sliceAxis);
  }
  if (slice >= static_cast<long>(size[sliceAxis]))
  {
    Fail("slice " + std::to_string(slice) + " is outside the image (" + std::to_string(size[sliceAxis]) +
         " slices along that axis)");
  }

  // In-plane index axes and the physical axes the screen shows (see the file comment).
  const unsigned int first = sliceAxis == 0 ? 1 : 0;
  const unsigned int second = sliceAxis == 2 ? 1 : 2;
  ScreenAxis         columns;
  ScreenAxis         rows;
  switch (options.axis)
  {
    case SliceAxis::Axial:
      columns = ChooseAxis(image, first, second, 0, +1.0);
      rows = ChooseAxis(image, first, second, 1, +1.0);
      break;
    case SliceAxis::Coronal:
      columns = ChooseAxis(image, first, second, 0, +1.0);
      rows = ChooseAxis(image, first, second, 2, -1.0);
      break;
    case SliceAxis::Sagittal:
      columns = ChooseAxis(image, first, second, 1, +1.0);
      rows = ChooseAxis(image, first, second, 2, -1.0);
      break;
  }
  if (columns.indexAxis == rows.indexAxis)
  {
    // Strongly oblique directions: fall back to the plain index order.
    columns = ChooseAxis(image, first, first, 0, 0.0);
    columns.reversed = false;
    rows = ChooseAxis(image, second, second, 0, 0.0);
    rows.reversed = false;
  }
  for (auto * screen : { &columns, &rows })
  {
    const double pixels = std::round(static_cast<double>(screen->voxels) * screen->spacing * options.pixelsPerMm);
    if (pixels > static_cast<double>(MaximumOutputSide))
    {
      Fail("the render would be " + std::to_string(static_cast<long long>(pixels)) + " pixels wide (limit " +
           std::to_string(MaximumOutputSide) + "); lower pixelsPerMm");
    }
    screen->pixels = std::max<SizeValueType>(1, static_cast<SizeValueType>(pixels));
  }

  const SizeValueType width = columns.pixels;
  const SizeValueType height = rows.pixels;
  std::array<SizeValueType, Dimension> stride{ { 1, size[0], size[0] * size[1] } };
  const SizeValueType sliceOffset = static_cast<SizeValueType>(slice) * stride[sliceAxis];

  // Per output column/row: the two neighbouring voxels and the bilinear weight,
  // plus the nearest voxel for the masks.
  struct Tap
  {
    SizeValueType low, high, nearest;
    double        weight;
  };
  const auto makeTaps = [&](const ScreenAxis & screen) {
    std::vector<Tap> taps(screen.pixels);
    const auto       last = static_cast<double>(screen.voxels - 1);
    for (SizeValueType p = 0; p < screen.pixels; ++p)
    {
      const double c = std::clamp(screen.IndexAt(p), 0.0, last);
      const auto   low = static_cast<SizeValueType>(std::floor(c));
      const auto   high = std::min(low + 1, screen.voxels - 1);
      const auto   nearest = static_cast<SizeValueType>(std::lround(c));
      taps[p] = { low * stride[screen.indexAxis], high * stride[screen.indexAxis],
                  nearest * stride[screen.indexAxis], c - static_cast<double>(low) };
    }
    return taps;
  };
  const auto columnTaps = makeTaps(columns);
  const auto rowTaps = makeTaps(rows);

  auto render = RGBImageType::New();
  {
    RGBImageType::RegionType region;
    region.SetSize({ { width, height } });
    render->SetRegions(region);
    RGBImageType::SpacingType spacing;
    spacing.Fill(1.0 / options.pixelsPerMm);
    render->SetSpacing(spacing);
    render->Allocate();
  }
  RGBPixelType * out = render->GetBufferPointer();

  // Gray background: window the bilinearly sampled intensities to 8 bits.
  const float * voxels = image->GetBufferPointer();
  const double  windowWidth = static_cast<double>(options.windowMax) - options.windowMin;
  for (SizeValueType r = 0; r < height; ++r)
  {
    const Tap & rt = rowTaps[r];
    for (SizeValueType c = 0; c < width; ++c)
    {
      const Tap &  ct = columnTaps[c];
      const auto   at = [&](SizeValueType ro, SizeValueType co) { return static_cast<double>(voxels[sliceOffset + ro + co]); };
      const double top = (1.0 - ct.weight) * at(rt.low, ct.low) + ct.weight * at(rt.low, ct.high);
      const double bottom = (1.0 - ct.weight) * at(rt.high, ct.low) + ct.weight * at(rt.high, ct.high);
      const double value = (1.0 - rt.weight) * top + rt.weight * bottom;
      const auto   gray = static_cast<unsigned char>(std::clamp(std::round((value - options.windowMin) * 255.0 / windowWidth), 0.0, 255.0));
      out[r * width + c].Set(gray, gray, gray);
    }
  }

  // Contours: pixels inside the sampled mask with a 4-neighbour outside it (or
  // on the picture's edge), drawn in list order so later layers lie on top.
  std::vector<unsigned char> inside(width * height);
  for (const auto & layer : layers)
  {
    const auto * mask = layer.mask->GetBufferPointer();
    for (SizeValueType r = 0; r < height; ++r)
    {
      for (SizeValueType c = 0; c < width; ++c)
      {
        inside[r * width + c] = mask[sliceOffset + rowTaps[r].nearest + columnTaps[c].nearest] != 0;
      }
    }
    RGBPixelType color;
    color.Set(layer.color[0], layer.color[1], layer.color[2]);
    for (SizeValueType r = 0; r < height; ++r)
    {
      for (SizeValueType c = 0; c < width; ++c)
      {
        const SizeValueType p = r * width + c;
        if (!inside[p])
        {
          continue;
        }
        const bool boundary = r == 0 || c == 0 || r + 1 == height || c + 1 == width || !inside[p - 1] ||
                              !inside[p + 1] || !inside[p - width] || !inside[p + width];
        if (boundary)
        {
          out[p] = color;
        }
      }
    }
  }

  // Write under a temporary name, then rename, so a failed write leaves no PNG.
  const fs::path parent = fs::path(pngPath).parent_path();
  if (!parent.empty())
  {
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec)
    {
      Fail("cannot create folder '" + parent.string() + "': " + ec.message());
    }
  }
  const std::string temporary = TemporaryPathFor(pngPath);
  auto              writer = ImageFileWriter<RGBImageType>::New();
  writer->SetInput(render);
  writer->SetFileName(temporary);
  try
  {
    writer->Update();
  }
  catch (const ExceptionObject & e)
  {
    std::error_code ec;
    fs::remove(temporary, ec);
    Fail("cannot write '" + pngPath + "': " + e.GetDescription());
  }
  CommitFile(temporary, pngPath);
  return slice;
}

} // namespace morea
} // namespace itk
