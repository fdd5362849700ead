// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  Tests of the DICOM RT Structure Set import: rasterisation on synthetic
 *  grids, the real TCIA structure sets against the provided reference masks,
 *  and bad inputs.
 *=========================================================================*/
#include "itkMOREAImageIO.h"
#include "itkRTStructureSetIO.h"

#include "itkImageRegionConstIterator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace itk::morea;

namespace
{
const fs::path kDataDir = fs::path{ MOREA_SHARED_DATA_DIR } / "abdomen-cbct-pair";
const fs::path kOutputDir{ MOREA_TEST_OUTPUT_DIR };
const char *   kROINames[] = { "Bowel_sm_CBCT", "LUNG_L", "LUNG_R", "Stomach_duo_CBCT" };

/** A 20 x 20 x 5 grid, 2 mm slices, with the given direction. */
MaskType::Pointer
MakeGrid(const MaskType::DirectionType & direction)
{
  auto                 grid = MaskType::New();
  MaskType::RegionType region;
  region.SetSize({ { 20, 20, 5 } });
  grid->SetRegions(region);
  const double spacing[]{ 1.0, 1.0, 2.0 };
  const double origin[]{ -10.0, -10.0, 0.0 };
  grid->SetSpacing(spacing);
  grid->SetOrigin(origin);
  grid->SetDirection(direction);
  return grid;
}

/** An axis-aligned square in the grid's continuous-index space, as a physical polygon. */
PointListType
Square(const MaskType * grid, double from, double to, double slice)
{
  PointListType polygon;
  const std::initializer_list<std::pair<double, double>> corners{ { from, from }, { to, from }, { to, to }, { from, to } };
  for (const auto & [i, j] : corners)
  {
    itk::ContinuousIndex<double, Dimension> index;
    index[0] = i;
    index[1] = j;
    index[2] = slice;
    PointType p;
    grid->TransformContinuousIndexToPhysicalPoint(index, p);
    polygon.push_back(p);
  }
  return polygon;
}

/** Outer square covering voxel centres 3..12 (10 x 10) with an inner hole covering
 *  centres 6..9 (4 x 4) on slices 1..3: 84 voxels per slice. */
RTStructureROI
RingROI(const MaskType * grid)
{
  RTStructureROI roi;
  roi.name = "Ring";
  roi.number = 7;
  for (double k : { 1.0, 2.0, 3.1 }) // 3.1: a plane slightly off the slice centre still counts
  {
    roi.contours.push_back(Square(grid, 2.5, 12.5, k));
    roi.contours.push_back(Square(grid, 5.5, 9.5, k));
  }
  return roi;
}

std::size_t
Count(const MaskType * mask)
{
  std::size_t                                 n = 0;
  itk::ImageRegionConstIterator<MaskType> it(mask, mask->GetLargestPossibleRegion());
  for (; !it.IsAtEnd(); ++it)
  {
    n += it.Get() != 0;
  }
  return n;
}

double
Dice(const MaskType * a, const MaskType * b)
{
  std::size_t                                 na = 0, nb = 0, both = 0;
  itk::ImageRegionConstIterator<MaskType> ia(a, a->GetLargestPossibleRegion());
  itk::ImageRegionConstIterator<MaskType> ib(b, b->GetLargestPossibleRegion());
  for (; !ia.IsAtEnd(); ++ia, ++ib)
  {
    const bool inA = ia.Get() != 0;
    const bool inB = ib.Get() != 0;
    na += inA;
    nb += inB;
    both += inA && inB;
  }
  return na + nb == 0 ? 1.0 : 2.0 * static_cast<double>(both) / static_cast<double>(na + nb);
}

/** Extracts dicom.tar.xz once into the test output folder. The archive is unpacked
 *  into a private folder and renamed into place, so concurrent test processes never
 *  see a half-extracted tree. Returns the "dicom" folder, or empty if unavailable. */
fs::path
ExtractedDicom()
{
  const fs::path archive = kDataDir / "dicom.tar.xz";
  const fs::path target = kOutputDir / "dicom-extract";
  const fs::path marker = target / ".complete";
  if (!fs::exists(archive))
  {
    return {}; // no data: skip even when an old extraction is still around
  }
  if (fs::exists(marker))
  {
    return target / "dicom";
  }
  const fs::path staging = kOutputDir / ("dicom-extract.tmp" + std::to_string(::getpid()));
  fs::remove_all(staging);
  fs::create_directories(staging);
  const std::string command = "tar xJf '" + archive.string() + "' -C '" + staging.string() + "'";
  if (std::system(command.c_str()) != 0)
  {
    fs::remove_all(staging);
    ADD_FAILURE() << "cannot extract the test data: '" << command << "' failed";
    return {};
  }
  std::ofstream{ staging / ".complete" } << "extracted from " << archive.string() << '\n';
  std::error_code ec;
  if (!fs::exists(marker))
  {
    fs::remove_all(target, ec); // a stale, incomplete extraction
  }
  fs::rename(staging, target, ec);
  if (ec)
  {
    fs::remove_all(staging, ec); // another process won the race
  }
  return fs::exists(marker) ? target / "dicom" : fs::path{};
}

template <typename TCallable>
std::string
ThrownMessage(TCallable && call)
{
  try
  {
    call();
  }
  catch (const itk::ExceptionObject & e)
  {
    return e.GetDescription();
  }
  return {};
}

/** Reads one scan's DICOM series and RT Structure Set and checks them against the
 *  provided MetaImage conversion and reference masks. */
void
CheckRealScan(const std::string & scan)
{
  const fs::path dicom = ExtractedDicom();
  if (dicom.empty())
  {
    GTEST_SKIP() << "no test data at " << kDataDir;
  }

  // The DICOM series must give exactly the provided lossless conversion.
  const auto image = ReadImage((dicom / (scan + "_image")).string());
  const auto converted = ReadImage((kDataDir / (scan + ".mha")).string());
  ASSERT_TRUE(SameGrid(image, converted)) << scan << ": DICOM series and " << scan << ".mha differ in grid";
  double                                   maxDifference = 0.0;
  itk::ImageRegionConstIterator<ImageType> a(image, image->GetLargestPossibleRegion());
  itk::ImageRegionConstIterator<ImageType> b(converted, converted->GetLargestPossibleRegion());
  for (; !a.IsAtEnd(); ++a, ++b)
  {
    maxDifference = std::max(maxDifference, std::abs(static_cast<double>(a.Get()) - b.Get()));
  }
  EXPECT_LE(maxDifference, 1e-3) << scan << ": voxel values differ from " << scan << ".mha";

  // The folder form and the file form read the same structure set.
  const fs::path folder = dicom / (scan + "_rtstruct");
  const auto     rois = ReadRTStructureSet(folder.string());
  ASSERT_EQ(rois.size(), std::size(kROINames));
  const auto fromFile = ReadRTStructureSet(fs::directory_iterator(folder)->path().string());
  ASSERT_EQ(fromFile.size(), rois.size());

  for (const char * name : kROINames)
  {
    const auto & roi = FindROI(rois, name);
    EXPECT_FALSE(roi.contours.empty()) << name;
    EXPECT_EQ(FindROI(fromFile, name).contours.size(), roi.contours.size()) << name;
    EXPECT_GE(ContourPoints(roi).size(), 3 * roi.contours.size()) << name;

    const auto mask = RasterizeROI(roi, image);
    ASSERT_TRUE(SameGrid(mask, image)) << name;
    const auto   reference = ReadMask((kDataDir / (scan + "_masks") / (std::string{ name } + ".mha")).string());
    ASSERT_TRUE(SameGrid(mask, reference)) << name;
    const double dice = Dice(mask, reference);
    std::cout << "[ RTSTRUCT ] " << scan << ' ' << name << ": Dice " << dice << " (" << Count(mask)
              << " voxels rasterised, " << Count(reference) << " in the reference mask, " << roi.contours.size()
              << " contours)" << std::endl;
    EXPECT_GE(dice, 0.97) << scan << ' ' << name;
  }
}
} // namespace

