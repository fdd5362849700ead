// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: dense displacement fields from a solution's
// two meshes (the piecewise-affine map between twin tetrahedra).
#ifndef morea_MeshRasterizer_h
#define morea_MeshRasterizer_h

#include "morea_core/TetrahedralMesh.h"
#include "morea_core/Volume.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace morea_core
{
struct RasterizationReport
{
  std::size_t voxels{ 0 };
  std::size_t outsideMesh{ 0 }; ///< voxels no tetrahedron of `from` contains (extrapolated)
  /** Per voxel (offset order), 1 where no tetrahedron of `from` contains its
   *  centre; filled only when `outsideMesh` > 0, else empty. */
  std::vector<std::uint8_t> outsideMask;
};

/** Fills `field` (whose size, spacing and origin give the grid, in the domain
 *  frame) with u(x) = M(x) - x at every voxel centre x, where M is the
 *  piecewise-affine map taking each tetrahedron of `from` onto its twin in
 *  `to`. Voxels that no tetrahedron of `from` contains (only possible when the
 *  mesh does not cover the grid) take the affine map of the tetrahedron of the
 *  nearest contained voxel (breadth-first over 6-neighbours), so the map is
 *  extrapolated affinely. Tetrahedra of `from` with (near-)zero volume are
 *  skipped; a voxel centre on a face shared by several tetrahedra takes the map
 *  of the lowest-indexed one. Multi-threaded; the result does not depend on the
 *  number of threads. `field.data` is (re)allocated. Throws morea_core::Error when
 *  the meshes do not match the topology, a point is not finite, the spacing is
 *  not positive, or no voxel centre lies inside the mesh.
 *
 *  For a solution (source on the moving image, target on the fixed image):
 *  from = target, to = source on the fixed grid gives the fixed-to-moving field
 *  ITK resamples the moving image with; from = source, to = target on the
 *  moving grid gives the moving-to-fixed field. */
void
RasterizeDisplacement(const MeshTopology & topology, const std::vector<Vec3> & from, const std::vector<Vec3> & to,
                      Volume<Vec3> & field, RasterizationReport * report = nullptr);
} // namespace morea_core

#endif
