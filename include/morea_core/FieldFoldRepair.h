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
// field is smoothed locally around such voxels until none remain.
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
  /** Rounds of smoothing before giving up (the remaining folds are reported). */
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
  std::size_t  foldedAfter{ 0 };    ///< ... on return (0 unless the iterations ran out)
  std::size_t  voxelsChanged{ 0 };  ///< voxels whose displacement was smoothed
  unsigned int iterations{ 0 };     ///< smoothing rounds run
  double       maximumChange{ 0.0 }; ///< largest |u_after - u_before| in mm
  /** With an outside-the-mesh mask: the folded voxels on entry that the mesh
   *  does not cover (its map extrapolated there), and the largest change
   *  among the voxels it covers. */
  std::size_t foldedBeforeOutsideMesh{ 0 };
  double      maximumChangeInsideMesh{ 0.0 };
};

/** Removes voxel-level folds: while some voxel has a determinant <= 0, each
 *  voxel within the current radius of a folded voxel takes the mean
 *  displacement of its 3x3x3 neighbourhood (clipped at the grid's edge; all
 *  updates of one round read the previous round's field). Voxels away from
 *  folds keep their exact values. Deterministic and single-threaded (the work
 *  is proportional to the folded region). Throws morea_core::Error on an empty
 *  field or a non-positive spacing. `outsideMesh` (optional, one entry per
 *  voxel, RasterizationReport::outsideMask) splits the report into voxels
 *  the mesh covers and voxels it does not; it does not change the repair. */
FieldFoldRepairReport
RemoveVoxelFolds(Volume<Vec3> & field, const FieldFoldRepairOptions & options = {},
                 const std::vector<std::uint8_t> * outsideMesh = nullptr);
} // namespace morea_core

#endif