TEST(RTStructureSetIO, RasterizeRingWithHole)
{
  MaskType::DirectionType identity;
  identity.SetIdentity();
  const auto grid = MakeGrid(identity);
  const auto roi = RingROI(grid);
  const auto mask = RasterizeROI(roi, grid);

  ASSERT_TRUE(SameGrid(mask, grid));
  EXPECT_EQ(Count(mask), 3u * (100u - 16u));
  for (itk::IndexValueType k = 0; k < 5; ++k)
  {
    const bool contoured = k >= 1 && k <= 3;
    EXPECT_EQ(mask->GetPixel({ { 3, 3, k } }), contoured ? 1 : 0) << "corner, slice " << k;
    EXPECT_EQ(mask->GetPixel({ { 12, 12, k } }), contoured ? 1 : 0) << "corner, slice " << k;
    EXPECT_EQ(mask->GetPixel({ { 2, 3, k } }), 0) << "outside, slice " << k;
    EXPECT_EQ(mask->GetPixel({ { 13, 12, k } }), 0) << "outside, slice " << k;
    for (itk::IndexValueType j = 6; j <= 9; ++j)
    {
      for (itk::IndexValueType i = 6; i <= 9; ++i)
      {
        EXPECT_EQ(mask->GetPixel({ { i, j, k } }), 0) << "hole voxel " << i << ',' << j << ',' << k;
      }
    }
    EXPECT_EQ(mask->GetPixel({ { 5, 5, k } }), contoured ? 1 : 0) << "ring voxel, slice " << k;
  }
  EXPECT_EQ(ContourPoints(roi).size(), 6u * 4u);
}

