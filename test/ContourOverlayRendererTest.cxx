// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// PNG contour overlays: size, colours, orientation and failure behaviour.
#include "itkContourOverlayRenderer.h"

#include "itkImageFileReader.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkRGBPixel.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

using namespace itk::morea;
namespace fs = std::filesystem;

namespace
{
using RGBImageType = itk::Image<itk::RGBPixel<unsigned char>, 2>;

/** A folder per test, so tests run in parallel (ctest -j) never see each other's files. */
fs::path
OutputDir()
{
  const auto * info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path     dir = fs::path(MOREA_TEST_OUTPUT_DIR) / "contour-overlay" / info->name();
  fs::create_directories(dir);
  return dir;
}

// 40 x 30 x 20 voxels of 0.5 x 1 x 2 mm: 20 x 30 x 40 mm.
template <typename TImage>
typename TImage::Pointer
MakeVolume(const std::function<typename TImage::PixelType(const typename TImage::IndexType &)> & value)
{
  auto                       image = TImage::New();
  typename TImage::SizeType  size{ { 40, 30, 20 } };
  image->SetRegions(typename TImage::RegionType{ size });
  typename TImage::SpacingType spacing;
  spacing[0] = 0.5;
  spacing[1] = 1.0;
  spacing[2] = 2.0;
  image->SetSpacing(spacing);
  image->Allocate();
  for (itk::ImageRegionIteratorWithIndex<TImage> it(image, image->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
  {
    it.Set(value(it.GetIndex()));
  }
  return image;
}

MaskType::Pointer
BoxMask(long x0, long x1, long y0, long y1, long z0, long z1)
{
  return MakeVolume<MaskType>([=](const MaskType::IndexType & i) -> unsigned char {
    return i[0] >= x0 && i[0] < x1 && i[1] >= y0 && i[1] < y1 && i[2] >= z0 && i[2] < z1;
  });
}

/** Intensity ramp along x: -200 at x = 0, +190 at x = 39, 0 at x = 20. */
ImageType::Pointer
Ramp()
{
  return MakeVolume<ImageType>([](const ImageType::IndexType & i) { return static_cast<float>(10 * i[0] - 200); });
}

RGBImageType::Pointer
ReadPng(const fs::path & path)
{
  auto reader = itk::ImageFileReader<RGBImageType>::New();
  reader->SetFileName(path.string());
  reader->Update();
  return reader->GetOutput();
}

bool
Is(const itk::RGBPixel<unsigned char> & p, unsigned char r, unsigned char g, unsigned char b)
{
  return p[0] == r && p[1] == g && p[2] == b;
}

std::size_t
CountColor(const RGBImageType * image, unsigned char r, unsigned char g, unsigned char b, long row0, long row1)
{
  std::size_t n{ 0 };
  const auto  size = image->GetLargestPossibleRegion().GetSize();
  for (long y = row0; y < row1; ++y)
  {
    for (long x = 0; x < static_cast<long>(size[0]); ++x)
    {
      n += Is(image->GetPixel({ { x, y } }), r, g, b);
    }
  }
  return n;
}

bool
NoTemporaryFiles(const fs::path & dir)
{
  for (const auto & entry : fs::directory_iterator(dir))
  {
    if (entry.path().filename().string().find(".tmp") != std::string::npos)
    {
      return false;
    }
  }
  return true;
}
} // namespace

TEST(ContourOverlayRenderer, AxialRenderHasSquarePixelsContoursAndGrayInterior)
{
  const auto image = Ramp();
  const auto red = BoxMask(10, 30, 5, 15, 4, 12);
  const auto green = BoxMask(20, 36, 20, 28, 0, 20);
  SliceRenderOptions options;
  options.axis = SliceAxis::Axial;
  options.windowMin = -100.0f;
  options.windowMax = 100.0f;
  options.pixelsPerMm = 2.0;
  const fs::path path = OutputDir() / "axial.png";
  fs::remove(path);
  const long slice = RenderContourOverlay(
    image, { { red, { { 255, 0, 0 } }, "red" }, { green, { { 0, 255, 0 } }, "green" } }, options, path.string());
  // Slice through the first layer's centroid: z = 4..11 -> 7.5 -> 8.
  EXPECT_EQ(slice, 8);

  const auto png = ReadPng(path);
  // 20 mm x 30 mm at 2 px/mm: column c samples x index c, rows 2k and 2k + 1 sample y index k.
  const auto size = png->GetLargestPossibleRegion().GetSize();
  ASSERT_EQ(size[0], 40u);
  ASSERT_EQ(size[1], 60u);
  // Red box x 10..29, y 5..14 -> columns 10..29, rows 10..29; anterior (low y) is at the top.
  EXPECT_TRUE(Is(png->GetPixel({ { 10, 20 } }), 255, 0, 0));
  EXPECT_TRUE(Is(png->GetPixel({ { 29, 20 } }), 255, 0, 0));
  EXPECT_TRUE(Is(png->GetPixel({ { 20, 10 } }), 255, 0, 0));
  EXPECT_TRUE(Is(png->GetPixel({ { 20, 29 } }), 255, 0, 0));
  // Green box x 20..35, y 20..27 -> rows 40..55.
  EXPECT_TRUE(Is(png->GetPixel({ { 20, 45 } }), 0, 255, 0));
  EXPECT_TRUE(Is(png->GetPixel({ { 28, 40 } }), 0, 255, 0));
  EXPECT_TRUE(Is(png->GetPixel({ { 28, 55 } }), 0, 255, 0));
  // Interior pixels: windowed gray. Intensity 0 -> 127.5 -> 128; the ramp clips at both ends.
  EXPECT_TRUE(Is(png->GetPixel({ { 20, 20 } }), 128, 128, 128));
  EXPECT_TRUE(Is(png->GetPixel({ { 2, 2 } }), 0, 0, 0));
  EXPECT_TRUE(Is(png->GetPixel({ { 38, 2 } }), 255, 255, 255));
  EXPECT_TRUE(Is(png->GetPixel({ { 15, 20 } }), 64, 64, 64)); // -50 -> 63.75
  // Only the outline is drawn: the red perimeter at this resolution is 2 * 20 + 2 * 20 - 4 pixels.
  EXPECT_EQ(CountColor(png, 255, 0, 0, 0, 60), 76u);
  EXPECT_TRUE(NoTemporaryFiles(OutputDir()));
}

TEST(ContourOverlayRenderer, CoronalAndSagittalPutSuperiorOnTop)
{
  const auto image = Ramp();
  // A structure in the superior half (z 12..17 of 0..19) and one in the inferior half.
  const auto top = BoxMask(8, 32, 5, 25, 12, 18);
  const auto bottom = BoxMask(8, 32, 5, 25, 2, 6);
  SliceRenderOptions options;
  options.windowMin = -200.0f;
  options.windowMax = 200.0f;
  options.pixelsPerMm = 1.0;
  options.sliceIndex = 15;
  const std::vector<ContourLayer> layers{ { top, { { 255, 255, 0 } }, "top" }, { bottom, { { 0, 0, 255 } }, "bottom" } };
  for (const auto axis : { SliceAxis::Coronal, SliceAxis::Sagittal })
  {
    options.axis = axis;
    const fs::path path = OutputDir() / (axis == SliceAxis::Coronal ? "coronal.png" : "sagittal.png");
    EXPECT_EQ(RenderContourOverlay(image, layers, options, path.string()), 15);
    const auto png = ReadPng(path);
    const auto size = png->GetLargestPossibleRegion().GetSize();
    // Coronal: 20 mm (x) wide; sagittal: 30 mm (y) wide; both 40 mm (z) high.
    EXPECT_EQ(size[0], axis == SliceAxis::Coronal ? 20u : 30u);
    ASSERT_EQ(size[1], 40u);
    EXPECT_GT(CountColor(png, 255, 255, 0, 0, 20), 0u);
    EXPECT_EQ(CountColor(png, 255, 255, 0, 20, 40), 0u);
    EXPECT_GT(CountColor(png, 0, 0, 255, 20, 40), 0u);
    EXPECT_EQ(CountColor(png, 0, 0, 255, 0, 20), 0u);
  }
  // Sagittal: anterior (low y) on the left. A structure at y 0..9 lies in the left third.
  options.axis = SliceAxis::Sagittal;
  const auto anterior = BoxMask(0, 40, 0, 10, 0, 20);
  const fs::path path = OutputDir() / "sagittal-anterior.png";
  RenderContourOverlay(image, { { anterior, { { 255, 0, 255 } }, "" } }, options, path.string());
  const auto png = ReadPng(path);
  EXPECT_TRUE(Is(png->GetPixel({ { 9, 20 } }), 255, 0, 255));
  EXPECT_FALSE(Is(png->GetPixel({ { 20, 20 } }), 255, 0, 255));
}

TEST(ContourOverlayRenderer, BadInputsThrowAndLeaveNoFile)
{
  const auto image = Ramp();
  const auto mask = BoxMask(10, 30, 5, 15, 4, 12);
  SliceRenderOptions options;

  // A parent "folder" that is a regular file.
  const fs::path blocker = OutputDir() / "not-a-folder";
  {
    std::ofstream(blocker.string()) << "x";
  }
  const fs::path underFile = blocker / "render.png";
  EXPECT_THROW(RenderContourOverlay(image, { { mask, { { 255, 0, 0 } }, "" } }, options, underFile.string()),
               itk::ExceptionObject);
  EXPECT_FALSE(fs::exists(underFile));

  // Not a PNG name.
  const fs::path jpeg = OutputDir() / "render.jpg";
  fs::remove(jpeg);
  EXPECT_THROW(RenderContourOverlay(image, { { mask, { { 255, 0, 0 } }, "" } }, options, jpeg.string()),
               itk::ExceptionObject);
  EXPECT_FALSE(fs::exists(jpeg));

  const fs::path png = OutputDir() / "bad-inputs.png";
  fs::remove(png);
  // A mask on another grid, a slice beyond the image, an empty window, a null image.
  auto other = BoxMask(10, 30, 5, 15, 4, 12);
  MaskType::SpacingType spacing;
  spacing.Fill(1.0);
  other->SetSpacing(spacing);
  EXPECT_THROW(RenderContourOverlay(image, { { other, { { 255, 0, 0 } }, "" } }, options, png.string()),
               itk::ExceptionObject);
  SliceRenderOptions beyond;
  beyond.sliceIndex = 20;
  EXPECT_THROW(RenderContourOverlay(image, {}, beyond, png.string()), itk::ExceptionObject);
  SliceRenderOptions flat;
  flat.windowMin = flat.windowMax = 5.0f;
  EXPECT_THROW(RenderContourOverlay(image, {}, flat, png.string()), itk::ExceptionObject);
  EXPECT_THROW(RenderContourOverlay(nullptr, {}, options, png.string()), itk::ExceptionObject);
  EXPECT_THROW(RenderContourOverlay(image, { { nullptr, { { 255, 0, 0 } }, "" } }, options, png.string()),
               itk::ExceptionObject);
  EXPECT_FALSE(fs::exists(png));
  EXPECT_TRUE(NoTemporaryFiles(OutputDir()));
}

TEST(ContourOverlayRenderer, RendersAPhantomForVisualInspection)
{
  // A torso-like axial phantom: soft-tissue ellipse, two lungs, a bright
  // sternum at the front (low y = anterior in LPS) and a spine at the back.
  // The picture (output/contour-overlay/RendersAPhantomForVisualInspection/phantom-*.png) is meant to be looked at.
  auto image = ImageType::New();
  ImageType::SizeType size{ { 120, 90, 30 } };
  image->SetRegions(ImageType::RegionType{ size });
  ImageType::SpacingType spacing;
  spacing[0] = 3.0;
  spacing[1] = 3.0;
  spacing[2] = 5.0;
  image->SetSpacing(spacing);
  image->Allocate();
  const auto sq = [](double v) { return v * v; };
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
  {
    const double x = it.GetIndex()[0] * 3.0 - 180.0;
    const double y = it.GetIndex()[1] * 3.0 - 135.0;
    const double z = it.GetIndex()[2] * 5.0;
    float        v = -1000.0f;
    if (sq(x / 160.0) + sq(y / 110.0) <= 1.0)
    {
      v = 40.0f;
      if (sq((std::abs(x) - 70.0) / 50.0) + sq(y / 75.0) + sq((z - 80.0) / 120.0) <= 1.0)
      {
        v = -800.0f;
      }
      if (sq(x / 15.0) + sq((y + 95.0) / 8.0) <= 1.0 || sq(x / 18.0) + sq((y - 80.0) / 18.0) <= 1.0)
      {
        v = 700.0f;
      }
    }
    it.Set(v);
  }
  // The left lung (patient left = +x) and a slightly shifted copy of it.
  const auto lung = [&](double shift) {
    auto mask = MaskType::New();
    mask->SetRegions(image->GetLargestPossibleRegion());
    mask->SetSpacing(image->GetSpacing());
    mask->Allocate();
    for (itk::ImageRegionIteratorWithIndex<MaskType> it(mask, mask->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
    {
      const double x = it.GetIndex()[0] * 3.0 - 180.0 - shift;
      const double y = it.GetIndex()[1] * 3.0 - 135.0;
      const double z = it.GetIndex()[2] * 5.0;
      it.Set(sq((x - 70.0) / 50.0) + sq(y / 75.0) + sq((z - 80.0) / 120.0) <= 1.0);
    }
    return mask;
  };
  const auto reference = lung(0.0);
  const auto warped = lung(9.0);
  SliceRenderOptions options;
  options.windowMin = -1000.0f;
  options.windowMax = 400.0f;
  options.pixelsPerMm = 1.5;
  const std::vector<ContourLayer> layers{ { reference, { { 0, 255, 0 } }, "reference" },
                                          { warped, { { 255, 0, 0 } }, "warped" } };
  for (const auto axis : { SliceAxis::Axial, SliceAxis::Coronal, SliceAxis::Sagittal })
  {
    options.axis = axis;
    const auto name = std::string("phantom-") + (axis == SliceAxis::Axial ? "axial" : axis == SliceAxis::Coronal ? "coronal" : "sagittal") + ".png";
    RenderContourOverlay(image, layers, options, (OutputDir() / name).string());
    const auto png = ReadPng(OutputDir() / name);
    EXPECT_GT(CountColor(png, 255, 0, 0, 0, static_cast<long>(png->GetLargestPossibleRegion().GetSize()[1])), 0u);
  }
  // Axial, 540 x 405 pixels: column ~ (x + 181.5) * 1.5, row ~ (y + 136.5) * 1.5.
  const auto axial = ReadPng(OutputDir() / "phantom-axial.png");
  ASSERT_EQ(axial->GetLargestPossibleRegion().GetSize()[0], 540u);
  ASSERT_EQ(axial->GetLargestPossibleRegion().GetSize()[1], 405u);
  // The bright sternum (y = -95 mm, anterior) is near the top, the spine (y = +80 mm) near the bottom.
  EXPECT_GT(axial->GetPixel({ { 272, 62 } })[0], 200);
  EXPECT_GT(axial->GetPixel({ { 272, 324 } })[0], 200);
  EXPECT_LT(axial->GetPixel({ { 377, 204 } })[0], 80); // inside the left lung
  // Patient left (+x, the contoured lung) is on the viewer's right.
  std::size_t leftHalf{ 0 }, rightHalf{ 0 };
  for (long r = 0; r < 405; ++r)
  {
    for (long c = 0; c < 540; ++c)
    {
      if (Is(axial->GetPixel({ { c, r } }), 0, 255, 0))
      {
        (c < 272 ? leftHalf : rightHalf) += 1;
      }
    }
  }
  EXPECT_EQ(leftHalf, 0u);
  EXPECT_GT(rightHalf, 100u);
}
