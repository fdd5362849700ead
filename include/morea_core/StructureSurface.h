// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration mesh generation: the surface of a structure as a
// closed triangle mesh, to constrain the tetrahedralisation (its triangles
// become mesh faces, so the mesh follows the organ's boundary).
#ifndef morea_StructureSurface_h
#define morea_StructureSurface_h

#include "morea_core/Volume.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace morea_core
{
struct TriangleSurface
{
  std::vector<Vec3>                         vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/** Marching cubes (VTK) of `mask` at its boundary after a light Gaussian blur
 *  (sigma one voxel, so the surface is not a staircase), then quadric
 *  decimation to about `targetVertices` vertices. Vertices are in the frame of
 *  the mask's grid. Empty result for an empty mask. */
TriangleSurface
ExtractStructureSurface(const Volume<std::uint8_t> & mask, std::size_t targetVertices);
} // namespace morea_core

#endif