TEST(RTStructureSetIO, RasterizeOnRotatedGrid)
{
  // A grid rotated by 30 degrees about its slice axis: the fill happens in index space,
  // so the same index-space ring gives the same voxels.
  const double            angle = 30.0 * itk::Math::pi / 180.0;
  MaskType::DirectionType rotation;
  rotation.SetIdentity();
  rotation[0][0] = std::cos(angle);
  rotation[0][1] = -std::sin(angle);
  rotation[1][0] = std::sin(angle);
  rotation[1][1] = std::cos(angle);
  const auto grid = MakeGrid(rotation);
  const auto mask = RasterizeROI(RingROI(grid), grid);
  EXPECT_EQ(Count(mask), 3u * (100u - 16u));
  EXPECT_EQ(mask->GetPixel({ { 7, 7, 2 } }), 0);
  EXPECT_EQ(mask->GetPixel({ { 4, 7, 2 } }), 1);
}

TEST(RTStructureSetIO, RasterizeClipsAtGridBorder)
{
  MaskType::DirectionType identity;
  identity.SetIdentity();
  const auto     grid = MakeGrid(identity);
  RTStructureROI roi;
  roi.name = "Big";
  roi.contours.push_back(Square(grid, -30.5, 14.5, 0.0)); // reaches beyond the grid
  const auto mask = RasterizeROI(roi, grid);
  EXPECT_EQ(Count(mask), 15u * 15u); // centres 0..14 along both axes
}

TEST(RTStructureSetIO, Errors)
{
  MaskType::DirectionType identity;
  identity.SetIdentity();
  const auto grid = MakeGrid(identity);
  const auto roi = RingROI(grid);

  const std::vector<RTStructureROI> rois{ roi };
  EXPECT_EQ(&FindROI(rois, "Ring"), &rois.front());
  const std::string unknown = ThrownMessage([&] { FindROI(rois, "Liver"); });
  EXPECT_NE(unknown.find("Liver"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("Ring"), std::string::npos) << "should list the available names: " << unknown;

  RTStructureROI empty;
  empty.name = "Nothing";
  EXPECT_NE(ThrownMessage([&] { RasterizeROI(empty, grid); }).find("Nothing"), std::string::npos);

  RTStructureROI offGrid;
  offGrid.name = "Elsewhere";
  offGrid.contours.push_back(Square(grid, 2.5, 12.5, 9.0)); // beyond the last slice
  EXPECT_NE(ThrownMessage([&] { RasterizeROI(offGrid, grid); }).find("Elsewhere"), std::string::npos);

  RTStructureROI tiny;
  tiny.name = "Tiny";
  tiny.contours.push_back(Square(grid, 3.2, 3.8, 1.0)); // between voxel centres
  EXPECT_NE(ThrownMessage([&] { RasterizeROI(tiny, grid); }).find("no voxel"), std::string::npos);

  RTStructureROI tilted;
  tilted.name = "Tilted";
  tilted.contours.push_back(Square(grid, 2.5, 12.5, 1.0));
  tilted.contours.back()[2][2] += 3 * grid->GetSpacing()[2]; // one vertex three slices away
  EXPECT_NE(ThrownMessage([&] { RasterizeROI(tilted, grid); }).find("not parallel"), std::string::npos);
}

TEST(RTStructureSetIO, BadFiles)
{
  fs::create_directories(kOutputDir);
  const fs::path missing = kOutputDir / "no-such-rtstruct.dcm";
  std::string    message = ThrownMessage([&] { ReadRTStructureSet(missing.string()); });
  EXPECT_NE(message.find(missing.string()), std::string::npos) << message;

  const fs::path text = kOutputDir / "not-dicom.dcm";
  std::ofstream{ text } << "this is not a DICOM file\n";
  message = ThrownMessage([&] { ReadRTStructureSet(text.string()); });
  EXPECT_NE(message.find(text.string()), std::string::npos) << message;
  std::cout << "[ RTSTRUCT ] text file given as structure set: " << message << std::endl;

  const fs::path dicom = ExtractedDicom();
  if (dicom.empty())
  {
    GTEST_SKIP() << "no test data at " << kDataDir;
  }
  // A CT image slice is DICOM but not a structure set.
  const fs::path slice = *fs::directory_iterator(dicom / "CB02_image");
  message = ThrownMessage([&] { ReadRTStructureSet(slice.string()); });
  EXPECT_NE(message.find(slice.string()), std::string::npos) << message;
  EXPECT_NE(message.find("not a DICOM RT Structure Set"), std::string::npos) << message;
  std::cout << "[ RTSTRUCT ] CT slice given as structure set: " << message << std::endl;

  // A folder without any structure set.
  const fs::path folder = dicom / "CB02_image";
  message = ThrownMessage([&] { ReadRTStructureSet(folder.string()); });
  EXPECT_NE(message.find(folder.string()), std::string::npos) << message;
}

TEST(RTStructureSetIO, RealCB02) { CheckRealScan("CB02"); }

TEST(RTStructureSetIO, RealCB07) { CheckRealScan("CB07"); }
