// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkMOREAImageIO.h"
#include "itkMOREAFail.h"
#include "itkTransformFileWriter.h"

#include "itkGDCMImageIO.h"
#include "itkGDCMSeriesFileNames.h"
#include "itkImageFileReader.h"
#include "itkImageFileWriter.h"
#include "itkImageRegionConstIterator.h"
#include "itkImageRegionIterator.h"
#include "itkImageSeriesReader.h"

#include "InputGeometryChecks.h"
#include "ParallelGzip.h"

#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace fs = std::filesystem;

namespace itk
{
namespace morea
{
namespace
{
void
CheckNotTruncated(const std::string & path, long long available, long long needed, const std::string & what)
{
  if (available < needed)
  {
    Fail(what + " '" + path + "' is truncated: " +
         (available < 0 ? std::string("its compressed data stream ends early")
                        : std::to_string(available) + " of " + std::to_string(needed) + " bytes of voxel data present"));
  }
}

std::string
LowerCase(std::string s)
{
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

/** Bytes of voxel data a file holds after `offset`, following gzip streams to
 *  their end; -1 when the gzip stream itself is cut short. */
long long
PayloadBytes(const std::string & path, long long offset, bool gzipped)
{
  if (!gzipped)
    return static_cast<long long>(fs::file_size(path)) - offset;
  gzFile file = gzopen(path.c_str(), "rb");
  if (file == nullptr)
    return -1;
  std::vector<char> buffer(1 << 16);
  long long         total = 0;
  int               n = 0;
  while ((n = gzread(file, buffer.data(), static_cast<unsigned>(buffer.size()))) > 0)
    total += n;
  int         error = Z_OK;
  const char * message = gzerror(file, &error);
  (void)message;
  gzclose(file);
  if (n < 0 || (error != Z_OK && error != Z_STREAM_END))
    return -1;
  return total - offset;
}

/** ITK 5.2's MetaImage and NIfTI readers accept files cut short (they warn or pad
 *  with zeros); a truncated scan must be an error, so check the data size here. */
void
CheckNotTruncated(const std::string & path, const ImageIOBase * io, const std::string & what)
{
  const std::string name = LowerCase(fs::path(path).filename().string());
  const auto        endsWith = [&name](const std::string & ext) {
    return name.size() >= ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0;
  };
  const long long needed = static_cast<long long>(io->GetImageSizeInBytes());
  long long       available = needed;
  if (endsWith(".nii") || endsWith(".nii.gz"))
  {
    // NIfTI-1: the voxel data start at vox_offset (a float at byte 108; 352 by default).
    const bool    gz = endsWith(".gz");
    long long     offset = 352;
    std::ifstream in(path, std::ios::binary);
    if (!gz && in)
    {
      float voxOffset = 0.0f;
      in.seekg(108);
      if (in.read(reinterpret_cast<char *>(&voxOffset), sizeof voxOffset) && voxOffset >= 348.0f)
        offset = static_cast<long long>(voxOffset);
    }
    available = PayloadBytes(path, offset, gz);
  }
  else if (endsWith(".mha"))
  {
    // Raw and compressed: the data against DimSize (ITK pads a short compressed stream with zeros).
    return CheckMetaImageDataSize(path, static_cast<unsigned long long>(needed), what);
  }
  CheckNotTruncated(path, available, needed, what);
}

template <typename TImage>
typename TImage::Pointer
ReadFile(const std::string & path, const std::string & what)
{
  if (!fs::exists(path))
  {
    Fail(what + " '" + path + "' does not exist");
  }
  if (fs::is_directory(path))
  {
    Fail(what + " '" + path + "' is a directory, expected an image file");
  }
  auto reader = ImageFileReader<TImage>::New();
  reader->SetFileName(path);
  try
  {
    reader->Update();
  }
  catch (const ExceptionObject & e)
  {
    Fail("cannot read " + what + " '" + path + "': " + e.GetDescription());
  }
  const auto * io = reader->GetImageIO();
  if (io != nullptr && io->GetNumberOfDimensions() != Dimension)
  {
    // ITK pads 2D files to 3D silently; a 2D structure on a 3D problem is an input error.
    Fail(what + " '" + path + "' has " + std::to_string(io->GetNumberOfDimensions()) + " dimensions, expected 3");
  }
  const unsigned int components = PixelTraits<typename TImage::PixelType>::Dimension;
  if (io != nullptr && io->GetNumberOfComponents() != components)
  {
    // ITK converts silently (RGB to luminance, a scalar copied into every vector component).
    Fail(what + " '" + path + "' has " + std::to_string(io->GetNumberOfComponents()) +
         " components per voxel, expected " + std::to_string(components));
  }
  if (io != nullptr)
  {
    CheckNotTruncated(path, io, what);
  }
  typename TImage::Pointer image = reader->GetOutput();
  image->DisconnectPipeline();
  return image;
}

ImageType::Pointer
ReadDicomSeries(const std::string & directory)
{
  auto names = GDCMSeriesFileNames::New();
  names->SetUseSeriesDetails(true);
  names->SetDirectory(directory);
  const auto & seriesUIDs = names->GetSeriesUIDs();
  if (seriesUIDs.empty())
  {
    Fail("no DICOM image series found in folder '" + directory + "'");
  }
  const auto fileNames = names->GetFileNames(seriesUIDs.front());
  if (fileNames.size() < 2)
  {
    Fail("the DICOM series in '" + directory + "' has fewer than 2 slices");
  }
  using ReaderType = ImageSeriesReader<ImageType>;
  auto reader = ReaderType::New();
  auto dicomIO = GDCMImageIO::New();
  reader->SetImageIO(dicomIO);
  reader->SetFileNames(fileNames);
  try
  {
    reader->Update();
  }
  catch (const ExceptionObject & e)
  {
    Fail("cannot read DICOM series in '" + directory + "': " + e.GetDescription());
  }
  // ITK takes the spacing of the first two slices and only warns when the
  // others are spaced otherwise (a slice missing from the export, say).
  if (const auto * slices = reader->GetMetaDataDictionaryArray())
    CheckDicomSliceSpacing(*slices, directory);
  ImageType::Pointer image = reader->GetOutput();
  image->DisconnectPipeline();
  return image;
}
} // namespace

void
ValidateImage(const ImageBase<Dimension> * image, const std::string & what)
{
  if (image == nullptr)
  {
    Fail(what + ": no image");
  }
  const auto size = image->GetLargestPossibleRegion().GetSize();
  for (unsigned int d = 0; d < Dimension; ++d)
  {
    if (size[d] == 0)
    {
      Fail(what + ": image has zero size along axis " + std::to_string(d));
    }
    const double s = image->GetSpacing()[d];
    if (!(s > 0.0) || !std::isfinite(s))
    {
      std::ostringstream os;
      os << what << ": spacing along axis " << d << " is " << s << ", must be positive";
      Fail(os.str());
    }
    if (!std::isfinite(image->GetOrigin()[d]))
    {
      Fail(what + ": origin is not finite");
    }
  }
  const double det = vnl_determinant(image->GetDirection().GetVnlMatrix());
  if (!(std::abs(det) > 1e-6))
  {
    Fail(what + ": direction matrix is singular");
  }
  CheckOrthonormalDirection(image->GetDirection(), what);
}

void
ValidateVoxels(const ImageType * image, const std::string & what)
{
  // The buffer directly: an iterator per voxel took a quarter of a second
  // on the abdominal pair's masks and images.
  const float *     voxels = image->GetBufferPointer();
  const std::size_t count = image->GetBufferedRegion().GetNumberOfPixels();
  std::size_t       bad = 0;
  for (std::size_t v = 0; v < count; ++v)
    bad += std::isfinite(voxels[v]) ? 0 : 1;
  if (bad > 0)
  {
    Fail(what + ": " + std::to_string(bad) + " voxels are NaN or infinite");
  }
}

std::size_t
CountInside(const MaskType * mask)
{
  const MaskType::PixelType * voxels = mask->GetBufferPointer();
  const std::size_t           count = mask->GetBufferedRegion().GetNumberOfPixels();
  std::size_t                 inside = 0;
  for (std::size_t v = 0; v < count; ++v)
    inside += voxels[v] != 0 ? 1 : 0;
  return inside;
}

bool
SameGrid(const ImageBase<Dimension> * a, const ImageBase<Dimension> * b, double tolerance)
{
  if (a->GetLargestPossibleRegion().GetSize() != b->GetLargestPossibleRegion().GetSize())
  {
    return false;
  }
  for (unsigned int i = 0; i < Dimension; ++i)
  {
    const double s = a->GetSpacing()[i];
    if (std::abs(s - b->GetSpacing()[i]) > tolerance * s ||
        std::abs(a->GetOrigin()[i] - b->GetOrigin()[i]) > tolerance * s)
    {
      return false;
    }
    for (unsigned int j = 0; j < Dimension; ++j)
    {
      if (std::abs(a->GetDirection()[i][j] - b->GetDirection()[i][j]) > tolerance)
      {
        return false;
      }
    }
  }
  return true;
}

ImageType::Pointer
ReadImage(const std::string & path)
{
  ImageType::Pointer image =
    fs::is_directory(path) ? ReadDicomSeries(path) : ReadFile<ImageType>(path, "image");
  ValidateImage(image, "image '" + path + "'");
  ValidateVoxels(image, "image '" + path + "'");
  return image;
}

LabelMapType::Pointer
ReadLabelMap(const std::string & path)
{
  auto labels = ReadFile<LabelMapType>(path, "label map");
  ValidateImage(labels, "label map '" + path + "'");
  return labels;
}

MaskType::Pointer
ReadMask(const std::string & path)
{
  // Read as float so that masks stored as probabilities or with NaN are caught.
  auto raw = ReadFile<ImageType>(path, "mask");
  ValidateImage(raw, "mask '" + path + "'");
  ValidateVoxels(raw, "mask '" + path + "'");
  auto mask = MaskType::New();
  mask->CopyInformation(raw);
  mask->SetRegions(raw->GetBufferedRegion()); // a reader's buffer is its whole image
  mask->Allocate();
  const float *       in = raw->GetBufferPointer();
  MaskType::PixelType * out = mask->GetBufferPointer();
  const std::size_t   count = raw->GetBufferedRegion().GetNumberOfPixels();
  std::size_t         inside = 0;
  for (std::size_t v = 0; v < count; ++v)
  {
    out[v] = in[v] != 0.0f ? 1 : 0;
    inside += out[v];
  }
  if (inside == 0)
  {
    Fail("mask '" + path + "' is empty (no non-zero voxel)");
  }
  return mask;
}

MaskType::Pointer
ExtractLabel(const LabelMapType * labelMap, unsigned int label, const std::string & what)
{
  if (labelMap->GetBufferedRegion() != labelMap->GetLargestPossibleRegion())
  {
    Fail(what + ": the label map is not wholly in memory");
  }
  auto mask = MaskType::New();
  mask->CopyInformation(labelMap);
  mask->SetRegions(labelMap->GetLargestPossibleRegion());
  mask->Allocate();
  const LabelMapType::PixelType * in = labelMap->GetBufferPointer();
  MaskType::PixelType *           out = mask->GetBufferPointer();
  const std::size_t               count = labelMap->GetBufferedRegion().GetNumberOfPixels();
  std::size_t                     inside = 0;
  for (std::size_t v = 0; v < count; ++v)
  {
    out[v] = in[v] == label ? 1 : 0;
    inside += out[v];
  }
  if (inside == 0)
  {
    Fail(what + ": label " + std::to_string(label) + " is absent from the label map");
  }
  return mask;
}

std::map<std::string, unsigned int>
ReadLabelNames(const std::string & path)
{
  std::ifstream in(path);
  if (!in)
  {
    Fail("cannot open label description file '" + path + "'");
  }
  std::map<std::string, unsigned int> names;
  std::string                         line;
  int                                 lineNumber = 0;
  while (std::getline(in, line))
  {
    ++lineNumber;
    const auto hash = line.find('#');
    if (hash != std::string::npos)
    {
      line.erase(hash);
    }
    std::istringstream fields(line);
    long               value = 0;
    std::string        name;
    if (!(fields >> value))
    {
      if (line.find_first_not_of(" \t\r") == std::string::npos)
      {
        continue;
      }
      Fail("label description file '" + path + "' line " + std::to_string(lineNumber) + ": expected '<value> <name>'");
    }
    if (!(fields >> name) || value <= 0 || value > 65535)
    {
      Fail("label description file '" + path + "' line " + std::to_string(lineNumber) +
           ": expected a label value in 1..65535 and a name");
    }
    names[name] = static_cast<unsigned int>(value);
  }
  return names;
}

std::string
TemporaryPathFor(const std::string & finalPath)
{
  static std::atomic<unsigned> counter{ 0 };
  const fs::path p(finalPath);
  std::string    name = p.filename().string();
  // Keep the whole extension chain (".nii.gz") so ITK selects the same IO.
  const auto     dot = name.find('.', 1);
  const std::string stem = dot == std::string::npos ? name : name.substr(0, dot);
  const std::string ext = dot == std::string::npos ? "" : name.substr(dot);
  const std::string tmp = "." + stem + ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + ext;
  return (p.parent_path() / tmp).string();
}

void
WriteTransformFile(const TransformBaseTemplate<double> * transform, const std::string & path)
{
  const std::string tmp = TemporaryPathFor(path);
  auto              writer = TransformFileWriterTemplate<double>::New();
  writer->SetInput(transform);
  writer->SetFileName(tmp);
  try
  {
    writer->Update();
  }
  catch (const ExceptionObject & e)
  {
    std::remove(tmp.c_str());
    Fail("cannot write transform '" + path + "': " + e.GetDescription());
  }
  CommitFile(tmp, path);
}

void
CommitFile(const std::string & temporaryPath, const std::string & finalPath)
{
  std::error_code ec;
  fs::rename(temporaryPath, finalPath, ec);
  if (ec)
  {
    fs::remove(temporaryPath, ec);
    Fail("cannot move '" + temporaryPath + "' to '" + finalPath + "'");
  }
}

namespace
{
template <typename TImage>
void
WriteFileAtomically(const TImage * image, const std::string & path)
{
  const fs::path target(path);
  const fs::path parent = target.parent_path();
  if (!parent.empty())
  {
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec)
    {
      Fail("cannot create folder '" + parent.string() + "': " + ec.message());
    }
  }
  // Write under the final file name inside a temporary folder next to the
  // target, then move the file(s) into place. Formats with separate header and
  // data files (.mhd + .zraw, .hdr + .img, .nhdr + .raw) name the data file
  // after the header, so writing under a temporary name and renaming only the
  // header would break the pair. The requested file is moved last.
  const fs::path  folder = TemporaryPathFor(path) + ".d";
  std::error_code ec;
  if (!fs::create_directory(folder, ec) || ec)
  {
    Fail("cannot write '" + path + "': cannot create temporary folder '" + folder.string() + "'");
  }
  const fs::path staged = folder / target.filename();
  // NIfTI is written plain and gzipped here on several threads
  // (ParallelGzip.h): ITK's writer deflates on one.
  // (Other spellings, .NII.GZ say, are left to ITK's writer as they were.)
  const std::string name = target.filename().string();
  const bool        gzipAfter = name.size() > 7 && name.compare(name.size() - 7, 7, ".nii.gz") == 0;
  const fs::path    written = gzipAfter ? folder / target.stem() : staged; // "x.nii.gz" -> "x.nii"
  auto              writer = ImageFileWriter<TImage>::New();
  writer->SetInput(image);
  writer->SetFileName(written.string());
  writer->SetUseCompression(!gzipAfter);
  try
  {
    writer->Update();
    if (!fs::exists(written))
    {
      Fail("the writer produced no file");
    }
    if (gzipAfter)
    {
      GzipFileInChunks(written.string(), staged.string());
      std::error_code removed;
      fs::remove(written, removed); // the folder goes below in any case
    }
    for (const auto & entry : fs::directory_iterator(folder))
    {
      if (entry.path() != staged && entry.path() != written)
      {
        CommitFile(entry.path().string(), (parent / entry.path().filename()).string());
      }
    }
    CommitFile(staged.string(), path);
  }
  catch (const ExceptionObject & e)
  {
    fs::remove_all(folder, ec);
    Fail("cannot write '" + path + "': " + e.GetDescription());
  }
  fs::remove_all(folder, ec);
}

} // namespace

void
WriteImage(const ImageType * image, const std::string & path)
{
  WriteFileAtomically(image, path);
}

void
WriteMask(const MaskType * mask, const std::string & path)
{
  WriteFileAtomically(mask, path);
}

void
WriteDisplacementField(const DisplacementFieldType * field, const std::string & path)
{
  WriteFileAtomically(field, path);
}

void
WriteTextFile(const std::string & text, const std::string & path)
{
  const fs::path  parent = fs::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty())
  {
    fs::create_directories(parent, ec);
  }
  const std::string tmp = TemporaryPathFor(path);
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    if (!out.flush())
    {
      fs::remove(tmp, ec);
      Fail("cannot write '" + path + "'");
    }
  }
  CommitFile(tmp, path);
}

DisplacementFieldType::Pointer
ReadDisplacementField(const std::string & path)
{
  auto field = ReadFile<DisplacementFieldType>(path, "displacement field");
  ValidateImage(field, "displacement field '" + path + "'");
  return field;
}

} // namespace morea
} // namespace itk
