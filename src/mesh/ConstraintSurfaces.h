// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration mesh generation (the mesh layer's own header):
// structure surfaces made fit to constrain TetGen, and the constrained
// tetrahedralisation that falls back to fewer surfaces, then none, when
// TetGen fails or crashes on them. Each step down leaves a note.
#ifndef morea_ConstraintSurfaces_h
#define morea_ConstraintSurfaces_h

#include "morea_core/StructureSurface.h"
#include "morea_core/TetrahedralMesh.h"
#include "morea_core/Tetrahedralization.h"

#include <optional>
#include <string>
#include <vector>

namespace morea_core
{
/** The closed surface of `mask` (about `targetVertices` vertices) with every
 *  vertex at least `margin` inside `domain`, without self-intersections and
 *  not meeting any of `others`. A surface cut by the domain is closed a few
 *  voxels inside it; a surface that decimation folded onto itself is made
 *  again at other decimation levels. Nothing (and a note naming `name` and
 *  the reason) when no such surface can be made. */
std::optional<TriangleSurface>
PrepareConstraintSurface(const std::string & name, const Volume<std::uint8_t> & mask, const MeshDomain & domain,
                         std::size_t targetVertices, double margin, const std::vector<TriangleSurface> & others,
                         std::vector<std::string> & notes);

/** Constrained tetrahedralisation of a changing point set (points are added
 *  and moved between runs) with named groups of constraint triangles. */
class ConstrainedTetrahedralization
{
public:
  explicit ConstrainedTetrahedralization(TetrahedralizationOptions options = {})
    : m_Options(options)
  {}

  /** The same surfaces, with TetGen run as `options` say. */
  ConstrainedTetrahedralization
  WithOptions(const TetrahedralizationOptions & options) const
  {
    ConstrainedTetrahedralization copy = *this;
    copy.m_Options = options;
    return copy;
  }

  /** A structure's triangles, as indices into the points given to Run. */
  void
  AddSurface(std::string name, std::vector<std::array<std::uint32_t, 3>> triangles);

  /** Tetrahedralises `points` with the surfaces still in use. When TetGen
   *  fails with them and `mayDropSurfaces`, the surfaces are tried again one
   *  by one and those TetGen fails on are dropped for good (a note each),
   *  down to none; otherwise the failure is thrown (morea_core::Error). */
  TetrahedralizationResult
  Run(const std::vector<Vec3> & points, bool mayDropSurfaces, std::vector<std::string> & notes);

  /** The triangles of the surfaces in use. */
  std::vector<std::array<std::uint32_t, 3>>
  Triangles() const;

  std::size_t
  NumberOfSurfaces() const
  {
    return m_Surfaces.size();
  }

private:
  struct Surface
  {
    std::string                               name;
    std::vector<std::array<std::uint32_t, 3>> triangles;
  };
  std::vector<std::array<std::uint32_t, 3>>
  TrianglesOf(const std::vector<Surface> & surfaces) const;

  TetrahedralizationOptions m_Options;
  std::vector<Surface>      m_Surfaces;
};
} // namespace morea_core

#endif
