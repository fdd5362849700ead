// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration mesh generation: Delaunay tetrahedralisation of
// points (TetGen), optionally constrained so that given triangles are faces.
#ifndef morea_Tetrahedralization_h
#define morea_Tetrahedralization_h

#include "morea_core/TetrahedralMesh.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace morea_core
{
struct TetrahedralizationResult
{
  /** The input points first, then any Steiner points TetGen had to add to
   *  recover the constraining triangles. */
  std::vector<Vec3>        points;
  std::vector<Tetrahedron> tetrahedra; ///< positively oriented
  std::size_t              steinerPoints{ 0 };
};

struct TetrahedralizationOptions
{
  /** Each TetGen run in a child process (ChildProcess.h), so that TetGen's
   *  crash is an Error here. Costs a fork per run (TetrahedralizationTest
   *  measures it). */
  bool   isolated{ true };
  /** Per run in a child; 0: TimeoutFor's default. TetGen 1.5 can also loop
   *  for ever on some constraint surfaces (one crop of the phantom in 1000
   *  fuzz cases), so a run that takes a thousand times longer than usual is
   *  stopped and counts as failed. */
  double timeoutSeconds{ 0.0 };
  /** Not isolated: after TetGen fails here, try no other switches, as its
   *  failure may have damaged this process's heap (for a child process that
   *  gives up then, and leaves the retries to its parent). */
  bool   noRetryAfterFailure{ false };

  /** The time-out of one run on `points` points: timeoutSeconds, or 5 s plus
   *  1 ms per point (a run of 600 points takes about 3 ms). */
  double
  TimeoutFor(std::size_t points) const
  {
    return timeoutSeconds > 0.0 ? timeoutSeconds : 5.0 + 1e-3 * static_cast<double>(points);
  }
};

/** Tetrahedralises the convex hull of `points`. With `constraintTriangles`
 *  (indices into `points`) the result is a constrained Delaunay mesh in which
 *  every such triangle is a union of mesh faces; TetGen may add Steiner points
 *  for that, first tried without any on the constraints. Throws morea_core::Error
 *  when TetGen fails (e.g. self-intersecting constraints), crashes or hangs. */
TetrahedralizationResult
Tetrahedralize(const std::vector<Vec3> & points,
               const std::vector<std::array<std::uint32_t, 3>> & constraintTriangles = {},
               const TetrahedralizationOptions & options = {});
} // namespace morea_core

#endif
