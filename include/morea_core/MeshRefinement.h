// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: refining a mesh between resolution levels.
//
// Conforming longest-edge bisection: an edge is split at its midpoint and
// every tetrahedron around it is cut in two there. Each new point is the
// midpoint of two older ones, so a solution of the coarse mesh carries over
// exactly: its midpoints in both meshes reproduce the same piecewise-affine
// map, every child tetrahedron keeps its parent's orientation (a fold-free
// solution stays fold-free) and its parent's volume ratio (the fold
// constraint's fraction holds alike).
//
// Where to refine: each tetrahedron has a density (how much it needs points:
// image mismatch, contour distance, strain) and the one whose density times
// volume is largest is bisected on its longest edge, until the mesh has the
// points asked for. Uniform density refines the largest tetrahedra first.
#ifndef morea_MeshRefinement_h
#define morea_MeshRefinement_h

#include "morea_core/TetrahedralMesh.h"
#include "morea_core/TetrahedronObjectives.h"

#include <array>
#include <cstdint>
#include <vector>

namespace morea_core
{
class ParameterSet;

/** When each mesh level runs: level k from FirstGeneration(k) to
 *  EndGeneration(k); the last level ends at ea_num_generations. */
struct MeshLevelPlan
{
  std::size_t levels{ 1 };
  std::size_t generationsPerLevel{ 0 }; ///< of each level but the last
  std::size_t generations{ 500 };       ///< of the whole run
  double      pointFactor{ 2.3 };       ///< points of a level over the level before's

  /** morea_max_num_mesh_levels, morea_num_generations_per_level,
   *  morea_mesh_refinement_factor and ea_num_generations. Throws
   *  morea_core::Error, naming the keys, when levels after the first would get
   *  no generation or levels but the last none. */
  static MeshLevelPlan
  FromParameters(const ParameterSet & parameters);

  std::size_t
  FirstGeneration(std::size_t level) const
  {
    return level * generationsPerLevel;
  }
  std::size_t
  EndGeneration(std::size_t level) const
  {
    return level + 1 == levels ? generations : (level + 1) * generationsPerLevel;
  }
  /** The points level `level` is refined to from `coarsePoints` at level 0. */
  std::size_t
  PointsAt(std::size_t level, std::size_t coarsePoints) const;
};

struct MeshRefinement
{
  TetrahedralMesh mesh; ///< the refined mesh; its first points are the coarse mesh's, in order
  /** For each new point (index coarse points + i): the two points, coarse
   *  or new and earlier, whose midpoint it is. */
  std::vector<std::array<std::uint32_t, 2>> midpointOf;
  /** Per refined tetrahedron, the coarse tetrahedron it lies in. */
  std::vector<std::uint32_t> parentTetrahedron;
};

/** Bisects `coarse` until it has `targetPoints` points (at least its own).
 *  `density` holds one positive value per coarse tetrahedron; children
 *  inherit their parent's. Deterministic. Throws morea_core::Error when `density`
 *  does not match the mesh or holds a value that is not positive and finite. */
MeshRefinement
RefineMesh(const TetrahedralMesh & coarse, const std::vector<double> & density, std::size_t targetPoints);

/** A coarse solution on the refined mesh: the same deformation. */
DualMesh
CarryOver(const MeshRefinement & refinement, const DualMesh & coarse);

/** The density RefineMesh uses, from the per-tetrahedron values of some
 *  solutions of the coarse mesh (values[s][t]): 1 plus, each scaled to mean 1
 *  over the mesh, the intensity mismatch and the guidance per sample and the
 *  strain (magnitude per squared edge length of the base tetrahedron), so
 *  that points go where the images or contours still disagree and where the
 *  deformation bends most. */
std::vector<double>
RefinementDensity(const TetrahedralMesh & base, const std::vector<std::vector<TetrahedronValues>> & values);
} // namespace morea_core

#endif
