// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of the chunked, multi-threaded gzip that NIfTI files are written with.
#include "ParallelGzip.h"

#include "itkMOREAImageIO.h"

#include "itkImageRegionConstIterator.h"
#include "itkImageRegionIteratorWithIndex.h"

#include "TestScratchDir.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using itk::morea::GzipFileInChunks;

namespace
{
fs::path
ScratchDir()
{
  return morea_test::TestScratchDir("ParallelGzip");
}

std::vector<unsigned char>
ReadBytes(const fs::path & path)
{
  std::ifstream in(path, std::ios::binary);
  return { std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>() };
}

void
WriteBytes(const fs::path & path, const std::vector<unsigned char> & bytes)
{
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char *>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

/** Inflates one gzip member; `consumed` is how many bytes of `gz` it took
 *  (the whole file when it holds one member). Fails the test on a zlib error,
 *  a bad CRC or a bad length among them. */
std::vector<unsigned char>
InflateOneMember(const std::vector<unsigned char> & gz, std::size_t & consumed)
{
  z_stream s{};
  EXPECT_EQ(inflateInit2(&s, 16 + 15), Z_OK);
  std::vector<unsigned char> out;
  std::vector<unsigned char> buffer(1 << 16);
  s.next_in = const_cast<Bytef *>(gz.data());
  s.avail_in = static_cast<uInt>(gz.size());
  int rc = Z_OK;
  while (rc == Z_OK)
  {
    s.next_out = buffer.data();
    s.avail_out = static_cast<uInt>(buffer.size());
    rc = inflate(&s, Z_NO_FLUSH);
    out.insert(out.end(), buffer.data(), buffer.data() + (buffer.size() - s.avail_out));
  }
  EXPECT_EQ(rc, Z_STREAM_END) << (s.msg ? s.msg : "");
  consumed = gz.size() - s.avail_in;
  inflateEnd(&s);
  return out;
}

/** Doubles like a displacement field's (hard to compress) with runs of zeros
 *  (easy), so that chunks differ in how well they deflate. */
std::vector<unsigned char>
FieldLikeBytes(std::size_t n)
{
  std::vector<unsigned char> bytes(n);
  std::mt19937_64            random(7);
  std::normal_distribution<double> normal(0.0, 10.0);
  for (std::size_t i = 0; i + 8 <= n; i += 8)
  {
    const double v = (i / 65536) % 3 == 0 ? 0.0 : normal(random);
    std::memcpy(bytes.data() + i, &v, 8);
  }
  return bytes;
}
} // namespace

TEST(ParallelGzip, ManyChunksInflateToTheInputAsOneMember)
{
  const auto dir = ScratchDir();
  for (const std::size_t size : { std::size_t{ 0 }, std::size_t{ 1 }, std::size_t{ 4096 }, std::size_t{ 40000 },
                                  std::size_t{ 3 } << 20, (std::size_t{ 3 } << 20) + 13 })
    for (const std::size_t chunk : { std::size_t{ 1000 }, std::size_t{ 32768 }, std::size_t{ 1 } << 18,
                                     std::size_t{ 1 } << 22 })
    {
      SCOPED_TRACE("size " + std::to_string(size) + ", chunk " + std::to_string(chunk));
      const auto input = FieldLikeBytes(size);
      WriteBytes(dir / "in.bin", input);
      GzipFileInChunks((dir / "in.bin").string(), (dir / "in.bin.gz").string(), chunk);
      const auto  gz = ReadBytes(dir / "in.bin.gz");
      std::size_t consumed = 0;
      const auto  output = InflateOneMember(gz, consumed);
      EXPECT_EQ(consumed, gz.size()); // nothing after the first member
      ASSERT_EQ(output.size(), input.size());
      EXPECT_TRUE(output == input);
    }
}

TEST(ParallelGzip, ChunksCompressAboutAsWellAsOneStream)
{
  // Each chunk is primed with the 32 KiB before it, so cutting the input
  // costs little: within 1 % of zlib's one stream at the same level.
  const auto dir = ScratchDir();
  const auto input = FieldLikeBytes(std::size_t{ 4 } << 20);
  WriteBytes(dir / "in.bin", input);
  GzipFileInChunks((dir / "in.bin").string(), (dir / "chunked.gz").string(), std::size_t{ 1 } << 18);
  uLongf                     oneStreamSize = compressBound(static_cast<uLong>(input.size()));
  std::vector<unsigned char> oneStream(oneStreamSize);
  ASSERT_EQ(compress2(oneStream.data(), &oneStreamSize, input.data(), static_cast<uLong>(input.size()),
                      Z_DEFAULT_COMPRESSION),
            Z_OK);
  const double chunked = static_cast<double>(fs::file_size(dir / "chunked.gz"));
  EXPECT_LT(chunked, 1.01 * static_cast<double>(oneStreamSize) + 64.0);
  EXPECT_LT(chunked, 0.9 * static_cast<double>(input.size())); // it did compress
}

TEST(ParallelGzip, MissingInputIsAnError)
{
  const auto dir = ScratchDir();
  EXPECT_THROW(GzipFileInChunks((dir / "absent.bin").string(), (dir / "absent.bin.gz").string()),
               itk::ExceptionObject);
  EXPECT_FALSE(fs::exists(dir / "absent.bin.gz"));
}

TEST(ParallelGzip, NiftiFieldOfManyChunksReadsBackExactly)
{
  // 96 x 80 x 40 vectors of doubles: 7.4 MB, two 4 MiB chunks.
  const auto dir = ScratchDir();
  auto       field = itk::morea::DisplacementFieldType::New();
  itk::morea::DisplacementFieldType::SizeType size{ { 96, 80, 40 } };
  field->SetRegions(size);
  field->Allocate();
  for (itk::ImageRegionIteratorWithIndex<itk::morea::DisplacementFieldType> it(field, field->GetLargestPossibleRegion());
       !it.IsAtEnd(); ++it)
  {
    const auto                         i = it.GetIndex();
    itk::morea::DisplacementVectorType v;
    v[0] = std::sin(0.1 * i[0]) * 3.0;
    v[1] = 0.01 * i[1] * i[2];
    v[2] = -1.0 / (1.0 + i[0] + i[1]);
    it.Set(v);
  }
  const auto path = (dir / "field.nii.gz").string();
  itk::morea::WriteDisplacementField(field, path);
  const auto  gz = ReadBytes(path);
  std::size_t consumed = 0;
  const auto  nifti = InflateOneMember(gz, consumed);
  EXPECT_EQ(consumed, gz.size());
  EXPECT_GT(nifti.size(), std::size_t{ 4 } << 20);
  const auto read = itk::morea::ReadDisplacementField(path);
  itk::ImageRegionConstIterator<itk::morea::DisplacementFieldType> a(field, field->GetLargestPossibleRegion());
  itk::ImageRegionConstIterator<itk::morea::DisplacementFieldType> b(read, read->GetLargestPossibleRegion());
  std::size_t                                                      differing = 0;
  for (; !a.IsAtEnd(); ++a, ++b)
    differing += a.Get() != b.Get();
  EXPECT_EQ(differing, 0u);
  // Only the final file is left: no plain .nii beside it, no staging folder.
  std::size_t files = 0;
  for ([[maybe_unused]] const auto & entry : fs::directory_iterator(dir))
    ++files;
  EXPECT_EQ(files, 1u);
}
