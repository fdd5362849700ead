// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: rigid pre-alignment on a structure.
 *
 *  Aligns the moving structure mask to the fixed one with ITK's v4
 *  registration framework: centroids first, then a versor rigid transform
 *  that minimises the mean squared difference of the two masks' clipped
 *  signed distance maps (a smooth, wide-basin criterion), coarse to fine.
 *  When the images are given, a last stage refines the transform on the image
 *  intensities (normalised correlation) inside the fixed structure, where its
 *  inner detail (vessels, bone texture) pins the alignment down better than
 *  its outline, which changes shape with breathing or filling.
 *=========================================================================*/
#ifndef itkRigidPreAlignment_h
#define itkRigidPreAlignment_h

#include "itkMOREATypes.h"
#include "itkVersorRigid3DTransform.h"

#include <string>

namespace itk
{
namespace morea
{
using RigidTransformType = VersorRigid3DTransform<double>;
/** The pre-alignment of the moving image: the rigid transform found, or a
 *  linear one given (affine, similarity, rigid), fixed point -> moving point. */
using PreAlignmentTransformType = MatrixOffsetTransformBase<double, Dimension, Dimension>;

struct RigidAlignmentOptions
{
  double       workingSpacing{ 3.0 };   ///< mm; distance maps are computed on this grid
  double       distanceClip{ 30.0 };    ///< mm; distances beyond are clipped
  unsigned int iterationsPerLevel{ 200 };
  double       intensityInset{ 5.0 };       ///< mm: the intensity stage uses the structure's interior this far in
  float        intensityClampMin{ -1000.0f }; ///< HU; below (e.g. outside the field of view) is clamped
  float        intensityClampMax{ 1000.0f };
  double       samplingFraction{ 0.25 };    ///< of the voxels in the region, drawn with a fixed seed
};

struct RigidAlignmentResult
{
  double       initialMetric{ 0.0 };
  double       finalMetric{ 0.0 };   ///< of the mask stage
  bool         intensityRefined{ false };
  /** Why the intensity stage did not run though both images were given
   *  (the structure's interior too small to sample); "" otherwise. */
  std::string  intensitySkipped;
  double       intensityMetric{ 0.0 }; ///< final value of the intensity stage (-correlation)
  unsigned int iterations{ 0 };
  double       translation[3]{ 0, 0, 0 }; ///< mm
  double       rotationDegrees{ 0.0 };     ///< angle of the rotation
  double       seconds{ 0.0 };
};

/** Returns T with T(fixed point) = moving point. */
RigidTransformType::Pointer
AlignRigidly(const MaskType * fixedMask, const MaskType * movingMask, const RigidAlignmentOptions & options,
             RigidAlignmentResult * result = nullptr, const ImageType * fixedImage = nullptr,
             const ImageType * movingImage = nullptr);

/** Writes the transform as an ITK transform file (.tfm, .h5, .mat), atomically. */
void
WriteRigidTransform(const PreAlignmentTransformType * transform, const std::string & path);

} // namespace morea
} // namespace itk

#endif
