// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "InputGeometryChecks.h"
#include "itkMOREAFail.h"

#include "itkMacro.h"
#include "itkMetaDataObject.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace itk
{
namespace morea
{
namespace
{
std::string
Number(double value, int digits = 4)
{
  char text[48];
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return text;
}

/** Decompressed size of a zlib (or gzip) stream; -1 when the stream is
 *  damaged or ends before its end marker. */
long long
InflatedBytes(std::ifstream & in, long long compressedBytes)
{
  z_stream stream{};
  if (inflateInit2(&stream, 15 + 32) != Z_OK) // 15 + 32: zlib or gzip header, detected
    return -1;
  std::vector<unsigned char> input(1 << 16), output(1 << 18);
  long long                  total = 0;
  int                        status = Z_OK;
  while (status != Z_STREAM_END && compressedBytes > 0)
  {
    const auto chunk = static_cast<std::streamsize>(std::min<long long>(compressedBytes, static_cast<long long>(input.size())));
    in.read(reinterpret_cast<char *>(input.data()), chunk);
    const std::streamsize got = in.gcount();
    if (got <= 0)
      break;
    compressedBytes -= got;
    stream.next_in = input.data();
    stream.avail_in = static_cast<uInt>(got);
    while (stream.avail_in > 0 && status != Z_STREAM_END)
    {
      stream.next_out = output.data();
      stream.avail_out = static_cast<uInt>(output.size());
      status = inflate(&stream, Z_NO_FLUSH);
      if (status != Z_OK && status != Z_STREAM_END)
      {
        inflateEnd(&stream);
        return -1;
      }
      total += static_cast<long long>(output.size() - stream.avail_out);
    }
  }
  inflateEnd(&stream);
  return status == Z_STREAM_END ? total : -1;
}

/** "1.2\3.4\5.6" (a DICOM multi-valued decimal string) as numbers. */
std::vector<double>
Decimals(const MetaDataDictionary & dictionary, const std::string & tag)
{
  std::string text;
  if (!ExposeMetaData<std::string>(dictionary, tag, text))
    return {};
  std::replace(text.begin(), text.end(), '\\', ' ');
  std::istringstream  in(text);
  std::vector<double> values;
  for (double v; in >> v;)
    values.push_back(v);
  return values;
}
} // namespace

void
CheckMetaImageDataSize(const std::string & path, unsigned long long neededBytes, const std::string & what)
{
  std::ifstream in(path, std::ios::binary);
  std::string   line, dimSize, elementType;
  long long     compressedSize = -1;
  bool          compressed = false, local = false;
  while (std::getline(in, line))
  {
    const auto value = [&line]() {
      const auto at = line.find('=');
      const auto first = at == std::string::npos ? std::string::npos : line.find_first_not_of(" \t", at + 1);
      return first == std::string::npos ? std::string() : line.substr(first, line.find_last_not_of(" \t\r") + 1 - first);
    };
    if (line.rfind("CompressedDataSize", 0) == 0)
      compressedSize = std::atoll(value().c_str());
    else if (line.rfind("CompressedData", 0) == 0)
      compressed = value() == "True" || value() == "true";
    else if (line.rfind("DimSize", 0) == 0)
      dimSize = value();
    else if (line.rfind("ElementType", 0) == 0)
      elementType = value();
    else if (line.rfind("ElementDataFile", 0) == 0)
    {
      local = value() == "LOCAL";
      break;
    }
  }
  if (!local)
    return; // data in another file: ITK checks that one
  const long long offset = static_cast<long long>(in.tellg());
  const long long rest = static_cast<long long>(fs::file_size(path)) - offset;
  const auto      needed = static_cast<long long>(neededBytes);
  const std::string described = "holds another amount of voxel data than its header describes: DimSize " + dimSize +
                                " of " + elementType + " needs " + std::to_string(needed) + " bytes";
  if (!compressed)
  {
    if (rest < needed)
      Fail(what + " '" + path + "' is truncated: " + std::to_string(rest) + " of " + std::to_string(needed) +
           " bytes of voxel data present");
    if (rest > needed)
      Fail(what + " '" + path + "' " + described + ", the file holds " + std::to_string(rest) +
           "; fix DimSize or ElementType, or write the image again");
    return;
  }
  if (compressedSize > 0 && rest < compressedSize)
    Fail(what + " '" + path + "' is truncated: its compressed data stream ends early (" + std::to_string(rest) +
         " of " + std::to_string(compressedSize) + " bytes)");
  const long long inflated = InflatedBytes(in, compressedSize > 0 ? compressedSize : rest);
  if (inflated < 0)
    Fail(what + " '" + path + "' is truncated or damaged: its compressed data stream cannot be decompressed to its end");
  if (inflated != needed)
    Fail(what + " '" + path + "' " + described + ", its compressed data hold " +
         std::to_string(inflated) +
         (inflated < needed ? " (ITK would fill the rest with zeros)" : "") +
         "; fix DimSize or ElementType, or write the image again");
}

void
CheckDicomSliceSpacing(const std::vector<MetaDataDictionary *> & slices, const std::string & directory)
{
  if (slices.size() < 2)
    return;
  const std::vector<double> orientation = Decimals(*slices.front(), "0020|0037");
  std::vector<double>       positions;
  for (std::size_t s = 0; s < slices.size(); ++s)
  {
    const std::vector<double> p = Decimals(*slices[s], "0020|0032");
    const std::vector<double> o = Decimals(*slices[s], "0020|0037");
    if (p.size() != 3 || orientation.size() != 6)
      return; // no positions: nothing to measure
    for (std::size_t k = 0; k < o.size() && o.size() == 6; ++k)
      if (std::abs(o[k] - orientation[k]) > 1e-4)
        Fail("the DICOM series in '" + directory + "' mixes slice orientations: slice " + std::to_string(s + 1) +
             " of " + std::to_string(slices.size()) + " is tilted against the first; export the series again");
    // Position along the slice normal (row x column direction cosines).
    const double n[3] = { orientation[1] * orientation[5] - orientation[2] * orientation[4],
                          orientation[2] * orientation[3] - orientation[0] * orientation[5],
                          orientation[0] * orientation[4] - orientation[1] * orientation[3] };
    positions.push_back(p[0] * n[0] + p[1] * n[1] + p[2] * n[2]);
  }
  std::sort(positions.begin(), positions.end());
  std::vector<double> gaps;
  for (std::size_t s = 1; s < positions.size(); ++s)
    gaps.push_back(positions[s] - positions[s - 1]);
  std::vector<double> sorted = gaps;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
  const double typical = sorted[sorted.size() / 2];
  // Positions are written with a few decimals: a hundredth of a millimetre,
  // or 1 % of the spacing, is rounding.
  const double tolerance = std::max(0.01, 0.01 * typical);
  std::string  uneven;
  std::size_t  count = 0;
  for (std::size_t g = 0; g < gaps.size(); ++g)
  {
    if (std::abs(gaps[g] - typical) <= tolerance)
      continue;
    if (++count > 3)
      continue; // the first three are enough to see what is wrong
    const double ratio = typical > 0.0 ? gaps[g] / typical : 0.0;
    const long   whole = std::lround(ratio);
    std::string  why;
    if (gaps[g] <= tolerance)
      why = "two slices at one position";
    else if (whole >= 2 && std::abs(ratio - static_cast<double>(whole)) < 0.05)
      why = std::to_string(whole - 1) + (whole == 2 ? " slice seems" : " slices seem") + " missing";
    uneven += std::string(uneven.empty() ? "" : "; ") + Number(gaps[g]) + " mm between slices at " +
              Number(positions[g], 6) + " and " + Number(positions[g + 1], 6) + " mm" + (why.empty() ? "" : " (" + why + ")");
  }
  if (count == 0)
    return;
  Fail("the DICOM series in '" + directory + "' has non-uniform slice spacing: " + std::to_string(gaps.size() - count) +
       " of its " + std::to_string(gaps.size()) + " gaps are " + Number(typical) + " mm, " +
       (count == 1 ? std::string("one is not: ") : std::to_string(count) + " are not, e.g. ") + uneven +
       "; export the whole series, or resample it onto a regular grid first");
}

void
CheckOrthonormalDirection(const Matrix<double, 3, 3> & direction, const std::string & what, double tolerance)
{
  double worst = 0.0;
  double lengths[3] = { 0.0, 0.0, 0.0 };
  for (unsigned int a = 0; a < 3; ++a)
    for (unsigned int b = 0; b < 3; ++b)
    {
      double dot = 0.0;
      for (unsigned int r = 0; r < 3; ++r)
        dot += direction[r][a] * direction[r][b];
      if (a == b)
        lengths[a] = std::sqrt(dot);
      worst = std::max(worst, std::abs(dot - (a == b ? 1.0 : 0.0)));
    }
  if (!(worst <= tolerance))
  {
    double skew = 0.0; // the largest departure from a right angle between two axes, degrees
    for (unsigned int a = 0; a < 3; ++a)
      for (unsigned int b = a + 1; b < 3; ++b)
      {
        double dot = 0.0;
        for (unsigned int r = 0; r < 3; ++r)
          dot += direction[r][a] * direction[r][b];
        const double c = dot / std::max(1e-300, lengths[a] * lengths[b]);
        skew = std::max(skew, std::abs(90.0 - std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / 3.14159265358979323846));
      }
    Fail(what + ": direction matrix is not orthonormal (axis lengths " + Number(lengths[0]) + ", " + Number(lengths[1]) +
         ", " + Number(lengths[2]) + "; axes up to " + Number(skew, 3) +
         " degrees from perpendicular): a sheared or scaled grid; resample the image onto a grid with an orthonormal "
         "direction first");
  }
}
} // namespace morea
} // namespace itk
