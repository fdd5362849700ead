// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: DICOM RT Structure Set (RTSTRUCT) import.
 *=========================================================================*/
#ifndef itkRTStructureSetIO_h
#define itkRTStructureSetIO_h

#include "itkMOREATypes.h"

#include <string>
#include <vector>

namespace itk
{
namespace morea
{
/** One ROI of an RT Structure Set: its planar contours in patient coordinates (mm, LPS). */
struct RTStructureROI
{
  std::string                         name;
  int                                 number{ 0 };
  std::vector<PointListType>          contours; ///< closed polygons, one per contour item
};

/** Reads every ROI (name, number, closed-planar contours) of an RTSTRUCT file
 *  with DCMTK's dcmrt; POINT and open contours are skipped. `path` may also be a
 *  folder holding exactly one RTSTRUCT file. Throws an ExceptionObject naming the
 *  file when it cannot be read, is not an RT Structure Set or defines no ROI. */
std::vector<RTStructureROI>
ReadRTStructureSet(const std::string & path);

/** The ROI named `name` (exact match); throws listing the available names otherwise. */
const RTStructureROI &
FindROI(const std::vector<RTStructureROI> & rois, const std::string & name);

/** Fills the ROI's contours on the grid of `reference`: per slice, a voxel centre
 *  is inside when it lies inside an odd number of that slice's polygons
 *  (even-odd rule, so holes drawn as inner contours stay empty). Throws when no
 *  voxel is inside. */
MaskType::Pointer
RasterizeROI(const RTStructureROI & roi, const ImageBase<Dimension> * reference);

/** All contour vertices of the ROI (the surface points drawn by the expert). */
PointListType
ContourPoints(const RTStructureROI & roi);

} // namespace morea
} // namespace itk

#endif
