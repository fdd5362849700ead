// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: the synthetic pelvis phantom as ITK images
 *  and files (the core generates it; this converts and writes it).
 *=========================================================================*/
#ifndef itkPhantomImages_h
#define itkPhantomImages_h

#include "itkMOREATypes.h"
#include "itkRegistrationProblem.h"
#include "morea_core/Phantom.h"

#include <map>
#include <string>

namespace itk
{
namespace morea
{
ImageType::Pointer
ToImage(const morea_core::Volume<float> & volume);
MaskType::Pointer
ToMask(const morea_core::Volume<std::uint8_t> & volume);
DisplacementFieldType::Pointer
ToDisplacementField(const morea_core::Volume<morea_core::Vec3> & volume);

/** The phantom case as a registration problem (images in HU, masks, landmarks). */
RegistrationProblem
MakePhantomProblem(const morea_core::PelvisPhantom::Case & phantomCase);

/** Paths of a phantom written to a folder. */
struct PhantomFiles
{
  std::string                        fixedImage;
  std::string                        movingImage;
  std::map<std::string, std::string> fixedMasks;  ///< by structure name
  std::map<std::string, std::string> movingMasks;
  std::string                        fixedLandmarks;
  std::string                        movingLandmarks;
  std::string                        trueFixedToMoving; ///< displacement field on the fixed grid
  std::string                        trueMovingToFixed; ///< displacement field on the moving grid
};

/** Writes fixed.nii.gz, moving.nii.gz, fixed_masks/ and moving_masks/ (one
 *  NIfTI per structure), fixed_landmarks.txt and moving_landmarks.txt (elastix
 *  point files) and the true displacement fields (NIfTI vector images) into
 *  `folder`; every file is written atomically. */
PhantomFiles
WritePhantomCase(const morea_core::PelvisPhantom::Case & phantomCase, const std::string & folder);

} // namespace morea
} // namespace itk

#endif
