// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: the data the image objectives sample.
 *
 *  Builds the core's ObjectiveData (SPEC 5) from a preprocessed problem:
 *  per image one multi-channel volume in the mesh model's domain frame with
 *  the windowed intensity and, per guidance structure, the distance to its
 *  surface, plus the guidance weights, radius and sampling rate.
 *=========================================================================*/
#ifndef itkObjectiveData_h
#define itkObjectiveData_h

#include "itkMOREATypes.h"
#include "itkMeshModel.h"
#include "itkRegistrationProblem.h"
#include "morea_core/ObjectiveData.h"

namespace morea_core
{
class ParameterSet;
}

namespace itk
{
namespace morea
{
/** The objective data of a preprocessed problem (both images on one grid) in the
 *  mesh model's domain frame: intensity channels from the images, one distance
 *  channel per guidance structure (GuidanceStructureNames(problem, parameters), in that
 *  order; none when problem_guidance_enabled is false), weights |C_g|/|G| from the
 *  structures' contour point counts on the moving image (fall back to the fixed
 *  side / masks' surface points when points are absent), guidance radius
 *  DefaultGuidanceRadius(domain extent), morea_sampling_rate, voxel volume.
 *  Throws when the images are not on one grid aligned with the model's frame, or
 *  a guidance structure has neither a non-empty mask nor points on a side. */
morea_core::ObjectiveData
BuildObjectiveData(const RegistrationProblem & problem, const MeshModel & model,
                   const morea_core::ParameterSet & parameters);

/** The same in the frame `frame` (a model's frame is DomainFrame::Of(its moving
 *  image)), without a model: RegisterMeshes makes it while the mesh is built. */
morea_core::ObjectiveData
BuildObjectiveData(const RegistrationProblem & problem, const DomainFrame & frame,
                   const morea_core::ParameterSet & parameters);

/** Unsigned distance in mm from every voxel centre of `grid` to the structure's surface:
 *  from the mask when present and non-empty (signed Maurer distances with image spacing,
 *  combined so that the surface lies halfway between inside and outside voxel centres),
 *  else from the contour points (rasterised to the nearest voxels of the grid, then
 *  Maurer). The mask must be on `grid`. Throws when the side has neither. */
ImageType::Pointer
StructureDistanceMap(const Structure & structure, bool fixedSide, const ImageBase<Dimension> * grid);

} // namespace morea
} // namespace itk

#endif
