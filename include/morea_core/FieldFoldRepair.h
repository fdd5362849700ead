// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: voxel-level fold repair of a rasterised
// displacement field.
//
// A solution whose tetrahedra all keep their orientation is a fold-free
// piecewise-affine map, yet its field sampled at voxel centres can show a
// non-positive finite-difference Jacobian where a strongly compressed
// tetrahedron meets a stretched neighbour: a central difference spans two
// voxels and mixes the gradients of several tetrahedra. Users (and every
// tool that scores registrations) measure folds on the voxel field, so the
// field is changed around such voxels until none remain: first by a
// projection that moves each voxel as little as it can (on the abdominal
// pair's folded fields at most 2.5-6.3 mm, where local smoothing moved
// voxels by 50 mm; bench/results/generation-budget.md), and by local
// smoothing only where the projection does not converge.
#ifndef morea_FieldFoldRepair_h
#define morea_FieldFoldRepair_h

#include "morea_core/Volume.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace morea_core
{
/** Jacobian determinant of x -> x + u(x) at voxel (i,j,k): central
 *  differences over the spacing, one-sided at the grid's edge (the convention
 *  of the ITK layer's fold metric; rotating the frame does not change it). */
double
JacobianDeterminantAt(const Volume<Vec3> & field, std::size_t i, std::size_t j, std::size_t k);

/** Number of voxels whose Jacobian determinant is <= 0. */
std::size_t
CountNonPositiveJacobians(const Volume<Vec3> & field);

struct FieldFoldRepairOptions
{
  /** The projection: each round, every voxel whose determinant is below
   *  half of `projectionTarget` asks for the smallest change of the
   *  displacements its determinant reads that lifts it, linearised, to the
   *  target; the requests are summed and `projectionStep` of the sum
   *  applied. It stops when no determinant is <= 0, or after
   *  `maximumProjectionRounds` (0: smoothing only). */
  double       projectionTarget{ 0.01 };
  double       projectionStep{ 0.9 };
  unsigned int maximumProjectionRounds{ 3000 };
  /** Threads of the projection (0: HostThreads()); the result does not
   *  depend on them. */
  std::size_t threads{ 0 };
  /** The last resort, for folds the projection leaves: rounds of smoothing
   *  before giving up (the remaining folds are reported). */
  unsigned int maximumIterations{ 400 };
  /** The smoothed neighbourhood of each folded voxel starts at this Chebyshev
   *  radius (voxels) and grows by one every `iterationsPerRadius` rounds...
   *  (A slow growth changes less: on the abdominal pair's folded fields 40
   *  rounds per radius smoothed 16-18 % fewer voxels than 10, for one and a
   *  half times the rounds; bench/results/generation-budget.md.) */
  unsigned int initialRadius{ 1 };
  unsigned int iterationsPerRadius{ 40 };
  /** ...up to this radius. */
  unsigned int maximumRadius{ 8 };
};

struct FieldFoldRepairReport
{
  std::size_t  foldedBefore{ 0 };   ///< voxels with determinant <= 0 on entry
  std::size_t  foldedAfter{ 0 };    ///< ... on return (0 unless both repairs ran out of rounds)
  std::size_t  voxelsChanged{ 0 };  ///< voxels whose displacement was changed
  std::size_t  voxelsChangedOver1mm{ 0 }; ///< ... by more than 1 mm
  unsigned int projectionRounds{ 0 };
  unsigned int smoothingRounds{ 0 }; ///< 0 unless the projection left folds
  double       maximumChange{ 0.0 }; ///< largest |u_after - u_before| in mm
  /** With an outside-the-mesh mask: the folded voxels on entry that the mesh
   *  does not cover (its map extrapolated there), and the largest change
   *  among the voxels it covers. */
  std::size_t foldedBeforeOutsideMesh{ 0 };
  double      maximumChangeInsideMesh{ 0.0 };
};

/** Removes voxel-level folds: the projection (see FieldFoldRepairOptions),
 *  then, if folds remain, rounds in which each voxel within the current
 *  radius of a folded voxel takes the mean displacement of its 3x3x3
 *  neighbourhood (clipped at the grid's edge; all updates of one round read
 *  the previous round's field). Voxels away from folds keep their exact
 *  values. Deterministic (the work is proportional to the folded region; the
 *  smoothing is single-threaded). Throws morea_core::Error on an empty field, a
 *  non-positive spacing or a projection target <= 0 or step outside (0, 1].
 *  `outsideMesh` (optional, one entry per voxel,
 *  RasterizationReport::outsideMask) splits the report into voxels the mesh
 *  covers and voxels it does not; it does not change the repair. */
FieldFoldRepairReport
RemoveVoxelFolds(Volume<Vec3> & field, const FieldFoldRepairOptions & options = {},
                 const std::vector<std::uint8_t> * outsideMesh = nullptr);
} // namespace morea_core

#endif
