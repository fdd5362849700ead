// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of the module's image reading, validation and (atomic) writing.
#include "itkMOREAImageIO.h"
#include "itkRegistrationProblem.h"

#include "itkImageFileWriter.h"
#include "itkImageRegionConstIterator.h"
#include "itkImageRegionIteratorWithIndex.h"

#include "ItkErrorSupport.h"
#include "TestScratchDir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace itk::morea;

namespace
{
using morea_test::ItkError;

fs::path
ScratchDir()
{
  return morea_test::TestScratchDir("ImageIO");
}

/** File names in `dir` (not recursive), hidden ones included. */
std::set<std::string>
Listing(const fs::path & dir)
{
  std::set<std::string> names;
  for (const auto & entry : fs::directory_iterator(dir))
    names.insert(entry.path().filename().string());
  return names;
}

template <typename TImage>
void
SetGeometry(TImage * image, const typename TImage::SizeType & size, bool rotated)
{
  image->SetRegions(typename TImage::RegionType(size));
  typename TImage::SpacingType spacing;
  spacing[0] = 0.75;
  spacing[1] = 1.25;
  spacing[2] = 2.5;
  typename TImage::PointType origin;
  origin[0] = -10.5;
  origin[1] = 20.25;
  origin[2] = 100.125;
  image->SetSpacing(spacing);
  image->SetOrigin(origin);
  typename TImage::DirectionType direction;
  direction.SetIdentity();
  if (rotated)
  {
    // 30 degrees about z.
    const double c = std::cos(M_PI / 6.0), s = std::sin(M_PI / 6.0);
    direction[0][0] = c;
    direction[0][1] = -s;
    direction[1][0] = s;
    direction[1][1] = c;
  }
  image->SetDirection(direction);
}

ImageType::Pointer
MakeImage(bool rotated = true, float offset = 0.0f)
{
  auto image = ImageType::New();
  SetGeometry(image.GetPointer(), ImageType::SizeType{ { 7, 6, 5 } }, rotated);
  image->Allocate();
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
  {
    const auto i = it.GetIndex();
    it.Set(static_cast<float>(i[0] + 10 * i[1] + 100 * i[2]) - 300.25f + offset);
  }
  return image;
}

template <typename TImage>
void
WriteWithItk(const TImage * image, const std::string & path, bool compress = false)
{
  auto writer = itk::ImageFileWriter<TImage>::New();
  writer->SetInput(image);
  writer->SetFileName(path);
  writer->SetUseCompression(compress);
  writer->Update();
}

void
WriteText(const fs::path & path, const std::string & text)
{
  std::ofstream out(path, std::ios::binary);
  out << text;
}

template <typename TA, typename TB>
void
ExpectSameGeometry(const TA * a, const TB * b, double tolerance)
{
  EXPECT_EQ(a->GetLargestPossibleRegion().GetSize(), b->GetLargestPossibleRegion().GetSize());
  for (unsigned d = 0; d < 3; ++d)
  {
    EXPECT_NEAR(a->GetSpacing()[d], b->GetSpacing()[d], tolerance) << "spacing " << d;
    EXPECT_NEAR(a->GetOrigin()[d], b->GetOrigin()[d], tolerance) << "origin " << d;
    for (unsigned e = 0; e < 3; ++e)
      EXPECT_NEAR(a->GetDirection()[d][e], b->GetDirection()[d][e], tolerance) << "direction " << d << "," << e;
  }
}

template <typename TImage>
void
ExpectSameValues(const TImage * a, const TImage * b)
{
  itk::ImageRegionConstIterator<TImage> ia(a, a->GetLargestPossibleRegion());
  itk::ImageRegionConstIterator<TImage> ib(b, b->GetLargestPossibleRegion());
  std::size_t                           differences = 0;
  for (; !ia.IsAtEnd() && !ib.IsAtEnd(); ++ia, ++ib)
    differences += !(ia.Get() == ib.Get());
  EXPECT_TRUE(ia.IsAtEnd() && ib.IsAtEnd());
  EXPECT_EQ(differences, 0u);
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

TEST(ImageIO, RoundTripPreservesGeometryAndValues)
{
  const auto dir = ScratchDir();
  const auto image = MakeImage();
  for (const std::string name : { "image.nii.gz", "image.nii", "image.mha", "image.nrrd" })
  {
    SCOPED_TRACE(name);
    const auto path = (dir / name).string();
    itk::morea::WriteImage(image, path);
    const auto read = ReadImage(path);
    ExpectSameGeometry(image.GetPointer(), read.GetPointer(), 1e-5);
    ExpectSameValues<ImageType>(image, read);
    EXPECT_TRUE(SameGrid(image, read));
  }
  // Only the final files are left: no temporary files.
  EXPECT_EQ(Listing(dir), (std::set<std::string>{ "image.nii.gz", "image.nii", "image.mha", "image.nrrd" }));
}

TEST(ImageIO, RoundTripOfTwoFileFormats)
{
  // Formats that keep header and data in two files must survive the temporary-name-then-rename write too.
  const auto dir = ScratchDir();
  const auto image = MakeImage();
  for (const std::string name : { "image.mhd", "pair.hdr", "header.nhdr" })
  {
    SCOPED_TRACE(name);
    const auto path = (dir / name).string();
    ASSERT_NO_THROW(itk::morea::WriteImage(image, path));
    ImageType::Pointer read;
    ASSERT_NO_THROW(read = ReadImage(path));
    ExpectSameGeometry(image.GetPointer(), read.GetPointer(), 1e-5);
    ExpectSameValues<ImageType>(image, read);
  }
  for (const auto & name : Listing(dir))
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << "temporary file left behind: " << name;
}

TEST(ImageIO, WriteCreatesParentFoldersAndOverwrites)
{
  const auto dir = ScratchDir();
  const auto path = (dir / "a" / "b" / "image.nii.gz").string();
  itk::morea::WriteImage(MakeImage(true, 0.0f), path);
  itk::morea::WriteImage(MakeImage(true, 1000.0f), path);
  const auto read = ReadImage(path);
  ImageType::IndexType index{ { 1, 2, 3 } };
  EXPECT_FLOAT_EQ(read->GetPixel(index), 1.0f + 20.0f + 300.0f - 300.25f + 1000.0f);
  EXPECT_EQ(Listing(dir / "a" / "b"), std::set<std::string>{ "image.nii.gz" });
}

TEST(ImageIO, MaskRoundTripAndNonZeroIsInside)
{
  const auto dir = ScratchDir();
  auto       mask = MaskType::New();
  SetGeometry(mask.GetPointer(), MaskType::SizeType{ { 8, 8, 4 } }, false);
  mask->Allocate(true);
  mask->SetPixel({ { 1, 2, 3 } }, 1);
  mask->SetPixel({ { 7, 7, 0 } }, 1);
  WriteMask(mask, (dir / "mask.nii.gz").string());
  const auto read = ReadMask((dir / "mask.nii.gz").string());
  ExpectSameGeometry(mask.GetPointer(), read.GetPointer(), 1e-5);
  ExpectSameValues<MaskType>(mask, read);

  // Any non-zero value (255, 0.5, -1) is inside and becomes 1.
  auto image = MakeImage(false);
  image->FillBuffer(0.0f);
  image->SetPixel({ { 0, 0, 0 } }, 255.0f);
  image->SetPixel({ { 1, 0, 0 } }, 0.5f);
  image->SetPixel({ { 2, 0, 0 } }, -1.0f);
  itk::morea::WriteImage(image, (dir / "probabilities.mha").string());
  const auto binary = ReadMask((dir / "probabilities.mha").string());
  EXPECT_EQ(binary->GetPixel({ { 0, 0, 0 } }), 1);
  EXPECT_EQ(binary->GetPixel({ { 1, 0, 0 } }), 1);
  EXPECT_EQ(binary->GetPixel({ { 2, 0, 0 } }), 1);
  EXPECT_EQ(binary->GetPixel({ { 3, 0, 0 } }), 0);
  std::size_t inside = 0;
  for (itk::ImageRegionConstIterator<MaskType> it(binary, binary->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
    inside += it.Get();
  EXPECT_EQ(inside, 3u);
  EXPECT_EQ(CountInside(binary), 3u);
  // Any non-zero mask value counts, the first and the last voxel included.
  mask->SetPixel({ { 0, 0, 0 } }, 255);
  mask->SetPixel({ { 7, 7, 3 } }, 2);
  EXPECT_EQ(CountInside(mask), 4u);
}

TEST(ImageIO, DisplacementFieldRoundTrip)
{
  const auto dir = ScratchDir();
  auto       field = DisplacementFieldType::New();
  SetGeometry(field.GetPointer(), DisplacementFieldType::SizeType{ { 5, 4, 3 } }, true);
  field->Allocate();
  for (itk::ImageRegionIteratorWithIndex<DisplacementFieldType> it(field, field->GetLargestPossibleRegion());
       !it.IsAtEnd(); ++it)
  {
    const auto           i = it.GetIndex();
    DisplacementVectorType v;
    v[0] = 0.125 * i[0];
    v[1] = -1.5 * i[1] + 0.1;
    v[2] = 1e-3 * i[2] - 7.0;
    it.Set(v);
  }
  for (const std::string name : { "field.nii.gz", "field.mha", "field.nrrd" })
  {
    SCOPED_TRACE(name);
    const auto path = (dir / name).string();
    WriteDisplacementField(field, path);
    const auto read = ReadDisplacementField(path);
    ExpectSameGeometry(field.GetPointer(), read.GetPointer(), 1e-5);
    itk::ImageRegionConstIterator<DisplacementFieldType> a(field, field->GetLargestPossibleRegion());
    itk::ImageRegionConstIterator<DisplacementFieldType> b(read, read->GetLargestPossibleRegion());
    double                                               worst = 0.0;
    for (; !a.IsAtEnd(); ++a, ++b)
      for (unsigned d = 0; d < 3; ++d)
        worst = std::max(worst, std::abs(a.Get()[d] - b.Get()[d]));
    EXPECT_LT(worst, 1e-12);
  }
}

TEST(ImageIO, ScalarImageIsNotADisplacementField)
{
  const auto dir = ScratchDir();
  const auto path = (dir / "scalar.nii.gz").string();
  itk::morea::WriteImage(MakeImage(), path);
  EXPECT_CONTAINS(ItkError([&] { ReadDisplacementField(path); }), path);
}

TEST(ImageIO, VectorImageIsNotAScalarImage)
{
  const auto dir = ScratchDir();
  auto       field = DisplacementFieldType::New();
  SetGeometry(field.GetPointer(), DisplacementFieldType::SizeType{ { 5, 4, 3 } }, false);
  field->Allocate();
  DisplacementVectorType v;
  v[0] = 1.0;
  v[1] = 2.0;
  v[2] = 3.0;
  field->FillBuffer(v);
  const auto path = (dir / "field.mha").string();
  WriteDisplacementField(field, path);
  EXPECT_CONTAINS(ItkError([&] { ReadImage(path); }), path);
}

TEST(ImageIO, LabelMapAndExtractLabel)
{
  const auto dir = ScratchDir();
  auto       labels = LabelMapType::New();
  SetGeometry(labels.GetPointer(), LabelMapType::SizeType{ { 6, 5, 4 } }, true);
  labels->Allocate(true);
  for (itk::ImageRegionIteratorWithIndex<LabelMapType> it(labels, labels->GetLargestPossibleRegion()); !it.IsAtEnd();
       ++it)
  {
    const auto i = it.GetIndex();
    it.Set(i[2] == 1 ? 2 : (i[0] == 0 ? 300 : 0)); // one slice of 2, one column face of 300
  }
  const auto path = (dir / "labels.nii.gz").string();
  WriteWithItk<LabelMapType>(labels, path, true);
  const auto read = ReadLabelMap(path);
  ExpectSameGeometry(labels.GetPointer(), read.GetPointer(), 1e-5);
  ExpectSameValues<LabelMapType>(labels, read);

  const auto two = ExtractLabel(read, 2, "bladder");
  const auto big = ExtractLabel(read, 300, "bones");
  std::size_t nTwo = 0, nBig = 0;
  for (itk::ImageRegionConstIterator<MaskType> it(two, two->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
    nTwo += it.Get();
  for (itk::ImageRegionConstIterator<MaskType> it(big, big->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
    nBig += it.Get();
  EXPECT_EQ(nTwo, 6u * 5u);
  EXPECT_EQ(nBig, 5u * 3u); // i == 0, k != 1
  EXPECT_TRUE(SameGrid(two, read));
  EXPECT_EQ(two->GetPixel({ { 3, 3, 1 } }), 1);
  EXPECT_EQ(two->GetPixel({ { 3, 3, 2 } }), 0);

  const std::string message = ItkError([&] { ExtractLabel(read, 7, "rectum in 'labels.nii.gz'"); });
  EXPECT_CONTAINS(message, "label 7");
  EXPECT_CONTAINS(message, "rectum in 'labels.nii.gz'");
}

TEST(ImageIO, ReadLabelNames)
{
  const auto dir = ScratchDir();
  WriteText(dir / "labels.txt", "# value name\n1 bladder  urine filled\n\n  2\trectum\r\n300 bones # comment\n");
  const auto names = ReadLabelNames((dir / "labels.txt").string());
  EXPECT_EQ(names, (std::map<std::string, unsigned int>{ { "bladder", 1 }, { "rectum", 2 }, { "bones", 300 } }));

  WriteText(dir / "bad-value.txt", "1 bladder\n0 background\n");
  const std::string zero = ItkError([&] { ReadLabelNames((dir / "bad-value.txt").string()); });
  EXPECT_CONTAINS(zero, "line 2");
  EXPECT_CONTAINS(zero, (dir / "bad-value.txt").string());
  WriteText(dir / "no-value.txt", "bladder 1\n");
  EXPECT_CONTAINS(ItkError([&] { ReadLabelNames((dir / "no-value.txt").string()); }), "line 1");
  WriteText(dir / "no-name.txt", "1 bladder\n\n2\n");
  EXPECT_CONTAINS(ItkError([&] { ReadLabelNames((dir / "no-name.txt").string()); }), "line 3");
  WriteText(dir / "too-large.txt", "70000 huge\n");
  EXPECT_THROW(ReadLabelNames((dir / "too-large.txt").string()), itk::ExceptionObject);
  EXPECT_CONTAINS(ItkError([&] { ReadLabelNames((dir / "missing.txt").string()); }), "missing.txt");
}

// ---------------------------------------------------------------------------
// Bad inputs
// ---------------------------------------------------------------------------

TEST(ImageIO, MissingFileNamesTheFile)
{
  const auto        dir = ScratchDir();
  const std::string path = (dir / "nothing-here.nii.gz").string();
  for (const auto & message : { ItkError([&] { ReadImage(path); }), ItkError([&] { ReadMask(path); }),
                                ItkError([&] { ReadLabelMap(path); }), ItkError([&] { ReadDisplacementField(path); }) })
  {
    EXPECT_CONTAINS(message, path);
    EXPECT_CONTAINS(message, "does not exist");
  }
}

TEST(ImageIO, TruncatedFileIsAnError)
{
  const auto dir = ScratchDir();
  auto       image = ImageType::New();
  image->SetRegions(ImageType::SizeType{ { 40, 40, 40 } });
  image->Allocate();
  unsigned state = 12345;
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
  {
    state = state * 1103515245u + 12345u;
    it.Set(static_cast<float>(state >> 16));
  }
  for (const std::string name : { "truncated.mha", "truncated.nrrd" })
  {
    SCOPED_TRACE(name);
    const auto path = dir / name;
    itk::morea::WriteImage(image, path.string()); // compressed
    ASSERT_NO_THROW(ReadImage(path.string()));
    const auto size = fs::file_size(path);
    fs::resize_file(path, size / 2);
    EXPECT_CONTAINS(ItkError([&] { ReadImage(path.string()); }), path.string());
  }
}

// Known defect: ITK 5.2's NIfTI reader (niftilib) reads a truncated .nii.gz without an error.
TEST(ImageIO, TruncatedNiftiIsAnError)
{
  const auto dir = ScratchDir();
  auto       image = MakeImage();
  for (const std::string name : { "truncated.nii.gz", "truncated.nii" })
  {
    SCOPED_TRACE(name);
    const auto path = dir / name;
    itk::morea::WriteImage(image, path.string());
    fs::resize_file(path, fs::file_size(path) / 2);
    EXPECT_CONTAINS(ItkError([&] { ReadImage(path.string()); }), path.string());
  }
}

TEST(ImageIO, TextFileWithImageExtensionIsAnError)
{
  const auto dir = ScratchDir();
  const auto path = dir / "notes.nii.gz";
  WriteText(path, "this is not an image\n");
  const std::string message = ItkError([&] { ReadImage(path.string()); });
  EXPECT_CONTAINS(message, path.string());
  EXPECT_CONTAINS(message, "cannot read");
  EXPECT_CONTAINS(ItkError([&] { ReadMask(path.string()); }), path.string());
}

TEST(ImageIO, ZeroSpacingIsAnError)
{
  const auto dir = ScratchDir();
  const auto path = dir / "zero-spacing.mha";
  {
    std::ofstream out(path, std::ios::binary);
    out << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
           "CompressedData = False\nTransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = 0 0 0\n"
           "ElementSpacing = 0 1 1\nDimSize = 2 2 2\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n";
    const float values[8] = { 1, 2, 3, 4, 5, 6, 7, 8 };
    out.write(reinterpret_cast<const char *>(values), sizeof(values));
  }
  const std::string message = ItkError([&] { ReadImage(path.string()); });
  EXPECT_CONTAINS(message, path.string());
  EXPECT_CONTAINS(message, "spacing");

  // The same header with a valid spacing reads fine (the crafted file is otherwise correct).
  const auto good = dir / "good-spacing.mha";
  {
    std::ofstream out(good, std::ios::binary);
    out << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
           "CompressedData = False\nTransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = 0 0 0\n"
           "ElementSpacing = 0.5 1 1\nDimSize = 2 2 2\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n";
    const float values[8] = { 1, 2, 3, 4, 5, 6, 7, 8 };
    out.write(reinterpret_cast<const char *>(values), sizeof(values));
  }
  const auto read = ReadImage(good.string());
  EXPECT_DOUBLE_EQ(read->GetSpacing()[0], 0.5);
  EXPECT_FLOAT_EQ(read->GetPixel({ { 1, 1, 1 } }), 8.0f);
}

TEST(ImageIO, NegativeSpacingIsAnError)
{
  const auto dir = ScratchDir();
  const auto path = dir / "negative-spacing.nrrd";
  {
    std::ofstream out(path, std::ios::binary);
    out << "NRRD0004\ntype: float\ndimension: 3\nspace: left-posterior-superior\nsizes: 2 2 2\n"
           "space directions: (-1,0,0) (0,1,0) (0,0,1)\nkinds: domain domain domain\nendian: little\n"
           "encoding: raw\nspace origin: (0,0,0)\n\n";
    const float values[8] = { 1, 2, 3, 4, 5, 6, 7, 8 };
    out.write(reinterpret_cast<const char *>(values), sizeof(values));
  }
  // A negative axis is a valid flipped direction, not an error: ITK reads it as spacing 1, direction -1.
  const auto read = ReadImage(path.string());
  EXPECT_GT(read->GetSpacing()[0], 0.0);
  EXPECT_DOUBLE_EQ(read->GetDirection()[0][0], -1.0);
}

TEST(ImageIO, NonFiniteVoxelsAreAnError)
{
  const auto dir = ScratchDir();
  auto       image = MakeImage();
  image->SetPixel({ { 1, 1, 1 } }, std::numeric_limits<float>::quiet_NaN());
  image->SetPixel({ { 2, 1, 1 } }, std::numeric_limits<float>::infinity());
  for (const std::string name : { "nan.mha", "nan.nrrd" })
  {
    SCOPED_TRACE(name);
    const auto path = (dir / name).string();
    itk::morea::WriteImage(image, path); // writing does not validate
    const std::string message = ItkError([&] { ReadImage(path); });
    EXPECT_CONTAINS(message, path);
    EXPECT_CONTAINS(message, "2 voxels are NaN or infinite");
    EXPECT_CONTAINS(ItkError([&] { ReadMask(path); }), "NaN");
  }
}

// Known defect: niftilib replaces non-finite float voxels by 0 while reading, so
// NaN in a NIfTI file goes unnoticed.
TEST(ImageIO, DISABLED_NonFiniteVoxelsInNiftiAreAnError)
{
  const auto dir = ScratchDir();
  auto       image = MakeImage();
  image->SetPixel({ { 1, 1, 1 } }, std::numeric_limits<float>::quiet_NaN());
  const auto path = (dir / "nan.nii.gz").string();
  itk::morea::WriteImage(image, path);
  EXPECT_CONTAINS(ItkError([&] { ReadImage(path); }), "NaN");
}

TEST(ImageIO, EmptyMaskIsAnError)
{
  const auto dir = ScratchDir();
  auto       mask = MaskType::New();
  SetGeometry(mask.GetPointer(), MaskType::SizeType{ { 4, 4, 4 } }, false);
  mask->Allocate(true);
  const auto path = (dir / "empty.nii.gz").string();
  WriteMask(mask, path);
  const std::string message = ItkError([&] { ReadMask(path); });
  EXPECT_CONTAINS(message, path);
  EXPECT_CONTAINS(message, "empty");
}

TEST(ImageIO, TwoDimensionalImageIsAnError)
{
  const auto dir = ScratchDir();
  using Image2D = itk::Image<float, 2>;
  auto image = Image2D::New();
  image->SetRegions(Image2D::SizeType{ { 8, 9 } });
  image->Allocate();
  image->FillBuffer(1.0f);
  for (const std::string name : { "slice.mha", "slice.nii.gz" })
  {
    SCOPED_TRACE(name);
    const auto path = (dir / name).string();
    WriteWithItk<Image2D>(image, path);
    const std::string message = ItkError([&] { ReadImage(path); });
    EXPECT_CONTAINS(message, path);
    EXPECT_CONTAINS(message, "2 dimensions, expected 3");
    EXPECT_CONTAINS(ItkError([&] { ReadMask(path); }), "2 dimensions");
    EXPECT_CONTAINS(ItkError([&] { ReadLabelMap(path); }), "2 dimensions");
  }
}

TEST(ImageIO, FolderWithoutDicomIsAnError)
{
  const auto dir = ScratchDir();
  fs::create_directories(dir / "empty-folder");
  const std::string message = ItkError([&] { ReadImage((dir / "empty-folder").string()); });
  EXPECT_CONTAINS(message, (dir / "empty-folder").string());
  // A folder where a mask file is expected.
  EXPECT_CONTAINS(ItkError([&] { ReadMask((dir / "empty-folder").string()); }), "is a directory");
}

TEST(ImageIO, ValidateImageChecksGeometry)
{
  auto image = MakeImage();
  EXPECT_NO_THROW(ValidateImage(image, "good"));
  EXPECT_NO_THROW(ValidateVoxels(image, "good"));
  EXPECT_CONTAINS(ItkError([] { ValidateImage(nullptr, "nothing"); }), "nothing");

  auto empty = ImageType::New();
  empty->SetRegions(ImageType::SizeType{ { 4, 0, 4 } });
  const std::string zero = ItkError([&] { ValidateImage(empty, "empty image"); });
  EXPECT_CONTAINS(zero, "empty image");
  EXPECT_CONTAINS(zero, "axis 1");

  auto                  nanOrigin = MakeImage();
  ImageType::PointType  origin = nanOrigin->GetOrigin();
  origin[2] = std::numeric_limits<double>::quiet_NaN();
  nanOrigin->SetOrigin(origin);
  EXPECT_CONTAINS(ItkError([&] { ValidateImage(nanOrigin, "nan origin"); }), "origin");

  // (An image with infinite spacing cannot even be built: ITK aborts in its index-to-point matrix.)
}

TEST(ImageIO, SameGridComparesSizeSpacingOriginDirection)
{
  const auto a = MakeImage();
  auto       b = MakeImage();
  EXPECT_TRUE(SameGrid(a, b));

  ImageType::PointType origin = a->GetOrigin();
  origin[1] += 1e-6; // far below the tolerance of 1e-4 spacing
  b->SetOrigin(origin);
  EXPECT_TRUE(SameGrid(a, b));
  origin[1] += 0.01; // 0.8% of the spacing 1.25
  b->SetOrigin(origin);
  EXPECT_FALSE(SameGrid(a, b));
  EXPECT_TRUE(SameGrid(a, b, 0.01));

  auto                   c = MakeImage();
  ImageType::SpacingType spacing = a->GetSpacing();
  spacing[2] *= 1.001;
  c->SetSpacing(spacing);
  EXPECT_FALSE(SameGrid(a, c));

  const auto unrotated = MakeImage(false);
  EXPECT_FALSE(SameGrid(a, unrotated));

  auto mask = MaskType::New();
  SetGeometry(mask.GetPointer(), MaskType::SizeType{ { 7, 6, 5 } }, true);
  EXPECT_TRUE(SameGrid(a, mask)); // pixel type does not matter
  auto other = MaskType::New();
  SetGeometry(other.GetPointer(), MaskType::SizeType{ { 7, 6, 6 } }, true);
  EXPECT_FALSE(SameGrid(a, other));
}

// ---------------------------------------------------------------------------
// Atomic writing
// ---------------------------------------------------------------------------

TEST(ImageIO, TemporaryPathKeepsFolderAndExtensions)
{
  const auto dir = ScratchDir();
  const auto finalPath = (dir / "result.nii.gz").string();
  const auto t1 = fs::path(TemporaryPathFor(finalPath));
  const auto t2 = fs::path(TemporaryPathFor(finalPath));
  EXPECT_NE(t1, t2);
  EXPECT_EQ(t1.parent_path(), dir);
  const std::string name = t1.filename().string();
  EXPECT_EQ(name.front(), '.');
  ASSERT_GE(name.size(), 7u);
  EXPECT_EQ(name.substr(name.size() - 7), ".nii.gz");
  EXPECT_NE(t1.string(), finalPath);
  EXPECT_EQ(fs::path(TemporaryPathFor("noextension")).parent_path(), fs::path());
}

TEST(ImageIO, WriteTextFileIsAtomicAndReplaces)
{
  const auto dir = ScratchDir();
  const auto path = dir / "sub" / "notes.txt";
  WriteTextFile("first\n", path.string());
  WriteTextFile("second line\nthird\n", path.string());
  std::ifstream     in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "second line\nthird\n");
  EXPECT_EQ(Listing(dir / "sub"), std::set<std::string>{ "notes.txt" });
}

TEST(ImageIO, FailedWritesLeaveNoFileBehind)
{
  const auto dir = ScratchDir();
  WriteText(dir / "plain-file", "I am a file, not a folder\n");
  const auto underFile = (dir / "plain-file" / "image.nii.gz").string();
  EXPECT_CONTAINS(ItkError([&] { itk::morea::WriteImage(MakeImage(), underFile); }), "plain-file");
  EXPECT_THROW(WriteTextFile("text", (dir / "plain-file" / "notes.txt").string()), itk::ExceptionObject);
  EXPECT_THROW(WriteMask(MaskType::New(), (dir / "plain-file" / "mask.nii.gz").string()), itk::ExceptionObject);

  // No writer for the extension: the temporary file must be removed too.
  const auto unknown = (dir / "image.unknown-format").string();
  EXPECT_CONTAINS(ItkError([&] { itk::morea::WriteImage(MakeImage(), unknown); }), unknown);

  EXPECT_EQ(Listing(dir), std::set<std::string>{ "plain-file" });
  EXPECT_TRUE(fs::is_regular_file(dir / "plain-file"));
}

TEST(ImageIO, FailedOverwriteKeepsTheOldFile)
{
  const auto dir = ScratchDir();
  const auto path = (dir / "keep.nii.gz").string();
  itk::morea::WriteImage(MakeImage(true, 0.0f), path);
  // An image with no buffer cannot be written: the write fails, the old file stays intact.
  auto broken = ImageType::New();
  EXPECT_THROW(itk::morea::WriteImage(broken, path), itk::ExceptionObject);
  const auto read = ReadImage(path);
  ExpectSameValues<ImageType>(MakeImage(true, 0.0f), read);
  EXPECT_EQ(Listing(dir), std::set<std::string>{ "keep.nii.gz" });
}

TEST(ImageIO, CommitFileFailsForAMissingTemporary)
{
  const auto dir = ScratchDir();
  EXPECT_THROW(CommitFile((dir / "nope.tmp").string(), (dir / "final.txt").string()), itk::ExceptionObject);
  EXPECT_FALSE(fs::exists(dir / "final.txt"));
}

// ---------------------------------------------------------------------------
// Real data
// ---------------------------------------------------------------------------

TEST(ImageIO, ReadsTheRealLungCT)
{
  const std::string path = SharedData("lung-ct-pair/baseline.mha");
  if (!fs::exists(path))
    GTEST_SKIP() << path << " is absent";
  const auto image = ReadImage(path);
  const auto size = image->GetLargestPossibleRegion().GetSize();
  EXPECT_EQ(size[0], 115u);
  EXPECT_EQ(size[1], 157u);
  EXPECT_EQ(size[2], 129u);
  EXPECT_NEAR(image->GetSpacing()[0], 1.366, 1e-9);
  EXPECT_NEAR(image->GetSpacing()[1], 1.366, 1e-9);
  EXPECT_NEAR(image->GetSpacing()[2], 2.5, 1e-9);
  EXPECT_NEAR(image->GetOrigin()[0], -153.827, 1e-9);
  EXPECT_NEAR(image->GetOrigin()[1], -150.352, 1e-9);
  EXPECT_NEAR(image->GetOrigin()[2], -1434.5, 1e-9);
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  for (itk::ImageRegionConstIterator<ImageType> it(image, image->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
  {
    lo = std::min(lo, it.Get());
    hi = std::max(hi, it.Get());
  }
  EXPECT_LT(lo, -900.0f); // air / lung in HU
  EXPECT_GT(hi, 100.0f);  // bone

  const std::string maskPath = SharedData("lung-ct-pair/baseline_lung_mask.mha");
  if (fs::exists(maskPath))
  {
    const auto mask = ReadMask(maskPath);
    EXPECT_TRUE(SameGrid(image, mask));
  }
}

// ---------------------------------------------------------------------------
// Loading a problem's structures side by side
// ---------------------------------------------------------------------------

namespace
{
/** A problem folder: two images, a label map with names, a mask, a point file. */
struct StructureFiles
{
  fs::path dir;
  std::vector<RegistrationProblem::StructureSource> sources;

  StructureFiles()
    : dir(ScratchDir())
  {
    const auto image = MakeImage(false);
    WriteWithItk<ImageType>(image, (dir / "fixed.mha").string());
    WriteWithItk<ImageType>(MakeImage(false, 5.0f), (dir / "moving.mha").string());
    auto labels = LabelMapType::New();
    SetGeometry(labels.GetPointer(), LabelMapType::SizeType{ { 7, 6, 5 } }, false);
    labels->Allocate(true);
    for (itk::ImageRegionIteratorWithIndex<LabelMapType> it(labels, labels->GetLargestPossibleRegion()); !it.IsAtEnd();
         ++it)
      it.Set(it.GetIndex()[2] == 1 ? 2 : (it.GetIndex()[0] == 0 ? 300 : 0));
    WriteWithItk<LabelMapType>(labels, (dir / "labels.mha").string(), true);
    WriteText(dir / "labels.txt", "2 bladder\n300 bones\n");
    auto mask = MaskType::New();
    SetGeometry(mask.GetPointer(), MaskType::SizeType{ { 7, 6, 5 } }, false);
    mask->Allocate(true);
    for (itk::ImageRegionIteratorWithIndex<MaskType> it(mask, mask->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
      it.Set(it.GetIndex()[1] >= 3 ? 1 : 0);
    WriteWithItk<MaskType>(mask, (dir / "bladder_mask.mha").string());
    WriteText(dir / "bladder_points.txt", "point\n2\n-8.25 23.375 105.125\n-7.5 24.0 106.0\n");
    const std::string labelPath = (dir / "labels.mha").string();
    sources = { { "bladder", true, labelPath + ":bladder" },
                { "bones", true, labelPath + ":300" },
                { "bladder", false, (dir / "bladder_mask.mha").string() },
                { "bones", false, labelPath + ":bones" },
                { "bladder", false, (dir / "bladder_points.txt").string() } };
  }

  RegistrationProblem
  Images() const
  {
    RegistrationProblem problem;
    problem.LoadImages((dir / "fixed.mha").string(), (dir / "moving.mha").string());
    return problem;
  }
};

void
ExpectSameMask(const MaskType * a, const MaskType * b, const std::string & what)
{
  ASSERT_EQ(a == nullptr, b == nullptr) << what;
  if (a == nullptr)
    return;
  ASSERT_TRUE(SameGrid(a, b)) << what;
  itk::ImageRegionConstIterator<MaskType> ia(a, a->GetLargestPossibleRegion()), ib(b, b->GetLargestPossibleRegion());
  std::size_t                             differ = 0, inside = 0;
  for (; !ia.IsAtEnd(); ++ia, ++ib)
  {
    differ += ia.Get() != ib.Get();
    inside += ia.Get() != 0;
  }
  EXPECT_EQ(differ, 0u) << what;
  EXPECT_GT(inside, 0u) << what;
}
} // namespace

// Loading all sides at once gives what loading them one at a time gives:
// the same structures in the same order, masks, and points (a point file
// after a mask adds its points to the side).
TEST(RegistrationProblemLoading, StructuresAtOnceMatchOneAtATime)
{
  const StructureFiles files;
  RegistrationProblem  serial = files.Images();
  for (const auto & s : files.sources)
    serial.LoadStructure(s.name, s.fixedSide, s.source);
  RegistrationProblem together = files.Images();
  together.LoadStructures(files.sources);
  ExpectSameValues<ImageType>(serial.fixedImage, together.fixedImage);
  ExpectSameValues<ImageType>(serial.movingImage, together.movingImage);
  EXPECT_EQ(together.movingImage->GetPixel({ { 0, 0, 0 } }), serial.fixedImage->GetPixel({ { 0, 0, 0 } }) + 5.0f);
  ASSERT_EQ(together.structures.size(), 2u);
  ASSERT_EQ(serial.structures.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i)
  {
    const Structure & a = serial.structures[i];
    const Structure & b = together.structures[i];
    EXPECT_EQ(a.name, b.name);
    ExpectSameMask(a.fixedMask, b.fixedMask, a.name + " fixed");
    ExpectSameMask(a.movingMask, b.movingMask, a.name + " moving");
    EXPECT_EQ(a.fixedPoints.size(), b.fixedPoints.size());
    ASSERT_EQ(a.movingPoints.size(), b.movingPoints.size());
    for (std::size_t k = 0; k < a.movingPoints.size(); ++k)
      EXPECT_EQ(a.movingPoints[k], b.movingPoints[k]);
  }
  EXPECT_EQ(together.GetStructure("bladder").movingPoints.size(), 2u);
  EXPECT_TRUE(together.GetStructure("bladder").movingMask.IsNotNull()) << "the points kept the mask";
  EXPECT_NO_THROW(together.Validate());
}

// The first failing source in the given order is the one reported, with
// its structure's name and side, however the reads finish.
TEST(RegistrationProblemLoading, TheFirstFailingSourceIsReported)
{
  const StructureFiles files;
  auto                 sources = files.sources;
  sources.insert(sources.begin() + 1, { "rectum", false, (files.dir / "labels.mha").string() + ":7" });
  sources.push_back({ "liver", true, (files.dir / "nowhere.mha").string() });
  RegistrationProblem problem = files.Images();
  const std::string   message = ItkError([&] { problem.LoadStructures(sources); });
  EXPECT_CONTAINS(message, "structure 'rectum' (moving)");
  EXPECT_CONTAINS(message, "label 7");
  sources.erase(sources.begin() + 1);
  RegistrationProblem again = files.Images();
  EXPECT_CONTAINS(ItkError([&] { again.LoadStructures(sources); }), "nowhere.mha");
  RegistrationProblem noImages;
  EXPECT_CONTAINS(ItkError([&] { noImages.LoadStructures(files.sources); }), "before its structures");
}
