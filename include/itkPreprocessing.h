// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: preprocessing (SPEC 4.1-4.2).
 *
 *  Resample to isotropic voxels, pre-align rigidly on a structure, crop both
 *  images to the union bounding box of a structure plus a margin, window the
 *  intensities to [0,1] with background exactly 0, and extract 3D surface
 *  points per structure. After preprocessing, both images share one grid.
 *=========================================================================*/
#ifndef itkPreprocessing_h
#define itkPreprocessing_h

#include "itkMOREATypes.h"
#include "itkRegistrationProblem.h"
#include "itkRigidPreAlignment.h"

#include <string>
#include <vector>

namespace morea_core
{
class ParameterSet;
}

namespace itk
{
namespace morea
{
struct PreprocessOptions
{
  double      isotropicSpacing{ 1.5 };  ///< mm
  std::string rigidStructure{ "bones" }; ///< "none" skips pre-alignment
  std::string cropStructure;            ///< empty: the structure whose volume changes most
  double      cropMargin{ 30.0 };       ///< mm
  float       windowMin{ -1000.0f };    ///< maps to the lowest foreground value
  float       windowMax{ 1000.0f };     ///< maps to 1
  float       fieldOfViewThreshold{ -1024.0f }; ///< raw values below are outside the scanner's view
  /** A pre-alignment given (fixed point -> moving point), used instead of the
   *  rigid step on `rigidStructure`; null: none. Must be invertible. */
  PreAlignmentTransformType::ConstPointer initialTransform;

  static PreprocessOptions
  FromParameters(const morea_core::ParameterSet & parameters);
};

/** Foreground voxels are mapped into [ForegroundFloor, 1] so that only
 *  background (outside the body or the field of view) is exactly 0. */
constexpr float ForegroundFloor = 1.0e-3f;

struct PreprocessReport
{
  std::string                 rigidStructure;   ///< "" when skipped or when a transform was given
  std::string                 initialTransform; ///< the class of the transform given, "" when none
  RigidAlignmentResult        rigid;            ///< identity when skipped
  std::string                 cropStructure;
  std::vector<std::string>    droppedStructures; ///< no voxel left inside the crop
  std::vector<std::string>    droppedReasons;    ///< per dropped structure, why ("its moving mask has no voxel inside ...")
  ImageType::SizeType         size{ { 0, 0, 0 } };
  double                      spacing{ 0.0 };
  PointType                   origin;
  double                      secondsTotal{ 0.0 };
};

/** The preprocessed problem: both images on one isotropic grid in the fixed
 *  frame (the moving image pre-aligned), masks on that grid, surface points
 *  from the masks, moving landmarks mapped into the fixed frame. */
struct PreprocessResult
{
  RegistrationProblem problem;
  /** Rigid map from the preprocessed frame to the original moving image
   *  (fixed point -> moving point), to compose with later deformations. */
  PreAlignmentTransformType::Pointer rigidTransform;
  PreprocessReport            report;
};

PreprocessResult
Preprocess(const RegistrationProblem & input, const PreprocessOptions & options);

/** Throws when a structure the registration would use (the guidance
 *  structures of `parameters`: every structure but the body, or those named
 *  in problem_guidance_selection) was dropped by preprocessing, with the
 *  reason and the fix: a registration would otherwise run without it. */
void
CheckGuidanceStructuresKept(const PreprocessReport & report, const morea_core::ParameterSet & parameters);

/** Whether both images' values lie in [0, 1], as preprocessing leaves them
 *  (a problem `morea preprocess` wrote, a registration's preprocessed/
 *  folder). Preprocess refuses such images under a window of Hounsfield
 *  units: windowed again they would lose their contrast. */
bool
IsWindowedAlready(const RegistrationProblem & problem);

// The steps, usable alone.

/** Resamples `image` onto isotropic voxels of `spacing` mm covering the same extent (linear). */
ImageType::Pointer
ResampleIsotropic(const ImageType * image, double spacing);

/** Resamples a mask onto `grid` through `gridToMask` (identity when null). Uses
 *  linear interpolation of the mask's signed distance map, so structures drawn
 *  slice by slice become smooth 3D shapes without between-slice gaps. */
MaskType::Pointer
ResampleMask(const MaskType * mask, const ImageBase<Dimension> * grid,
             const PreAlignmentTransformType * gridToMask = nullptr);

/** The structure whose volume differs most between the images (ratio of the
 *  larger to the smaller volume), skipping "body"; "" when there is none. */
std::string
LargestDeformingStructure(const RegistrationProblem & problem);

/** Physical bounding box of the mask's voxels (centres +- half a voxel); when
 *  `maskToFrame` is given the box is of the mask mapped into that frame. */
void
MaskBoundingBox(const MaskType * mask, PointType & lower, PointType & upper,
                const PreAlignmentTransformType * frameToMask = nullptr);

/** Windows `image` to [ForegroundFloor, 1]; voxels where `foreground` is 0 become exactly 0. */
ImageType::Pointer
ApplyIntensityWindow(const ImageType * image, const MaskType * foreground, float windowMin, float windowMax);

/** Surface points of a mask: centres of inside voxels with a face-neighbour
 *  outside (or on the grid edge), in mm. On an isotropic grid from ResampleMask
 *  they cover the whole 3D surface, including between original slices. */
PointListType
ExtractSurfacePoints(const MaskType * mask);

} // namespace morea
} // namespace itk

#endif
