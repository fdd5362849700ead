// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Surface elements of a binary mask on the grid of voxel corners, the
// representation behind ComputeSurfaceDistances (private to the ITK layer).
#ifndef itkSurfaceElements_h
#define itkSurfaceElements_h

#include "itkRegistrationMetrics.h"

#include <array>
#include <vector>

namespace itk
{
namespace morea
{
namespace detail
{
using VoxelBox = std::array<SizeValueType, Dimension>;

/** The surface elements of one mask inside the voxel box [lower, upper]
 *  (inclusive), which must hold all of the mask's inside voxels.
 *
 *  The corner grid has (upper - lower + 2) points per axis; its point c lies
 *  at the continuous voxel index lower + c - 1/2, the corner shared by the
 *  voxels lower + c - 1 + o, o in {0, 1}^3 (voxels outside the box are
 *  outside the mask). A point is a surface element when its 2x2x2 code (see
 *  SurfaceElementAreas) is neither 0 nor 255. */
struct SurfaceElements
{
  struct Element
  {
    SizeValueType offset; ///< linear offset on the corner grid
    double        area;   ///< mm^2
  };
  MaskType::Pointer    grid;   ///< corner grid (spacing and direction of the mask), 1 at every surface element
  SizeValueType        count{ 0 }; ///< surface elements on the grid
  std::vector<Element> scored; ///< the surface elements that the region keeps (all without a region)
};

/** With a region (a mask on the mask's grid), an element is scored when every
 *  voxel of its 2x2x2 neighbourhood that lies in the image is in the region. */
SurfaceElements
ExtractSurfaceElements(const MaskType *                mask,
                       const MaskType *                region,
                       const VoxelBox &                lower,
                       const VoxelBox &                upper,
                       const SurfaceElementAreaTable & areas);

} // namespace detail
} // namespace morea
} // namespace itk

#endif
