// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration mesh generation: checks of constraint surfaces
// before TetGen sees them. A decimated marching-cubes surface can fold onto
// itself where the structure is thin, or come apart where the crop cuts it,
// and two structures' surfaces can cross where the organs touch; TetGen
// cannot recover such triangles as mesh faces (and TetGen 1.5 crashes when it
// finds out, see ChildProcess.h), so they are found and dropped beforehand.
#ifndef morea_SurfaceCheck_h
#define morea_SurfaceCheck_h

#include "morea_core/StructureSurface.h"

#include <cstddef>
#include <string>

namespace morea_core
{
struct SurfaceDefects
{
  std::size_t openEdges{ 0 };           ///< edges of one triangle only (a hole)
  std::size_t nonManifoldEdges{ 0 };    ///< edges of more than two triangles
  std::size_t misorientedEdges{ 0 };    ///< edges two triangles run the same way (inconsistent orientation)
  std::size_t degenerateTriangles{ 0 }; ///< of (nearly) zero area
  std::size_t duplicateVertices{ 0 };   ///< at the position of another vertex
  std::size_t crossingPairs{ 0 };       ///< pairs of triangles that intersect (other than along shared edges)

  bool
  Valid() const
  {
    return openEdges + nonManifoldEdges + misorientedEdges + degenerateTriangles + duplicateVertices +
             crossingPairs ==
           0;
  }
  /** "3 open edges, 1 pair of crossing triangles"; "" when valid. */
  std::string
  Describe() const;
};

/** Whether `surface` is a closed, consistently oriented 2-manifold (any
 *  number of components) without degenerate triangles, duplicate vertices or
 *  self-intersections. */
SurfaceDefects
CheckSurface(const TriangleSurface & surface);

/** The pairs of triangles, one of `a` and one of `b`, that intersect or
 *  touch: two surfaces that must both be mesh faces may not. */
std::size_t
CountCrossings(const TriangleSurface & a, const TriangleSurface & b);
} // namespace morea_core

#endif
