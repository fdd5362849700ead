// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the linkage model of the mesh (SPEC 4.4).
// FOS elements are edges chosen by a greedy set cover of the points (or, on
// refined mesh levels, connected groups of points); elements whose dependent
// tetrahedra overlap interact; DSATUR colours the interaction
// graph into parallel groups whose elements can be varied and evaluated at
// the same time without touching each other's tetrahedra.
#ifndef morea_ParallelStructure_h
#define morea_ParallelStructure_h

#include "morea_core/TetrahedralMesh.h"

#include <cstdint>
#include <vector>

namespace morea_core
{
struct FosElement
{
  std::vector<std::uint32_t> points;              ///< mesh points whose 6 coordinates vary together
  std::vector<std::uint32_t> dependentTetrahedra; ///< re-evaluated when they move; ascending
};

struct ParallelStructure
{
  std::vector<FosElement>                 elements;
  std::vector<std::vector<std::uint32_t>> interactions; ///< interaction graph, adjacency lists
  std::vector<std::uint32_t>              colour;       ///< per element
  std::vector<std::vector<std::uint32_t>> groups;       ///< elements per colour
};

/** Edges covering every point: first a greedy maximal matching that prefers
 *  points with few free neighbours (each chosen edge covers two new points),
 *  then one edge for each point left over. */
std::vector<Edge>
GreedyEdgeCover(const MeshTopology & topology);

/** Connected groups of about `size` points that cover every point once.
 *  A group starts at the free point with the fewest free neighbours and
 *  takes the free neighbour nearest its first point until it is full; a
 *  group left with fewer than half that joins its smallest neighbouring
 *  group when the two hold at most twice the size. No group is larger than
 *  that; `size` 1 gives one group per point. */
std::vector<std::vector<std::uint32_t>>
GreedyPointGroups(const MeshTopology & topology, const std::vector<Vec3> & points, std::size_t size);

/** Tetrahedra that have any of `points` as a vertex, ascending. */
std::vector<std::uint32_t>
DependentTetrahedra(const MeshTopology & topology, const std::vector<std::uint32_t> & points);

/** Adjacency lists: i and j interact when their dependent tetrahedra overlap. */
std::vector<std::vector<std::uint32_t>>
InteractionGraph(const std::vector<FosElement> & elements, std::size_t numberOfTetrahedra);

/** DSATUR colouring (Brelaz 1979): colour per vertex, adjacent vertices differ. */
std::vector<std::uint32_t>
DsaturColouring(const std::vector<std::vector<std::uint32_t>> & graph);

/** All of the above for one mesh, with the edge cover's elements. */
ParallelStructure
BuildParallelStructure(const MeshTopology & topology);

/** All of the above with the given elements (their points). */
ParallelStructure
BuildParallelStructure(const MeshTopology & topology, const std::vector<std::vector<std::uint32_t>> & elementPoints);
} // namespace morea_core

#endif
