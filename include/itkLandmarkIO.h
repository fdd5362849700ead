// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: landmark and point-set files.
 *
 *  elastix point files:   "point" or "index", the count, then one "x y z" per line
 *                         (index files hold voxel indices of a reference image).
 *  CSV:                   optional header, then "x,y,z" (mm) per row; extra
 *                         leading columns (e.g. a name) are allowed when the
 *                         header names the coordinate columns x,y,z.
 *=========================================================================*/
#ifndef itkLandmarkIO_h
#define itkLandmarkIO_h

#include "itkMOREATypes.h"

#include <string>

namespace itk
{
namespace morea
{
/** Reads landmarks in mm. Files in elastix "index" form need `reference` (the
 *  image whose voxel indices they hold) and throw without it. The format is
 *  chosen from the content (elastix) or the extension (.csv). */
LandmarkListType
ReadLandmarks(const std::string & path, const ImageBase<Dimension> * reference = nullptr);

/** Writes an elastix "point" file (mm), atomically. */
void
WriteElastixPointFile(const LandmarkListType & points, const std::string & path);

/** Writes "x,y,z" CSV with a header, atomically. */
void
WriteLandmarksCsv(const LandmarkListType & points, const std::string & path);

} // namespace morea
} // namespace itk

#endif
