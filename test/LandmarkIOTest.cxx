// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of the landmark readers and writers (elastix point/index files, CSV).
#include "itkLandmarkIO.h"
#include "itkMOREAImageIO.h"

#include "ItkErrorSupport.h"
#include "TestScratchDir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

namespace fs = std::filesystem;
using namespace itk::morea;

namespace
{
using morea_test::ItkError;

fs::path
ScratchDir()
{
  return morea_test::TestScratchDir("LandmarkIO");
}

std::string
WriteText(const fs::path & path, const std::string & text)
{
  std::ofstream out(path, std::ios::binary);
  out << text;
  return path.string();
}

PointType
P(double x, double y, double z)
{
  PointType p;
  p[0] = x;
  p[1] = y;
  p[2] = z;
  return p;
}

void
ExpectPoints(const LandmarkListType & actual, const LandmarkListType & expected, double tolerance)
{
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t n = 0; n < actual.size(); ++n)
    for (unsigned d = 0; d < 3; ++d)
      EXPECT_NEAR(actual[n][d], expected[n][d], tolerance) << "point " << n << " coordinate " << d;
}

/** An image with origin (10, 20, 30), spacing (2, 3, 4) and the given direction. */
ImageType::Pointer
Reference(bool rotated)
{
  auto image = ImageType::New();
  image->SetRegions(ImageType::SizeType{ { 20, 20, 20 } });
  ImageType::SpacingType spacing;
  spacing[0] = 2.0;
  spacing[1] = 3.0;
  spacing[2] = 4.0;
  image->SetSpacing(spacing);
  image->SetOrigin(P(10.0, 20.0, 30.0));
  ImageType::DirectionType direction;
  direction.SetIdentity();
  if (rotated)
  {
    // 90 degrees about z: index axis i runs along +y, j along -x.
    direction[0][0] = 0.0;
    direction[0][1] = -1.0;
    direction[1][0] = 1.0;
    direction[1][1] = 0.0;
  }
  image->SetDirection(direction);
  return image;
}

std::string
SharedData(const std::string & relative)
{
  return (fs::path(MOREA_SHARED_DATA_DIR) / relative).string();
}
} // namespace

// ---------------------------------------------------------------------------
// Round trips
// ---------------------------------------------------------------------------

