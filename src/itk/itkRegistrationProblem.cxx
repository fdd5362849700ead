// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkRegistrationProblem.h"
#include "itkMOREAFail.h"

#include "itkObjectFactoryBase.h"
#include "itkImageRegionConstIterator.h"
#include "itkLandmarkIO.h"
#include "itkMOREAImageIO.h"
#include "itkPreprocessing.h"
#include "itkRTStructureSetIO.h"
#include "morea_core/ThreadPool.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <mutex>

namespace fs = std::filesystem;

namespace itk
{
namespace morea
{
namespace
{
bool
IsDicomFile(const std::string & path)
{
  std::ifstream in(path, std::ios::binary);
  char          magic[4]{};
  in.seekg(128);
  return in.read(magic, 4) && std::equal(magic, magic + 4, "DICM");
}

bool
IsPointFile(const std::string & path)
{
  const std::string ext = fs::path(path).extension().string();
  if (ext == ".csv")
    return true;
  if (ext != ".txt" && ext != ".pts")
    return false;
  std::ifstream in(path);
  std::string   first;
  in >> first;
  return first == "point" || first == "index";
}

/** Splits "path:selector" where path exists; the selector may be empty. */
void
SplitSource(const std::string & source, std::string & path, std::string & selector)
{
  path = source;
  selector.clear();
  if (fs::exists(source))
    return;
  const auto colon = source.rfind(':');
  if (colon != std::string::npos && colon > 0)
  {
    path = source.substr(0, colon);
    selector = source.substr(colon + 1);
  }
  if (!fs::exists(path))
    Fail("structure source '" + path + "' does not exist");
}


const char *
SideName(bool fixedSide)
{
  return fixedSide ? "fixed" : "moving";
}

/** An RTSTRUCT file or folder and an ROI name. */
bool
IsStructureSet(const std::string & path, const std::string & selector)
{
  return (fs::is_directory(path) || IsDicomFile(path)) && !selector.empty();
}

/** Sets ITK's IO factories up on this thread, before readers on several
 *  threads ask for them. */
void
PrepareConcurrentReads()
{
  ObjectFactoryBase::CreateAllInstance("itkImageIOBase");
}
} // namespace

void
RegistrationProblem::LoadImages(const std::string & fixedPath, const std::string & movingPath)
{
  // Side by side: inflating their voxels is most of the loading.
  PrepareConcurrentReads();
  auto moving = std::async(std::launch::async, [&movingPath] { return ReadImage(movingPath); });
  ImageType::Pointer fixed;
  try
  {
    fixed = ReadImage(fixedPath);
  }
  catch (...)
  {
    moving.wait(); // its thread reads movingPath: let it end first
    throw;
  }
  movingImage = moving.get();
  fixedImage = fixed;
}

MaskType::Pointer
RegistrationProblem::LoadMask(const std::string & source, const ImageType * grid, PointListType * contourPoints,
                              const LabelMapReader & readLabels) const
{
  std::string path, selector;
  SplitSource(source, path, selector);
  MaskType::Pointer mask;
  if (IsStructureSet(path, selector))
  {
    const auto   rois = ReadRTStructureSet(path);
    const auto & roi = FindROI(rois, selector);
    mask = RasterizeROI(roi, grid);
    if (contourPoints != nullptr)
      *contourPoints = ContourPoints(roi);
    return mask;
  }
  if (!selector.empty())
  {
    auto         labels = readLabels ? readLabels(path) : ReadLabelMap(path);
    unsigned int value = 0;
    const bool   numeric = !selector.empty() && std::all_of(selector.begin(), selector.end(), ::isdigit);
    if (numeric)
    {
      value = static_cast<unsigned int>(std::stoul(selector));
    }
    else
    {
      // labels.mha -> labels.txt beside it.
      std::string stem = fs::path(path).filename().string();
      stem = stem.substr(0, stem.find('.'));
      const std::string names = (fs::path(path).parent_path() / (stem + ".txt")).string();
      if (!fs::exists(names))
        Fail("label map '" + path + "': label '" + selector + "' is a name but there is no label file '" + names + "'");
      const auto table = ReadLabelNames(names);
      const auto it = table.find(selector);
      if (it == table.end())
        Fail("label file '" + names + "' has no label called '" + selector + "'");
      value = it->second;
    }
    mask = ExtractLabel(labels, value, "label map '" + path + "'");
  }
  else
  {
    mask = ReadMask(path);
  }
  if (!SameGrid(mask, grid))
  {
    mask = ResampleMask(mask, grid);
    if (CountInside(mask) == 0)
      Fail("mask '" + source + "' does not overlap its image");
  }
  return mask;
}

void
RegistrationProblem::LoadStructure(const std::string & name, bool fixedSide, const std::string & source)
{
  LoadStructures({ StructureSource{ name, fixedSide, source } });
}

Structure &
RegistrationProblem::StructureNamed(const std::string & name)
{
  if (Structure * s = FindStructure(name))
    return *s;
  structures.push_back(Structure{});
  structures.back().name = name;
  return structures.back();
}

bool
RegistrationProblem::LoadSide(const std::string & source, const ImageType * grid, MaskType::Pointer & mask,
                              PointListType & points, const LabelMapReader & readLabels) const
{
  std::string path, selector;
  SplitSource(source, path, selector);
  if (selector.empty() && IsPointFile(path))
  {
    points = ReadLandmarks(path, grid);
    return true;
  }
  mask = LoadMask(source, grid, &points, readLabels);
  return IsStructureSet(path, selector); // LoadMask gave its contour points
}

void
RegistrationProblem::CheckNoSideGivenTwice(const std::vector<StructureSource> & sources) const
{
  // One side of a structure takes one mask (an image, a label, an RTSTRUCT
  // ROI) and one set of points (a point file, or the RTSTRUCT's contours): a
  // mask and a point file add up, but a second mask or second points would
  // silently replace the first (the same NAME given twice, say).
  struct Given
  {
    std::string mask, points; // the sources that gave them; "" when none
  };
  std::map<std::pair<std::string, bool>, Given> given;
  for (const Structure & s : structures)
  {
    given[{ s.name, true }] = { s.fixedMask ? "(loaded before)" : "", s.fixedPoints.empty() ? "" : "(loaded before)" };
    given[{ s.name, false }] = { s.movingMask ? "(loaded before)" : "", s.movingPoints.empty() ? "" : "(loaded before)" };
  }
  for (const StructureSource & s : sources)
  {
    std::string path, selector;
    try
    {
      SplitSource(s.source, path, selector);
    }
    catch (const ExceptionObject &)
    {
      continue; // a missing file: its load says so, naming the structure
    }
    const bool   pointFile = selector.empty() && IsPointFile(path);
    const bool   givesMask = !pointFile, givesPoints = pointFile || IsStructureSet(path, selector);
    Given &      g = given[{ s.name, s.fixedSide }];
    const auto   quoted = [](const std::string & source) {
      return source == "(loaded before)" ? std::string("one loaded before") : "'" + source + "'";
    };
    const std::string earlier = givesMask && !g.mask.empty() ? g.mask : givesPoints && !g.points.empty() ? g.points : "";
    if (!earlier.empty())
      Fail("structure '" + s.name + "' is given twice on the " + SideName(s.fixedSide) + " image: " + quoted(earlier) +
           " and '" + s.source + "' both give its " + (givesMask && !g.mask.empty() ? "mask" : "points") +
           "; give each structure once per image (a mask, and points from a point file if wanted), or rename one");
    if (givesMask)
      g.mask = s.source;
    if (givesPoints)
      g.points = s.source;
  }
}

void
RegistrationProblem::LoadStructures(const std::vector<StructureSource> & sources)
{
  for (const StructureSource & s : sources)
  {
    if ((s.fixedSide ? fixedImage : movingImage).IsNull())
      Fail("load the " + std::string(SideName(s.fixedSide)) + " image before its structures");
    if (s.name.empty())
      Fail("structure from '" + s.source + "' has no name");
  }
  if (sources.empty())
    return;
  CheckNoSideGivenTwice(sources);
  // Label maps that several sources name are read once, on the first
  // thread that asks; the others wait for it.
  std::mutex                                                       labelMutex;
  std::map<std::string, std::shared_future<LabelMapType::Pointer>> labelMaps;
  const LabelMapReader readLabels = [&labelMutex, &labelMaps](const std::string & path) {
    std::promise<LabelMapType::Pointer>     promise;
    std::shared_future<LabelMapType::Pointer> future;
    bool                                      reader = false;
    {
      std::lock_guard<std::mutex> lock(labelMutex);
      auto                        found = labelMaps.find(path);
      if (found == labelMaps.end())
      {
        found = labelMaps.emplace(path, promise.get_future().share()).first;
        reader = true;
      }
      future = found->second;
    }
    if (reader)
    {
      try
      {
        promise.set_value(ReadLabelMap(path));
      }
      catch (...)
      {
        promise.set_exception(std::current_exception());
      }
    }
    return future.get();
  };
  // Each side into its own result, side by side, then kept in order.
  struct Loaded
  {
    MaskType::Pointer mask;
    PointListType     points;
    bool              pointsSet{ false }; ///< a point file or an RTSTRUCT's contours: they replace the side's points
  };
  PrepareConcurrentReads();
  std::vector<Loaded>             loaded(sources.size());
  // At most one reader per core, each taking the next source in turn.
  std::vector<std::future<void>>  tasks;
  std::vector<std::exception_ptr> errors(sources.size());
  std::atomic<std::size_t>        next{ 0 };
  const std::size_t readers = std::min<std::size_t>(sources.size(), morea_core::HostThreads());
  for (std::size_t r = 0; r < readers; ++r)
    tasks.push_back(std::async(std::launch::async, [&] {
      for (std::size_t i = next++; i < sources.size(); i = next++)
      {
        const StructureSource & s = sources[i];
        try
        {
          loaded[i].pointsSet = LoadSide(s.source, s.fixedSide ? fixedImage.GetPointer() : movingImage.GetPointer(),
                                         loaded[i].mask, loaded[i].points, readLabels);
        }
        catch (...)
        {
          errors[i] = std::current_exception();
        }
      }
    }));
  for (auto & t : tasks)
    t.wait();
  for (std::size_t i = 0; i < sources.size(); ++i)
    if (errors[i])
    {
      const StructureSource & s = sources[i];
      try
      {
        std::rethrow_exception(errors[i]);
      }
      catch (const ExceptionObject & e)
      {
        Fail("structure '" + s.name + "' (" + SideName(s.fixedSide) + "): " + e.GetDescription());
      }
    }
  for (std::size_t i = 0; i < sources.size(); ++i)
  {
    Structure & structure = StructureNamed(sources[i].name);
    const bool  fixedSide = sources[i].fixedSide;
    if (loaded[i].mask)
      (fixedSide ? structure.fixedMask : structure.movingMask) = loaded[i].mask;
    if (loaded[i].pointsSet)
      (fixedSide ? structure.fixedPoints : structure.movingPoints) = std::move(loaded[i].points);
  }
}

void
RegistrationProblem::LoadBodyMask(bool fixedSide, const std::string & source)
{
  const ImageType * grid = fixedSide ? fixedImage.GetPointer() : movingImage.GetPointer();
  if (grid == nullptr)
    Fail("load the images before the body masks");
  (fixedSide ? fixedBodyMask : movingBodyMask) = LoadMask(source, grid, nullptr);
}

void
RegistrationProblem::LoadLandmarks(const std::string & fixedPath, const std::string & movingPath)
{
  fixedLandmarks = ReadLandmarks(fixedPath, fixedImage);
  movingLandmarks = ReadLandmarks(movingPath, movingImage);
  if (fixedLandmarks.size() != movingLandmarks.size())
    Fail("landmark files '" + fixedPath + "' and '" + movingPath + "' hold " + std::to_string(fixedLandmarks.size()) +
         " and " + std::to_string(movingLandmarks.size()) + " points; they must pair up");
}

Structure *
RegistrationProblem::FindStructure(const std::string & name)
{
  for (auto & s : structures)
    if (s.name == name)
      return &s;
  return nullptr;
}

const Structure *
RegistrationProblem::FindStructure(const std::string & name) const
{
  return const_cast<RegistrationProblem *>(this)->FindStructure(name);
}

const Structure &
RegistrationProblem::GetStructure(const std::string & name) const
{
  if (const Structure * s = FindStructure(name))
    return *s;
  std::string known;
  for (const auto & s : structures)
    known += (known.empty() ? "" : ", ") + s.name;
  Fail("no structure called '" + name + "' (known: " + (known.empty() ? "none" : known) + ")");
}

void
RegistrationProblem::Validate() const
{
  if (fixedImage.IsNull() || movingImage.IsNull())
    Fail("both a fixed and a moving image are needed");
  for (const auto & s : structures)
  {
    for (bool fixedSide : { true, false })
    {
      const MaskType *      mask = fixedSide ? s.fixedMask.GetPointer() : s.movingMask.GetPointer();
      const PointListType & points = fixedSide ? s.fixedPoints : s.movingPoints;
      const ImageType *     grid = fixedSide ? fixedImage.GetPointer() : movingImage.GetPointer();
      if (mask == nullptr && points.empty())
        Fail("structure '" + s.name + "' is missing on the " + SideName(fixedSide) + " image");
      if (mask != nullptr && !SameGrid(mask, grid))
        Fail("structure '" + s.name + "': the " + std::string(SideName(fixedSide)) + " mask is not on the image grid");
      if (mask != nullptr && CountInside(mask) == 0)
        Fail("structure '" + s.name + "' is empty on the " + SideName(fixedSide) + " image");
    }
  }
  for (bool fixedSide : { true, false })
  {
    const MaskType * body = fixedSide ? fixedBodyMask.GetPointer() : movingBodyMask.GetPointer();
    if (body != nullptr && !SameGrid(body, fixedSide ? fixedImage.GetPointer() : movingImage.GetPointer()))
      Fail(std::string("the ") + SideName(fixedSide) + " body mask is not on the image grid");
  }
  if (fixedLandmarks.size() != movingLandmarks.size())
    Fail("fixed and moving landmark lists differ in length");
  // The images must share some physical space, or no registration can relate them.
  const auto bounds = [](const ImageType * image, PointType & lo, PointType & hi) {
    const auto region = image->GetLargestPossibleRegion();
    for (unsigned d = 0; d < Dimension; ++d)
    {
      lo[d] = std::numeric_limits<double>::max();
      hi[d] = std::numeric_limits<double>::lowest();
    }
    for (unsigned corner = 0; corner < 8; ++corner)
    {
      ContinuousIndex<double, Dimension> index;
      for (unsigned d = 0; d < Dimension; ++d)
        index[d] = (corner >> d & 1) ? region.GetSize()[d] - 0.5 : -0.5;
      PointType p;
      image->TransformContinuousIndexToPhysicalPoint(index, p);
      for (unsigned d = 0; d < Dimension; ++d)
      {
        lo[d] = std::min(lo[d], p[d]);
        hi[d] = std::max(hi[d], p[d]);
      }
    }
  };
  PointType flo, fhi, mlo, mhi;
  bounds(fixedImage, flo, fhi);
  bounds(movingImage, mlo, mhi);
  for (unsigned d = 0; d < Dimension; ++d)
    if (fhi[d] <= mlo[d] || mhi[d] <= flo[d])
      Fail("the fixed and moving images do not overlap in physical space");
}

void
WriteProblemFolder(const RegistrationProblem & problem, const std::string & folder, const std::string & imageExtension)
{
  const std::filesystem::path root(folder);
  WriteImage(problem.fixedImage, (root / ("fixed" + imageExtension)).string());
  WriteImage(problem.movingImage, (root / ("moving" + imageExtension)).string());
  for (const auto & s : problem.structures)
  {
    if (s.fixedMask)
      WriteMask(s.fixedMask, (root / "fixed_masks" / (s.name + imageExtension)).string());
    if (s.movingMask)
      WriteMask(s.movingMask, (root / "moving_masks" / (s.name + imageExtension)).string());
    if (!s.fixedPoints.empty())
      WriteLandmarksCsv(s.fixedPoints, (root / "fixed_points" / (s.name + ".csv")).string());
    if (!s.movingPoints.empty())
      WriteLandmarksCsv(s.movingPoints, (root / "moving_points" / (s.name + ".csv")).string());
  }
  if (problem.fixedBodyMask)
    WriteMask(problem.fixedBodyMask, (root / ("fixed_body" + imageExtension)).string());
  if (problem.movingBodyMask)
    WriteMask(problem.movingBodyMask, (root / ("moving_body" + imageExtension)).string());
  if (!problem.fixedLandmarks.empty())
  {
    WriteElastixPointFile(problem.fixedLandmarks, (root / "fixed_landmarks.txt").string());
    WriteElastixPointFile(problem.movingLandmarks, (root / "moving_landmarks.txt").string());
  }
}

} // namespace morea
} // namespace itk
