// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: choosing well-spread mesh points.
#ifndef morea_MeshPointPlacement_h
#define morea_MeshPointPlacement_h

#include "morea_core/Random.h"
#include "morea_core/TetrahedralMesh.h"
#include "morea_core/Volume.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace morea_core
{
/** Greedy spread-out (farthest-point) subset: up to `count` of `candidates`,
 *  each the candidate farthest from everything chosen so far and from
 *  `existing`. Stops early when the best remaining candidate is closer than
 *  `minimumDistance` to a chosen point (so no near-duplicates). Deterministic:
 *  without existing points the first pick is the candidate nearest the
 *  candidates' centroid. */
std::vector<Vec3>
SpreadOutSubset(const std::vector<Vec3> & candidates, std::size_t count, const std::vector<Vec3> & existing,
                double minimumDistance);

/** `count` random points, each the best of `candidatesPerPoint` draws of
 *  `draw` (the one farthest from `existing` and the points drawn before), so
 *  random points do not clump (Mitchell's best-candidate sampling). */
std::vector<Vec3>
BestCandidateRandomPoints(std::size_t count, const std::function<Vec3(RandomGenerator &)> & draw,
                          const std::vector<Vec3> & existing, RandomGenerator & random,
                          std::size_t candidatesPerPoint = 10);

/** Centres of the mask's voxels that have a 6-neighbour outside the mask (or
 *  on the grid's border): the structure's contour points. */
std::vector<Vec3>
MaskBoundaryPoints(const Volume<std::uint8_t> & mask);

/** Per voxel, the distance in mm from its centre to the nearest centre of a
 *  mask voxel (0 inside the mask; infinity everywhere when the mask is
 *  empty): the exact Euclidean distance transform, one axis at a time
 *  (Felzenszwalb and Huttenlocher 2012), with the mask's spacing. */
Volume<float>
DistanceToMask(const Volume<std::uint8_t> & mask);

/** Centres of the voxels outside a mask whose distance to it (`distance`,
 *  from DistanceToMask) is within half the largest voxel spacing of `offset`
 *  mm: candidates for points on a shell around a structure. Empty when the
 *  shell leaves the grid. */
std::vector<Vec3>
ShellPoints(const Volume<float> & distance, double offset);

/** The 8 corners of the domain. */
std::vector<Vec3>
DomainCorners(const MeshDomain & domain);
} // namespace morea_core

#endif
