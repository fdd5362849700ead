// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Inputs whose data or geometry are not what their header says are refused
// with what was measured: MetaImage files with more or less voxel data than
// DimSize describes (raw and compressed; ITK pads a short compressed stream
// with zeros), DICOM series with unevenly spaced or missing slices, and
// direction matrices that are not orthonormal.
#include "itkMOREAImageIO.h"

#include "itkGDCMImageIO.h"
#include "itkImageFileWriter.h"
#include "itkMetaDataObject.h"

#include "ItkErrorSupport.h"
#include "TestScratchDir.h"

#include <gtest/gtest.h>

#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace itk::morea;

namespace
{
using morea_test::ItkError;

std::string
MetaHeader(const std::string & dimSize, bool compressed, long long compressedSize = -1,
           const std::string & matrix = "1 0 0 0 1 0 0 0 1")
{
  std::string h = "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n";
  h += std::string("CompressedData = ") + (compressed ? "True" : "False") + "\n";
  if (compressedSize >= 0)
    h += "CompressedDataSize = " + std::to_string(compressedSize) + "\n";
  h += "TransformMatrix = " + matrix + "\nOffset = 0 0 0\nElementSpacing = 1 1 1\nDimSize = " + dimSize +
       "\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n";
  return h;
}

std::string
Floats(std::size_t n)
{
  std::vector<float> values(n);
  for (std::size_t i = 0; i < n; ++i)
    values[i] = static_cast<float>(i % 17);
  return std::string(reinterpret_cast<const char *>(values.data()), n * sizeof(float));
}

std::string
Deflated(const std::string & bytes)
{
  uLongf      size = compressBound(static_cast<uLong>(bytes.size()));
  std::string out(size, '\0');
  compress2(reinterpret_cast<Bytef *>(&out[0]), &size, reinterpret_cast<const Bytef *>(bytes.data()),
            static_cast<uLong>(bytes.size()), 6);
  out.resize(size);
  return out;
}

void
Write(const fs::path & path, const std::string & bytes)
{
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(InputGeometry, MetaImageDataMustMatchDimSize)
{
  const auto dir = morea_test::TestScratchDir("InputGeometry");
  const std::string whole = Floats(4 * 4 * 4), part = Floats(40), more = Floats(80);

  // The good files read, raw and compressed.
  Write(dir / "raw.mha", MetaHeader("4 4 4", false) + whole);
  EXPECT_NO_THROW(ReadImage((dir / "raw.mha").string()));
  const std::string packed = Deflated(whole);
  Write(dir / "compressed.mha", MetaHeader("4 4 4", true, static_cast<long long>(packed.size())) + packed);
  EXPECT_NO_THROW(ReadImage((dir / "compressed.mha").string()));
  EXPECT_NO_THROW(ReadMask((dir / "compressed.mha").string()));

  // Compressed, with less data than DimSize: ITK would pad it with zeros.
  const std::string short_ = Deflated(part);
  for (const long long declared : { static_cast<long long>(short_.size()), -1LL })
  {
    const auto path = dir / ("short" + std::to_string(declared) + ".mha");
    Write(path, MetaHeader("4 4 4", true, declared) + short_);
    const std::string message = ItkError([&] { ReadImage(path.string()); });
    EXPECT_CONTAINS(message, "image '" + path.string() + "' holds another amount of voxel data than its header "
                                                         "describes: DimSize 4 4 4 of MET_FLOAT needs 256 bytes, its "
                                                         "compressed data hold 160 (ITK would fill the rest with "
                                                         "zeros); fix DimSize or ElementType, or write the image again");
    EXPECT_CONTAINS(ItkError([&] { ReadMask(path.string()); }), "mask '" + path.string() + "' holds another amount");
  }
  // Compressed, with more data than DimSize.
  const std::string long_ = Deflated(more);
  Write(dir / "long.mha", MetaHeader("4 4 4", true, static_cast<long long>(long_.size())) + long_);
  EXPECT_CONTAINS(ItkError([&] { ReadImage((dir / "long.mha").string()); }), "its compressed data hold 320;");
  // Compressed, damaged in the middle of the stream, or cut short.
  std::string damaged = packed;
  for (std::size_t i = 4; i < damaged.size() - 4; i += 3)
    damaged[i] = static_cast<char>(damaged[i] ^ 0x5a);
  Write(dir / "damaged.mha", MetaHeader("4 4 4", true, static_cast<long long>(damaged.size())) + damaged);
  EXPECT_CONTAINS(ItkError([&] { ReadImage((dir / "damaged.mha").string()); }), "damaged");
  Write(dir / "cut.mha", MetaHeader("4 4 4", true, static_cast<long long>(packed.size())) + packed.substr(0, 20));
  EXPECT_CONTAINS(ItkError([&] { ReadImage((dir / "cut.mha").string()); }), "is truncated");

  // Raw: too little (truncated) and too much.
  Write(dir / "raw_short.mha", MetaHeader("4 4 4", false) + part);
  EXPECT_CONTAINS(ItkError([&] { ReadImage((dir / "raw_short.mha").string()); }),
                  "is truncated: 160 of 256 bytes of voxel data present");
  Write(dir / "raw_long.mha", MetaHeader("4 4 4", false) + more);
  EXPECT_CONTAINS(ItkError([&] { ReadImage((dir / "raw_long.mha").string()); }),
                  "needs 256 bytes, the file holds 320; fix DimSize");
}

TEST(InputGeometry, DirectionsMustBeOrthonormal)
{
  const auto dir = morea_test::TestScratchDir("InputGeometry");
  const std::string whole = Floats(4 * 4 * 4);
  Write(dir / "sheared.mha", MetaHeader("4 4 4", false, -1, "1 0 0 0.3 1 0 0 0 1") + whole);
  const std::string message = ItkError([&] { ReadImage((dir / "sheared.mha").string()); });
  EXPECT_CONTAINS(message, "image '" + (dir / "sheared.mha").string() + "': direction matrix is not orthonormal "
                                                                        "(axis lengths 1, 1.044, 1; axes up to 16.7 "
                                                                        "degrees from perpendicular)");
  EXPECT_CONTAINS(message, "resample the image onto a grid with an orthonormal direction first");
  // A scaled axis.
  Write(dir / "scaled.mha", MetaHeader("4 4 4", false, -1, "1 0 0 0 1.01 0 0 0 1") + whole);
  EXPECT_CONTAINS(ItkError([&] { ReadImage((dir / "scaled.mha").string()); }), "axis lengths 1, 1.01, 1;");
  // A rotation, rounded to 7 digits as files store it, is fine.
  Write(dir / "rotated.mha",
        MetaHeader("4 4 4", false, -1, "0.8660254 0.5 0 -0.5 0.8660254 0 0 0 1") + whole);
  EXPECT_NO_THROW(ReadImage((dir / "rotated.mha").string()));

  // In memory too (ValidateImage is what the filter's inputs go through).
  auto image = ImageType::New();
  image->SetRegions(ImageType::SizeType{ { 2, 2, 2 } });
  ImageType::DirectionType d;
  d.SetIdentity();
  d[0][1] = 1e-6; // below the tolerance of 1e-4
  image->SetDirection(d);
  EXPECT_NO_THROW(ValidateImage(image, "nearly"));
  d[0][1] = 0.01;
  image->SetDirection(d);
  EXPECT_CONTAINS(ItkError([&] { ValidateImage(image, "skewed input"); }),
                  "skewed input: direction matrix is not orthonormal");
}

/** Writes a DICOM CT series of 8x8 slices at `positions` (mm along z) into `folder`. */
void
WriteDicomSeries(const fs::path & folder, const std::vector<double> & positions, double tilt = 0.0)
{
  fs::create_directories(folder);
  using SliceType = itk::Image<short, 3>;
  const std::string study = "1.2.826.0.1.3680043.2.1125.7001", series = "1.2.826.0.1.3680043.2.1125.7002";
  for (std::size_t s = 0; s < positions.size(); ++s)
  {
    auto slice = SliceType::New();
    slice->SetRegions(SliceType::SizeType{ { 8, 8, 1 } });
    slice->Allocate();
    slice->FillBuffer(static_cast<short>(10 * s));
    const double spacing[3] = { 1.0, 1.0, 1.0 };
    const double origin[3] = { 0.0, 0.0, positions[s] };
    slice->SetSpacing(spacing);
    slice->SetOrigin(origin);
    itk::MetaDataDictionary & tags = slice->GetMetaDataDictionary();
    const double              c = std::cos(s + 1 == positions.size() ? tilt : 0.0), sn = std::sin(s + 1 == positions.size() ? tilt : 0.0);
    itk::EncapsulateMetaData<std::string>(tags, "0008|0060", "CT");
    itk::EncapsulateMetaData<std::string>(tags, "0008|0016", "1.2.840.10008.5.1.4.1.1.2");
    itk::EncapsulateMetaData<std::string>(tags, "0008|0018", series + "." + std::to_string(s + 1));
    itk::EncapsulateMetaData<std::string>(tags, "0020|000d", study);
    itk::EncapsulateMetaData<std::string>(tags, "0020|000e", series);
    itk::EncapsulateMetaData<std::string>(tags, "0020|0013", std::to_string(s + 1));
    itk::EncapsulateMetaData<std::string>(tags, "0020|0032", "0\\0\\" + std::to_string(positions[s]));
    itk::EncapsulateMetaData<std::string>(tags, "0020|0037",
                                          "1\\0\\0\\0\\" + std::to_string(c) + "\\" + std::to_string(sn));
    auto io = itk::GDCMImageIO::New();
    io->KeepOriginalUIDOn();
    auto writer = itk::ImageFileWriter<SliceType>::New();
    writer->SetImageIO(io);
    writer->SetInput(slice);
    writer->SetFileName((folder / ("slice" + std::to_string(s) + ".dcm")).string());
    writer->Update();
  }
}

TEST(InputGeometry, DicomSeriesMustBeEvenlySpaced)
{
  const auto dir = morea_test::TestScratchDir("InputGeometry");
  WriteDicomSeries(dir / "even", { 0.0, 2.5, 5.0, 7.5, 10.0, 12.5 });
  const auto image = ReadImage((dir / "even").string());
  EXPECT_NEAR(image->GetSpacing()[2], 2.5, 1e-6);
  EXPECT_EQ(image->GetLargestPossibleRegion().GetSize()[2], 6u);

  // A slice left out of the export: ITK would take 2.5 mm for the whole series.
  WriteDicomSeries(dir / "missing", { 0.0, 2.5, 5.0, 10.0, 12.5, 15.0 });
  const std::string missing = ItkError([&] { ReadImage((dir / "missing").string()); });
  EXPECT_CONTAINS(missing, "the DICOM series in '" + (dir / "missing").string() +
                             "' has non-uniform slice spacing: 4 of its 5 gaps are 2.5 mm, one is not: 5 mm between "
                             "slices at 5 and 10 mm (1 slice seems missing); export the whole series, or resample it "
                             "onto a regular grid first");

  // Uneven spacing, and two slices at one place.
  WriteDicomSeries(dir / "uneven", { 0.0, 2.0, 4.0, 7.0, 9.0, 11.0, 13.0 });
  EXPECT_CONTAINS(ItkError([&] { ReadImage((dir / "uneven").string()); }),
                  "5 of its 6 gaps are 2 mm, one is not: 3 mm between slices at 4 and 7 mm;");
  WriteDicomSeries(dir / "twice", { 0.0, 3.0, 3.0, 6.0, 9.0 });
  const std::string twice = ItkError([&] { ReadImage((dir / "twice").string()); });
  EXPECT_CONTAINS(twice, "3 of its 4 gaps are 3 mm, one is not: 0 mm between slices at 3 and 3 mm (two slices at "
                        "one position)");

  // Positions written with rounding (a few hundredths of a millimetre) are even.
  WriteDicomSeries(dir / "rounded", { 0.0, 3.0, 6.01, 9.0, 12.0 });
  EXPECT_NO_THROW(ReadImage((dir / "rounded").string()));

  // A slice tilted against the others.
  WriteDicomSeries(dir / "tilted", { 0.0, 2.0, 4.0, 6.0 }, 0.2);
  const std::string tilted = ItkError([&] { ReadImage((dir / "tilted").string()); });
  EXPECT_CONTAINS(tilted, "the DICOM series in '" + (dir / "tilted").string() +
                            "' mixes slice orientations: slice 4 of 4 is tilted against the first");
}
} // namespace
