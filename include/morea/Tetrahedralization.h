// MultiObjectiveRegistration mesh generation: Delaunay tetrahedralisation of
// points (TetGen), optionally constrained so that given triangles are faces.
#ifndef morea_Tetrahedralization_h
#define morea_Tetrahedralization_h

#include "morea/TetrahedralMesh.h"

#include <array>
#include <cstdint>
#include <vector>

namespace morea
{
struct TetrahedralizationResult
{
  /** The input points first, then any Steiner points TetGen had to add to
   *  recover the constraining triangles. */
  std::vector<Vec3>        points;
  std::vector<Tetrahedron> tetrahedra; ///< positively oriented
  std::size_t              steinerPoints{ 0 };
};

/** Tetrahedralises the convex hull of `points`. With `constraintTriangles`
 *  (indices into `points`) the result is a constrained Delaunay mesh in which
 *  every such triangle is a union of mesh faces; TetGen may add Steiner points
 *  for that, first tried without any on the constraints. Throws morea::Error
 *  when TetGen fails (e.g. self-intersecting constraints). */
TetrahedralizationResult
Tetrahedralize(const std::vector<Vec3> & points,
               const std::vector<std::array<std::uint32_t, 3>> & constraintTriangles = {});
} // namespace morea

#endif