TEST(LandmarkIO, ElastixPointFileRoundTrip)
{
  const auto             dir = ScratchDir();
  const LandmarkListType points{ P(-36.351, -36.974, -1204.5), P(0.0, 1e-3, 123.456789), P(-0.5, 250.25, -3.75) };
  const auto             path = (dir / "points.txt").string();
  WriteElastixPointFile(points, path);
  std::ifstream in(path);
  std::string   first;
  long          count = 0;
  in >> first >> count;
  EXPECT_EQ(first, "point");
  EXPECT_EQ(count, 3);
  ExpectPoints(ReadLandmarks(path), points, 1e-6);
  // Atomic: only the final file remains.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(LandmarkIO, CsvRoundTrip)
{
  const auto             dir = ScratchDir();
  const LandmarkListType points{ P(1.5, -2.25, 3.0), P(-1000.125, 0.0, 42.0) };
  const auto             path = (dir / "sub" / "points.csv").string();
  WriteLandmarksCsv(points, path);
  std::ifstream in(path);
  std::string   header;
  std::getline(in, header);
  EXPECT_EQ(header, "x,y,z");
  ExpectPoints(ReadLandmarks(path), points, 1e-9);
}

// ---------------------------------------------------------------------------
// CSV variants
// ---------------------------------------------------------------------------

TEST(LandmarkIO, CsvWithoutHeader)
{
  const auto dir = ScratchDir();
  const auto path = WriteText(dir / "plain.csv", "1,2,3\n\n 4.5 , -5 , 6e1 \r\n# a comment\n7,8,9");
  ExpectPoints(ReadLandmarks(path), { P(1, 2, 3), P(4.5, -5, 60), P(7, 8, 9) }, 1e-12);
}

TEST(LandmarkIO, CsvWithNameColumnAndHeader)
{
  const auto dir = ScratchDir();
  const auto path = WriteText(dir / "named.csv", "name,x,y,z\nfemoral head,1,2,3\napex,-4,-5,-6\n");
  ExpectPoints(ReadLandmarks(path), { P(1, 2, 3), P(-4, -5, -6) }, 1e-12);
  // Columns in another order, upper case, with a unit suffix; extra trailing columns are ignored.
  const auto reordered = WriteText(dir / "reordered.csv", "id,Z_mm,X_mm,Y_mm,note\n1,30,10,20,top\n2,-3,-1,-2,low\n");
  ExpectPoints(ReadLandmarks(reordered), { P(10, 20, 30), P(-1, -2, -3) }, 1e-12);
}

TEST(LandmarkIO, CsvIsRecognisedByContentWithoutTheExtension)
{
  const auto dir = ScratchDir();
  const auto path = WriteText(dir / "points.txt", "1,2,3\n4,5,6\n");
  ExpectPoints(ReadLandmarks(path), { P(1, 2, 3), P(4, 5, 6) }, 1e-12);
}

TEST(LandmarkIO, BadCsvIsAnError)
{
  const auto dir = ScratchDir();
  const auto twoValues = WriteText(dir / "two.csv", "1,2,3\n4,5\n");
  const std::string message = ItkError([&] { ReadLandmarks(twoValues); });
  EXPECT_CONTAINS(message, twoValues);
  EXPECT_CONTAINS(message, "line 2");

  const auto text = WriteText(dir / "text.csv", "x,y,z\n1,2,3\n4,five,6\n");
  const std::string nonNumeric = ItkError([&] { ReadLandmarks(text); });
  EXPECT_CONTAINS(nonNumeric, "line 3");
  EXPECT_CONTAINS(nonNumeric, "coordinate y");

  const auto noXyz = WriteText(dir / "noxyz.csv", "name,a,b,c\np,1,2,3\n");
  EXPECT_CONTAINS(ItkError([&] { ReadLandmarks(noXyz); }), "x, y and z");

  const auto nameNoHeader = WriteText(dir / "nameonly.csv", "p1,1,2,3\n");
  EXPECT_THROW(ReadLandmarks(nameNoHeader), itk::ExceptionObject);

  const auto headerOnly = WriteText(dir / "header.csv", "x,y,z\n");
  EXPECT_CONTAINS(ItkError([&] { ReadLandmarks(headerOnly); }), "no points");

  const auto infinite = WriteText(dir / "inf.csv", "1,2,inf\n");
  EXPECT_THROW(ReadLandmarks(infinite), itk::ExceptionObject);

  const auto shortRow = WriteText(dir / "short.csv", "name,x,y,z\np,1,2\n");
  EXPECT_CONTAINS(ItkError([&] { ReadLandmarks(shortRow); }), "coordinate z");
}

// ---------------------------------------------------------------------------
// elastix files
// ---------------------------------------------------------------------------

TEST(LandmarkIO, IndexFileNeedsAReferenceImage)
{
  const auto dir = ScratchDir();
  const auto path = WriteText(dir / "index.txt", "index\n2\n1 2 3\n0 0 0\n");
  const std::string message = ItkError([&] { ReadLandmarks(path); });
  EXPECT_CONTAINS(message, path);
  EXPECT_CONTAINS(message, "image");

  // origin + spacing * index, identity direction.
  ExpectPoints(ReadLandmarks(path, Reference(false)), { P(12, 26, 42), P(10, 20, 30) }, 1e-9);
  // With a rotated direction: origin + D * (spacing * index) = (10 - 6, 20 + 2, 30 + 12).
  ExpectPoints(ReadLandmarks(path, Reference(true)), { P(4, 22, 42), P(10, 20, 30) }, 1e-9);
  // Fractional indices are allowed (continuous index).
  const auto fractional = WriteText(dir / "fractional.txt", "INDEX\n1\n0.5 0.5 0.25\n");
  ExpectPoints(ReadLandmarks(fractional, Reference(false)), { P(11, 21.5, 31) }, 1e-9);
}

TEST(LandmarkIO, PointFileIgnoresTheReferenceImage)
{
  const auto dir = ScratchDir();
  const auto path = WriteText(dir / "point.txt", "Point\n1\n1 2 3\n");
  ExpectPoints(ReadLandmarks(path, Reference(true)), { P(1, 2, 3) }, 1e-12);
  ExpectPoints(ReadLandmarks(path), { P(1, 2, 3) }, 1e-12);
}

TEST(LandmarkIO, WrongCountOrValuesAreErrors)
{
  const auto dir = ScratchDir();
  const auto tooFew = WriteText(dir / "few.txt", "point\n3\n1 2 3\n4 5 6\n");
  const std::string few = ItkError([&] { ReadLandmarks(tooFew); });
  EXPECT_CONTAINS(few, tooFew);
  EXPECT_CONTAINS(few, "point 3 of 3");

  const auto tooMany = WriteText(dir / "many.txt", "point\n1\n1 2 3\n4 5 6\n");
  EXPECT_CONTAINS(ItkError([&] { ReadLandmarks(tooMany); }), "more values");

  const auto incomplete = WriteText(dir / "incomplete.txt", "point\n2\n1 2 3\n4 5\n");
  EXPECT_CONTAINS(ItkError([&] { ReadLandmarks(incomplete); }), "point 2 of 2");

  const auto nonNumeric = WriteText(dir / "nonnumeric.txt", "point\n2\n1 2 3\n4 five 6\n");
  EXPECT_CONTAINS(ItkError([&] { ReadLandmarks(nonNumeric); }), "not numeric");

  const auto trailingGarbage = WriteText(dir / "garbage.txt", "point\n1\n1 2 3x\n");
  EXPECT_THROW(ReadLandmarks(trailingGarbage), itk::ExceptionObject);

  for (const std::string count : { "0", "-2", "two" })
  {
    const auto badCount = WriteText(dir / ("count" + count + ".txt"), "point\n" + count + "\n1 2 3\n");
    EXPECT_CONTAINS(ItkError([&] { ReadLandmarks(badCount); }), "count") << "count '" << count << "'";
  }
}

TEST(LandmarkIO, UnknownFormatAndMissingFileAreErrors)
{
  const auto dir = ScratchDir();
  const auto neither = WriteText(dir / "neither.txt", "points\n1\n1 2 3\n");
  EXPECT_CONTAINS(ItkError([&] { ReadLandmarks(neither); }), "neither");
  const auto missing = (dir / "missing.txt").string();
  EXPECT_CONTAINS(ItkError([&] { ReadLandmarks(missing); }), missing);
  const auto empty = WriteText(dir / "empty.csv", "");
  EXPECT_THROW(ReadLandmarks(empty), itk::ExceptionObject);
}

// ---------------------------------------------------------------------------
// Real data
// ---------------------------------------------------------------------------

TEST(LandmarkIO, RealPointFile)
{
  const std::string path = SharedData("lung-ct-pair/baseline_landmarks51_mm.txt");
  if (!fs::exists(path))
    GTEST_SKIP() << path << " is absent";
  const auto points = ReadLandmarks(path);
  ASSERT_EQ(points.size(), 51u);
  EXPECT_NEAR(points[0][0], -36.351, 1e-9);
  EXPECT_NEAR(points[0][1], -36.974, 1e-9);
  EXPECT_NEAR(points[0][2], -1204.5, 1e-9);
  EXPECT_NEAR(points[1][0], -65.037, 1e-9);
  EXPECT_NEAR(points[1][2], -1344.5, 1e-9);
}

TEST(LandmarkIO, RealIndexFileLiesInsideTheImage)
{
  const std::string imagePath = SharedData("lung-ct-pair/baseline.mha");
  const std::string path = SharedData("lung-ct-pair/baseline_landmarks10_index.txt");
  if (!fs::exists(imagePath) || !fs::exists(path))
    GTEST_SKIP() << "lung CT data are absent";
  EXPECT_THROW(ReadLandmarks(path), itk::ExceptionObject);
  const auto image = ReadImage(imagePath);
  const auto points = ReadLandmarks(path, image);
  ASSERT_EQ(points.size(), 10u);
  // First line "94 92 114": origin + spacing * index.
  EXPECT_NEAR(points[0][0], -153.827 + 94 * 1.366, 1e-6);
  EXPECT_NEAR(points[0][1], -150.352 + 92 * 1.366, 1e-6);
  EXPECT_NEAR(points[0][2], -1434.5 + 114 * 2.5, 1e-6);
  const auto size = image->GetLargestPossibleRegion().GetSize();
  for (std::size_t n = 0; n < points.size(); ++n)
  {
    itk::ContinuousIndex<double, 3> index;
    image->TransformPhysicalPointToContinuousIndex(points[n], index);
    for (unsigned d = 0; d < 3; ++d)
    {
      EXPECT_GE(index[d], -0.5) << "point " << n;
      EXPECT_LE(index[d], static_cast<double>(size[d]) - 0.5) << "point " << n;
      // Index files hold whole voxel indices: the round trip lands on an integer.
      EXPECT_NEAR(index[d], std::round(index[d]), 1e-6) << "point " << n;
    }
  }
}
