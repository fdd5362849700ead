// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: reading, validating and writing images.
 *=========================================================================*/
#ifndef itkMOREAImageIO_h
#define itkMOREAImageIO_h

#include "itkMOREATypes.h"
#include "itkTransformBase.h"

#include <map>
#include <string>

namespace itk
{
namespace morea
{
/** Reads a 3D scalar image in any format ITK reads (NIfTI, MetaImage, NRRD, ...).
 *  A directory is read as a DICOM series (GDCM; the first series found, slices
 *  sorted by position; slices unevenly spaced, e.g. one missing, or of mixed
 *  orientations are an error). The result is validated with ValidateImage(): a
 *  file that cannot be read, is not 3D, is truncated or holds another amount
 *  of voxel data than its header describes (MetaImage, raw or compressed), has
 *  non-positive spacing, a direction that is not orthonormal or NaN/inf voxels
 *  raises an ExceptionObject whose message names the file. */
ImageType::Pointer
ReadImage(const std::string & path);

/** Reads a binary mask: every non-zero voxel is inside. Throws if the mask is
 *  empty (an absent structure is an error the caller must see). */
MaskType::Pointer
ReadMask(const std::string & path);

/** Reads a label map (integer image). */
LabelMapType::Pointer
ReadLabelMap(const std::string & path);

/** The voxels of `labelMap` equal to `label`, as a binary mask; throws when none is. */
MaskType::Pointer
ExtractLabel(const LabelMapType * labelMap, unsigned int label, const std::string & what);

/** Reads a label description file: lines "<value> <name> [anything]"; '#' starts a comment. */
std::map<std::string, unsigned int>
ReadLabelNames(const std::string & path);

/** Throws (naming `what`) when the image has non-positive or non-finite spacing,
 *  zero size, a singular direction matrix or one that is not orthonormal
 *  within 1e-4 (a sheared or scaled grid), or non-finite voxels. */
void
ValidateImage(const ImageBase<Dimension> * image, const std::string & what);
void
ValidateVoxels(const ImageType * image, const std::string & what);

/** The number of non-zero voxels in the mask's buffer. */
std::size_t
CountInside(const MaskType * mask);

/** Checks that two images describe the same voxel grid (size, spacing, origin,
 *  direction) to within `tolerance` (relative to spacing). */
bool
SameGrid(const ImageBase<Dimension> * a, const ImageBase<Dimension> * b, double tolerance = 1e-4);

/** Writers: the file is written under a temporary name in the same folder and
 *  renamed into place, so a failed write never leaves a valid-looking file.
 *  Parent folders are created. */
void
WriteImage(const ImageType * image, const std::string & path);
void
WriteMask(const MaskType * mask, const std::string & path);
void
WriteDisplacementField(const DisplacementFieldType * field, const std::string & path);

/** Writes text atomically (temporary name, then rename); creates parent folders. */
void
WriteTextFile(const std::string & text, const std::string & path);

/** Reads a displacement field (vector image with 3 components, mm). */
DisplacementFieldType::Pointer
ReadDisplacementField(const std::string & path);

/** Writes a transform file (.h5, .tfm, .txt: ITK's transform IO picks by
 *  extension) atomically; the message names `path` when it cannot. */
void
WriteTransformFile(const TransformBaseTemplate<double> * transform, const std::string & path);

/** Moves `temporaryPath` onto `finalPath` atomically (same file system). */
void
CommitFile(const std::string & temporaryPath, const std::string & finalPath);

/** A temporary name next to `finalPath` that keeps its extension(s), so ITK
 *  picks the same writer for it. */
std::string
TemporaryPathFor(const std::string & finalPath);

} // namespace morea
} // namespace itk

#endif
