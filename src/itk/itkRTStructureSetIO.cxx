// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: DICOM RT Structure Set (RTSTRUCT) import.
 *
 *  DCMTK stays inside this file: the public header only exposes ITK types.
 *=========================================================================*/
#include "itkRTStructureSetIO.h"
#include "itkMOREAFail.h"

#include "itkImageRegionIterator.h"
#include "itkMacro.h"

#include "dcmtk/config/osconfig.h" // must precede every other DCMTK header
#include "dcmtk/dcmdata/dcdict.h"
#include "dcmtk/dcmdata/dcdeftag.h"
#include "dcmtk/dcmdata/dcfilefo.h"
#include "dcmtk/dcmdata/dcuid.h"
#include "dcmtk/dcmrt/drtstrct.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>

namespace fs = std::filesystem;

namespace itk
{
namespace morea
{
namespace
{
std::string
Trimmed(const OFString & value)
{
  std::string s{ value.c_str() };
  const auto  first = s.find_first_not_of(" \t\r\n");
  const auto  last = s.find_last_not_of(" \t\r\n");
  return first == std::string::npos ? std::string{} : s.substr(first, last - first + 1);
}

/** Loads `path` as a DICOM file; the dataset stays owned by `file`. */
DcmDataset &
LoadDicom(DcmFileFormat & file, const std::string & path)
{
  if (!dcmDataDict.isDictionaryLoaded())
  {
    // Without the data dictionary DCMTK cannot name any attribute; say so instead of
    // reporting every file as broken.
    Fail("cannot read RT Structure Set '" + path +
         "': the DCMTK data dictionary is not loaded (set DCMDICTPATH to dicom.dic)");
  }
  const OFCondition status = file.loadFile(path.c_str());
  if (status.bad() || file.getDataset() == nullptr)
  {
    Fail("'" + path + "' is not a readable DICOM file: " + status.text());
  }
  return *file.getDataset();
}

/** Empty when the dataset is an RT Structure Set, otherwise why it is not. */
std::string
WhyNotRTStructureSet(DcmDataset & dataset)
{
  OFString sopClass;
  OFString modality;
  dataset.findAndGetOFString(DCM_SOPClassUID, sopClass);
  dataset.findAndGetOFString(DCM_Modality, modality);
  const std::string sop = Trimmed(sopClass);
  const std::string mod = Trimmed(modality);
  if (sop.empty() && mod.empty())
  {
    return "it has neither a SOP Class UID nor a Modality (not a DICOM object)";
  }
  if (sop == UID_RTStructureSetStorage || (sop.empty() && mod == "RTSTRUCT"))
  {
    return {};
  }
  const char * sopName = sop.empty() ? nullptr : dcmFindNameOfUID(sop.c_str());
  return "its SOP Class is " + (sopName != nullptr ? std::string{ sopName } + " (" + sop + ")" : "'" + sop + "'") +
         " and its Modality '" + mod + "', expected RT Structure Set Storage (" + UID_RTStructureSetStorage +
         ") / RTSTRUCT";
}

/** A folder is accepted when it holds exactly one RT Structure Set file (the layout of
 *  TCIA downloads: one folder per DICOM series). */
std::string
ResolveStructureSetFile(const std::string & path)
{
  if (!fs::exists(path))
  {
    Fail("RT Structure Set '" + path + "' does not exist");
  }
  if (!fs::is_directory(path))
  {
    return path;
  }
  std::vector<std::string> candidates;
  for (const auto & entry : fs::directory_iterator(path))
  {
    if (!entry.is_regular_file())
    {
      continue;
    }
    DcmFileFormat file;
    if (file.loadFile(entry.path().c_str()).good() && file.getDataset() != nullptr &&
        WhyNotRTStructureSet(*file.getDataset()).empty())
    {
      candidates.push_back(entry.path().string());
    }
  }
  if (candidates.size() != 1)
  {
    Fail("folder '" + path + "' holds " + std::to_string(candidates.size()) +
         " RT Structure Set files, expected exactly one (give the file itself)");
  }
  return candidates.front();
}

/** Index of the grid's slice axis (2) in continuous-index space, plus the in-plane
 *  polygon of one contour. */
struct SlicePolygon
{
  std::vector<double> column; // continuous index along axis 0
  std::vector<double> row;    // continuous index along axis 1
};

/** Even-odd scanline fill of `polygons` into slice `slice` of `mask`; returns the
 *  number of voxels set. A voxel centre (integer index) is inside when an odd number
 *  of edges cross its row to its left; edges are half-open in the row direction so a
 *  vertex on a row is counted once. */
std::size_t
FillSlice(MaskType * mask, IndexValueType slice, const std::vector<SlicePolygon> & polygons)
{
  const auto       region = mask->GetLargestPossibleRegion();
  const auto       start = region.GetIndex();
  const auto       size = region.GetSize();
  const auto       rows = static_cast<IndexValueType>(size[1]);
  const auto       columns = static_cast<IndexValueType>(size[0]);
  std::vector<std::vector<double>> crossings(static_cast<std::size_t>(rows));

  // Bucket every edge's crossings by row: O(crossings), not O(voxels x edges).
  for (const auto & polygon : polygons)
  {
    const std::size_t n = polygon.row.size();
    for (std::size_t a = 0; a < n; ++a)
    {
      const std::size_t b = (a + 1) % n;
      const double      y0 = polygon.row[a] - static_cast<double>(start[1]);
      const double      y1 = polygon.row[b] - static_cast<double>(start[1]);
      if (y0 == y1)
      {
        continue; // horizontal edges never cross a row under the half-open rule
      }
      const double x0 = polygon.column[a] - static_cast<double>(start[0]);
      const double x1 = polygon.column[b] - static_cast<double>(start[0]);
      const double yMin = std::min(y0, y1);
      const double yMax = std::max(y0, y1);
      // Rows y with yMin <= y < yMax.
      const auto first = std::max<IndexValueType>(0, static_cast<IndexValueType>(std::ceil(yMin)));
      const auto last = std::min<IndexValueType>(rows - 1, static_cast<IndexValueType>(std::ceil(yMax)) - 1);
      for (IndexValueType j = first; j <= last; ++j)
      {
        const double y = static_cast<double>(j);
        crossings[static_cast<std::size_t>(j)].push_back(x0 + (y - y0) * (x1 - x0) / (y1 - y0));
      }
    }
  }

  std::size_t inside = 0;
  for (IndexValueType j = 0; j < rows; ++j)
  {
    auto & xs = crossings[static_cast<std::size_t>(j)];
    std::sort(xs.begin(), xs.end());
    for (std::size_t p = 0; p + 1 < xs.size(); p += 2)
    {
      // Voxel centres i with xs[p] <= i < xs[p+1].
      const auto from = std::max<IndexValueType>(0, static_cast<IndexValueType>(std::ceil(xs[p])));
      const auto to = std::min<IndexValueType>(columns - 1, static_cast<IndexValueType>(std::ceil(xs[p + 1])) - 1);
      MaskType::IndexType index{ { start[0] + from, start[1] + j, start[2] + slice } };
      for (IndexValueType i = from; i <= to; ++i, ++index[0])
      {
        mask->SetPixel(index, 1);
        ++inside;
      }
    }
  }
  return inside;
}
} // namespace

std::vector<RTStructureROI>
ReadRTStructureSet(const std::string & path)
{
  const std::string fileName = ResolveStructureSetFile(path);
  DcmFileFormat     file;
  DcmDataset &      dataset = LoadDicom(file, fileName);
  const std::string whyNot = WhyNotRTStructureSet(dataset);
  if (!whyNot.empty())
  {
    Fail("'" + fileName + "' is not a DICOM RT Structure Set: " + whyNot);
  }

  DRTStructureSetIOD structureSet;
  const OFCondition  status = structureSet.read(dataset);
  if (status.bad())
  {
    Fail("cannot read RT Structure Set '" + fileName + "': " + status.text());
  }

  // Names and numbers come from StructureSetROISequence; contours are linked to them
  // through ROIContourSequence's ReferencedROINumber.
  std::vector<RTStructureROI> rois;
  std::map<int, std::size_t>  byNumber;
  auto &                      roiSequence = structureSet.getStructureSetROISequence();
  for (std::size_t n = 0; n < roiSequence.getNumberOfItems(); ++n)
  {
    const auto &   item = roiSequence.getItem(n);
    RTStructureROI roi;
    OFString       name;
    Sint32         number = 0;
    item.getROIName(name);
    if (item.getROINumber(number).bad())
    {
      Fail("RT Structure Set '" + fileName + "': StructureSetROISequence item " + std::to_string(n + 1) +
           " has no ROI Number");
    }
    roi.name = Trimmed(name);
    roi.number = static_cast<int>(number);
    if (!byNumber.emplace(roi.number, rois.size()).second)
    {
      Fail("RT Structure Set '" + fileName + "': ROI Number " + std::to_string(roi.number) + " is used twice");
    }
    rois.push_back(std::move(roi));
  }
  if (rois.empty())
  {
    Fail("RT Structure Set '" + fileName + "' defines no ROI (empty StructureSetROISequence)");
  }

  auto & contourSequence = structureSet.getROIContourSequence();
  for (std::size_t n = 0; n < contourSequence.getNumberOfItems(); ++n)
  {
    auto & item = contourSequence.getItem(n);
    Sint32 referenced = 0;
    if (item.getReferencedROINumber(referenced).bad())
    {
      Fail("RT Structure Set '" + fileName + "': ROIContourSequence item " + std::to_string(n + 1) +
           " has no Referenced ROI Number");
    }
    const auto found = byNumber.find(static_cast<int>(referenced));
    if (found == byNumber.end())
    {
      Fail("RT Structure Set '" + fileName + "': ROIContourSequence item " + std::to_string(n + 1) +
           " refers to ROI Number " + std::to_string(referenced) + ", which StructureSetROISequence does not define");
    }
    RTStructureROI & roi = rois[found->second];
    auto &           contours = item.getContourSequence();
    for (std::size_t c = 0; c < contours.getNumberOfItems(); ++c)
    {
      const auto & contour = contours.getItem(c);
      OFString     type;
      contour.getContourGeometricType(type);
      // POINT and OPEN_PLANAR/OPEN_NONPLANAR contours enclose no volume.
      if (Trimmed(type) != "CLOSED_PLANAR")
      {
        continue;
      }
      OFVector<Float64> data;
      contour.getContourData(data);
      if (data.size() % 3 != 0)
      {
        Fail("RT Structure Set '" + fileName + "': ROI '" + roi.name + "' contour " + std::to_string(c + 1) +
             " has " + std::to_string(data.size()) + " Contour Data values, not a multiple of 3");
      }
      PointListType polygon;
      polygon.reserve(data.size() / 3);
      for (std::size_t v = 0; v < data.size(); v += 3)
      {
        PointType p;
        for (unsigned int d = 0; d < Dimension; ++d)
        {
          p[d] = data[v + d];
          if (!std::isfinite(p[d]))
          {
            Fail("RT Structure Set '" + fileName + "': ROI '" + roi.name + "' contour " + std::to_string(c + 1) +
                 " has a non-finite coordinate");
          }
        }
        polygon.push_back(p);
      }
      // Fewer than 3 vertices enclose nothing.
      if (polygon.size() >= 3)
      {
        roi.contours.push_back(std::move(polygon));
      }
    }
  }
  return rois;
}

const RTStructureROI &
FindROI(const std::vector<RTStructureROI> & rois, const std::string & name)
{
  for (const auto & roi : rois)
  {
    if (roi.name == name)
    {
      return roi;
    }
  }
  std::string available;
  for (const auto & roi : rois)
  {
    available += (available.empty() ? "'" : ", '") + roi.name + "'";
  }
  Fail("no ROI named '" + name + "' in the RT Structure Set; available: " +
       (available.empty() ? std::string{ "none" } : available));
}

MaskType::Pointer
RasterizeROI(const RTStructureROI & roi, const ImageBase<Dimension> * reference)
{
  if (reference == nullptr)
  {
    Fail("RasterizeROI('" + roi.name + "'): no reference image");
  }
  if (roi.contours.empty())
  {
    Fail("ROI '" + roi.name + "' has no closed planar contour to rasterise");
  }
  const auto region = reference->GetLargestPossibleRegion();
  const auto slices = static_cast<IndexValueType>(region.GetSize()[2]);

  // Group the contours by the slice their plane lies on, in continuous-index space so
  // that any direction matrix is handled; the polygons are filled in that space too
  // (an affine map keeps inside inside).
  std::map<IndexValueType, std::vector<SlicePolygon>> bySlice;
  for (std::size_t c = 0; c < roi.contours.size(); ++c)
  {
    const auto & contour = roi.contours[c];
    SlicePolygon polygon;
    polygon.column.reserve(contour.size());
    polygon.row.reserve(contour.size());
    double kMin = std::numeric_limits<double>::max();
    double kMax = std::numeric_limits<double>::lowest();
    double kSum = 0.0;
    for (const auto & p : contour)
    {
      const auto index = reference->TransformPhysicalPointToContinuousIndex<double, double>(p);
      polygon.column.push_back(index[0]);
      polygon.row.push_back(index[1]);
      kMin = std::min(kMin, index[2]);
      kMax = std::max(kMax, index[2]);
      kSum += index[2];
    }
    if (kMax - kMin > 0.5)
    {
      // A contour spanning several slices is not parallel to the grid's slices
      // (e.g. axial contours on a sagittal grid): a per-slice fill would be wrong.
      std::ostringstream os;
      os << "ROI '" << roi.name << "' contour " << (c + 1) << " spans " << (kMax - kMin)
         << " slices of the reference grid: its plane is not parallel to the grid's slices";
      Fail(os.str());
    }
    const double k = kSum / static_cast<double>(contour.size());
    // Nearest slice centre, i.e. the plane lies within half a slice of it.
    const auto slice = static_cast<IndexValueType>(std::floor(k + 0.5)) - region.GetIndex()[2];
    if (slice < 0 || slice >= slices)
    {
      continue;
    }
    bySlice[slice].push_back(std::move(polygon));
  }
  if (bySlice.empty())
  {
    Fail("no contour of ROI '" + roi.name + "' lies within the slices of the reference grid");
  }

  auto mask = MaskType::New();
  mask->CopyInformation(reference);
  mask->SetRegions(region);
  mask->Allocate(true);
  std::size_t inside = 0;
  for (const auto & [slice, polygons] : bySlice)
  {
    inside += FillSlice(mask, slice, polygons);
  }
  if (inside == 0)
  {
    Fail("ROI '" + roi.name + "' covers no voxel centre of the reference grid");
  }
  return mask;
}

PointListType
ContourPoints(const RTStructureROI & roi)
{
  PointListType points;
  for (const auto & contour : roi.contours)
  {
    points.insert(points.end(), contour.begin(), contour.end());
  }
  return points;
}

} // namespace morea
} // namespace itk
