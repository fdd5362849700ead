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

/** Symmetric surface distances between two masks on one grid, in mm. */
struct SurfaceDistanceScores
{
  double hausdorff{ 0.0 };   ///< maximum of both directed distances
  double hausdorff95{ 0.0 }; ///< 95th percentile Hausdorff distance
  double meanSurfaceDistance{ 0.0 };
};
SurfaceDistanceScores
ComputeSurfaceDistances(const MaskType * a, const MaskType * b, const MaskType * region = nullptr);

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
