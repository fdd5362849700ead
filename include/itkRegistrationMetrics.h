// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: registration quality metrics.
 *
 *  Conventions: a fixed-to-moving displacement field lives on the fixed grid
 *  and maps a fixed point x to the moving point x + u(x) (ITK's convention for
 *  the transform that resamples the moving image onto the fixed grid). An
 *  optional evaluation region (a mask on the grid being scored) restricts
 *  every metric, e.g. to leave out a border margin.
 *=========================================================================*/
#ifndef itkRegistrationMetrics_h
#define itkRegistrationMetrics_h

#include "itkMOREATypes.h"

#include <array>
#include <cstddef>
#include <vector>

namespace itk
{
namespace morea
{
/** Dice = 2|A n B| / (|A| + |B|) over the voxels of `region` (all voxels when null).
 *  Both masks must share one grid. Two empty masks score 1. */
double
ComputeDice(const MaskType * a, const MaskType * b, const MaskType * region = nullptr);

/** Symmetric surface distances between two masks on one grid, in mm, by the
 *  method of DeepMind's surface-distance package as pymia 0.3.4 computes it
 *  (`HausdorffDistance`): a mask's surface is the set of voxel corners whose
 *  2x2x2 neighbourhood holds inside and outside voxels (the space beyond the
 *  image is outside), each weighted by its surface area (SurfaceElementAreas);
 *  directed distances run from each surface element of one mask to the nearest
 *  surface element of the other (exact Euclidean distance transform).
 *  With a region, only surface elements whose whole neighbourhood (within the
 *  image) lies in the region are scored; they are still measured to the other
 *  mask's whole surface (a direction without scored elements adds nothing, and
 *  all three scores are 0 when neither has any). Throws when a mask is empty. */
struct SurfaceDistanceScores
{
  double hausdorff{ 0.0 };   ///< maximum of both directed maxima
  /** Maximum of both directed 95th percentiles; a directed percentile is the
   *  smallest distance whose cumulative area share (distances ascending)
   *  reaches 0.95, without interpolation (as numpy.searchsorted in pymia). */
  double hausdorff95{ 0.0 };
  /** Area-weighted mean of the distances of both directions together. */
  double meanSurfaceDistance{ 0.0 };
};
SurfaceDistanceScores
ComputeSurfaceDistances(const MaskType * a, const MaskType * b, const MaskType * region = nullptr);

/** Area (mm^2) of the surface inside one cell of the voxel-corner grid, per
 *  neighbourhood code. The cell spans the centres of 2x2x2 voxels; bit
 *  (dx + 2 dy + 4 dz) of the code is set when the voxel at offset (dx, dy, dz)
 *  is inside. The surface is a marching-cubes surface through the midpoints of
 *  the cell edges that join an inside and an outside centre (see
 *  itkSurfaceElements.cxx for the triangulation). Codes 0 and 255 have area 0.
 *  Throws unless every spacing is positive and finite. */
using SurfaceElementAreaTable = std::array<double, 256>;
SurfaceElementAreaTable
SurfaceElementAreas(const MaskType::SpacingType & spacing);

/** Target registration error of landmark pairs, in mm. */
struct LandmarkErrorScores
{
  double              mean{ 0.0 };
  double              standardDeviation{ 0.0 };
  double              maximum{ 0.0 };
  std::vector<double> errors;
};
/** Maps each fixed landmark with the fixed-to-moving field (linear interpolation;
 *  identity when the field is null) and measures its distance to the matching
 *  moving landmark. Throws when the lists differ in length or are empty. */
LandmarkErrorScores
ComputeLandmarkErrors(const LandmarkListType &      fixedLandmarks,
                      const LandmarkListType &      movingLandmarks,
                      const DisplacementFieldType * fixedToMoving = nullptr);

/** Fraction of voxels (in `region`) where the Jacobian determinant of x + u(x) is <= 0. */
double
ComputeNonPositiveJacobianFraction(const DisplacementFieldType * field, const MaskType * region = nullptr);

/** Inverse consistency: for each fixed voxel x in `region`, |x + u(x) + v(x + u(x)) - x|,
 *  with u fixed-to-moving (fixed grid) and v moving-to-fixed (moving grid). */
struct InverseConsistencyScores
{
  double mean{ 0.0 };
  double maximum{ 0.0 };
  std::size_t evaluatedPoints{ 0 }; ///< voxels scored
  std::size_t pointsOutside{ 0 };   ///< voxels skipped: x + u(x) left the moving field's grid
};
InverseConsistencyScores
ComputeInverseConsistency(const DisplacementFieldType * fixedToMoving,
                          const DisplacementFieldType * movingToFixed,
                          const MaskType *              region = nullptr);

/** A region mask on `grid` that leaves out every voxel closer than `marginMm`
 *  to the edge of the image domain. */
MaskType::Pointer
MakeBorderMarginRegion(const ImageBase<Dimension> * grid, double marginMm);

/** Resamples a moving-grid mask onto the fixed grid of `fixedToMoving`
 *  (linear interpolation of the mask, threshold 0.5). */
MaskType::Pointer
WarpMask(const MaskType * movingMask, const DisplacementFieldType * fixedToMoving);

/** Resamples a moving image onto the fixed grid of `fixedToMoving` (linear). */
ImageType::Pointer
WarpImage(const ImageType * movingImage, const DisplacementFieldType * fixedToMoving, float defaultValue = 0.0f);

/** Resamples an image or mask onto `grid` without deformation (identity in physical space). */
MaskType::Pointer
ResampleMaskOnto(const MaskType * mask, const ImageBase<Dimension> * grid);

} // namespace morea
} // namespace itk

#endif
