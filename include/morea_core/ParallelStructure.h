// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the linkage model of the mesh (SPEC 4.4).
// FOS elements are edges chosen by a greedy set cover of the points; elements
// whose dependent tetrahedra overlap interact; DSATUR colours the interaction
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

/** Tetrahedra that have any of `points` as a vertex, ascending. */
std::vector<std::uint32_t>
DependentTetrahedra(const MeshTopology & topology, const std::vector<std::uint32_t> & points);

/** Adjacency lists: i and j interact when their dependent tetrahedra overlap. */
std::vector<std::vector<std::uint32_t>>
InteractionGraph(const std::vector<FosElement> & elements, std::size_t numberOfTetrahedra);

/** DSATUR colouring (Brelaz 1979): colour per vertex, adjacent vertices differ. */
std::vector<std::uint32_t>
DsaturColouring(const std::vector<std::vector<std::uint32_t>> & graph);

/** All of the above for one mesh. */
ParallelStructure
BuildParallelStructure(const MeshTopology & topology);
} // namespace morea_core

#endif
