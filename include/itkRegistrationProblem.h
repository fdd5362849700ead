// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: one loaded registration problem.
 *
 *  Holds the fixed (target) and moving (source) images, named structures on
 *  each side (masks and/or surface points), optional body masks and landmark
 *  pairs. Everything is in physical space; masks live on their image's grid.
 *=========================================================================*/
#ifndef itkRegistrationProblem_h
#define itkRegistrationProblem_h

#include "itkMOREATypes.h"

#include <functional>
#include <string>
#include <vector>

namespace itk
{
namespace morea
{
/** One structure (organ, bone, body) seen on both images. */
struct Structure
{
  std::string       name;
  MaskType::Pointer fixedMask;    ///< on the fixed image grid; may be null when only points are known
  MaskType::Pointer movingMask;   ///< on the moving image grid; may be null when only points are known
  PointListType     fixedPoints;  ///< surface points in mm (from a mask surface, RTSTRUCT or a point file)
  PointListType     movingPoints;
};

class RegistrationProblem
{
public:
  ImageType::Pointer     fixedImage;
  ImageType::Pointer     movingImage;
  std::vector<Structure> structures;
  MaskType::Pointer      fixedBodyMask;  ///< optional: voxels outside are background
  MaskType::Pointer      movingBodyMask; ///< optional
  LandmarkListType       fixedLandmarks;
  LandmarkListType       movingLandmarks;

  /** Loads the images (file or DICOM folder), both at once. */
  void
  LoadImages(const std::string & fixedPath, const std::string & movingPath);

  /** Loads one side of a structure from `source`, which is one of
   *   - a binary mask image:                      "liver.nii.gz"
   *   - a label map and its label value or name:  "labels.mha:3", "labels.mha:Stomach"
   *     (names are looked up in the label file beside it: labels.txt for labels.mha)
   *   - an RTSTRUCT file and the ROI name:        "rtstruct.dcm:Bladder"
   *     (filled on the image grid; its contour points are kept)
   *   - a point set (elastix point file or CSV):  "bladder_points.txt"
   *  The image of that side must be loaded first. Masks on another grid are
   *  resampled onto the image grid. Throws with the source in the message,
   *  also when the side already has a mask (points) and `source` gives another. */
  void
  LoadStructure(const std::string & name, bool fixedSide, const std::string & source);

  /** One side of a structure to load (LoadStructure's arguments). */
  struct StructureSource
  {
    std::string name;
    bool        fixedSide{ true };
    std::string source;
  };

  /** LoadStructure for each source, read side by side: a label map named by
   *  several sources is read once. Structures are added in the order of
   *  `sources`; the first failure in that order is the one thrown. One side
   *  of a structure given two masks or two point sets (the same name twice)
   *  is refused before anything is read. */
  void
  LoadStructures(const std::vector<StructureSource> & sources);

  /** Loads a body mask (any mask source form above) for one side. */
  void
  LoadBodyMask(bool fixedSide, const std::string & source);

  void
  LoadLandmarks(const std::string & fixedPath, const std::string & movingPath);

  /** The structure called `name`; throws listing the known names otherwise. */
  const Structure &
  GetStructure(const std::string & name) const;
  Structure *
  FindStructure(const std::string & name);
  const Structure *
  FindStructure(const std::string & name) const;

  /** Checks the problem is complete and consistent: both images; every structure
   *  present on both sides with a non-empty mask or points; masks on their
   *  image's grid; landmark lists of equal length; images overlapping in space. */
  void
  Validate() const;

private:
  /** Reads a label map by path (LoadStructures shares one read per path). */
  using LabelMapReader = std::function<LabelMapType::Pointer(const std::string & path)>;

  MaskType::Pointer
  LoadMask(const std::string & source, const ImageType * grid, PointListType * contourPoints,
           const LabelMapReader & readLabels = {}) const;
  /** Throws when `sources` (with what is loaded already) give one side of a
   *  structure two masks or two sets of points: the second would replace the
   *  first without a word. */
  void
  CheckNoSideGivenTwice(const std::vector<StructureSource> & sources) const;
  /** The structure called `name`, added (empty) when there is none. */
  Structure &
  StructureNamed(const std::string & name);
  /** The mask and/or points of `source` for a side whose image is `grid`;
   *  true when it gives the side's points (a point file, an RTSTRUCT). */
  bool
  LoadSide(const std::string & source, const ImageType * grid, MaskType::Pointer & mask, PointListType & points,
           const LabelMapReader & readLabels) const;
};

/** Writes `problem` as a problem folder that `--problem` reads: fixed and
 *  moving images, fixed_masks/, moving_masks/, fixed_points/ and
 *  moving_points/ (CSV), body masks and landmarks, images and masks with
 *  `imageExtension` (".nii.gz"; ".mha" keeps the grids' geometry exact in
 *  double precision). */
void
WriteProblemFolder(const RegistrationProblem & problem, const std::string & folder,
                   const std::string & imageExtension = ".nii.gz");

} // namespace morea
} // namespace itk

#endif
