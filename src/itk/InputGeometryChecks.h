// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: checks that an input's voxel data and
 *  geometry are what its header says (the ITK layer's own header).
 *
 *  ITK 5.2 reads some broken inputs without an error: a compressed MetaImage
 *  with less data than DimSize describes is padded with zeros, a DICOM
 *  series with a missing slice gets the spacing of its first two slices, and
 *  a sheared direction matrix is taken as it is. A registration on such an
 *  image runs and returns a wrong answer; these checks refuse it instead,
 *  saying what was measured and what to fix.
 *=========================================================================*/
#ifndef itkInputGeometryChecks_h
#define itkInputGeometryChecks_h

#include "itkMatrix.h"
#include "itkMetaDataDictionary.h"

#include <string>
#include <vector>

namespace itk
{
namespace morea
{
/** For a MetaImage file (.mha, data LOCAL): the bytes of voxel data it holds
 *  (decompressed when compressed) against `neededBytes`, what its header
 *  (DimSize, ElementType, channels) describes. Throws, naming `what` and the
 *  file, when they differ or the compressed stream is damaged or cut short;
 *  nothing to check for a header whose data lie in another file. */
void
CheckMetaImageDataSize(const std::string & path, unsigned long long neededBytes, const std::string & what);

/** For a DICOM series read from `directory`: the slices' positions
 *  (ImagePositionPatient, 0020|0032) along the normal of their orientation
 *  (ImageOrientationPatient, 0020|0037) must be evenly spaced, and every
 *  slice must have the same orientation. Throws with the gaps measured (and
 *  which slices seem missing) otherwise. Slices without positions are not
 *  checked (ITK could not have sorted them). */
void
CheckDicomSliceSpacing(const std::vector<MetaDataDictionary *> & slices, const std::string & directory);

/** Throws (naming `what`) when `direction` is not orthonormal within
 *  `tolerance` (each entry of D^T D against the identity): a sheared or
 *  scaled grid, which the rest of the module would treat as a rotation. */
void
CheckOrthonormalDirection(const Matrix<double, 3, 3> & direction, const std::string & what, double tolerance = 1e-4);
} // namespace morea
} // namespace itk

#endif
