// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the Gaussian repair operator (SPEC 5,
// morea_repair_method = "gaussian") that moves points of folded tetrahedra
// until the mesh is fold-free again.
#ifndef morea_MeshRepair_h
#define morea_MeshRepair_h

#include "morea_core/FoldConstraint.h"
#include "morea_core/Random.h"
#include "morea_core/TetrahedralMesh.h"

#include <cstddef>
#include <vector>

namespace morea_core
{
struct RepairOptions
{
  std::size_t samplesPerPoint{ 64 };
  std::size_t maxRounds{ 10 }; ///< passes over the points of folded tetrahedra
};

struct RepairResult
{
  FoldViolation before;
  FoldViolation after;
  std::size_t   movedPoints{ 0 };

  bool
  Repaired() const
  {
    return after.Feasible();
  }
};

/** Repairs one mesh (`points`, with the base mesh's pins and domain) in place.
 *  Each point of a folded tetrahedron draws `samplesPerPoint` Gaussian moves
 *  whose scale is the point's mean distance to the planes of the faces
 *  opposite it (its surrounding polyhedron); the move that lowers the
 *  violation of the point's tetrahedra most is kept (trials are ranked by the
 *  star terms of RepairStar.h: the same violations, rounded otherwise; the
 *  results before/after are the constraint's own). A point whose samples all
 *  make things worse is left alone; the repair stops when a whole pass moves
 *  nothing, when the mesh is fold-free, or after maxRounds passes. */
RepairResult
RepairFolds(std::vector<Vec3> & points, const TetrahedralMesh & base, const FoldConstraint & constraint,
            RandomGenerator & random, const RepairOptions & options = {});

/** The same, moving only the points in `movable` (null: all) and looking only
 *  at the tetrahedra in `scope` (null: all; it must hold every tetrahedron of
 *  the movable points). A variation step repairs only the points it moved
 *  within its dependent tetrahedra, so that candidates of one parallel group
 *  stay independent; before/after then count the scope only. The moves come
 *  from RepairTrialNormals(seed, ...): points are visited in ascending index
 *  and the first trial with the lowest (violation, folded count) wins, so a
 *  parallel implementation can reproduce the repair. */
RepairResult
RepairPoints(std::vector<Vec3> & points, const std::vector<std::uint32_t> * movable,
             const std::vector<std::uint32_t> * scope, const TetrahedralMesh & base, const FoldConstraint & constraint,
             std::uint64_t seed, const RepairOptions & options = {});
/** Both meshes of a solution. */
RepairResult
RepairFolds(DualMesh & solution, const TetrahedralMesh & base, const FoldConstraint & constraint,
            RandomGenerator & random, const RepairOptions & options = {});
} // namespace morea_core

#endif
