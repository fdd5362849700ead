// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the dual-dynamic tetrahedral mesh model.
//
// One topology (tetrahedra over point indices) is shared by two point sets:
// the source mesh on the moving image and the target mesh on the fixed image.
// A solution moves both point sets; the piecewise-affine map that takes each
// source tetrahedron onto its target twin is the registration.
//
// Coordinates are in the domain frame: millimetres along the image grid's
// axes, with the first voxel centre at the origin given by the grid (the ITK
// layer converts to and from physical space).
#ifndef morea_TetrahedralMesh_h
#define morea_TetrahedralMesh_h

#include "morea_core/Volume.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace morea_core
{
using Tetrahedron = std::array<std::uint32_t, 4>;
using Edge = std::array<std::uint32_t, 2>; ///< first < second

/** The axis-aligned box the meshes cover: the cropped image domain, from the
 *  first to the last voxel centre, so every sample inside the mesh can be
 *  interpolated and every voxel centre is inside the mesh. */
struct MeshDomain
{
  Vec3 lower{ { 0.0, 0.0, 0.0 } };
  Vec3 upper{ { 0.0, 0.0, 0.0 } };

  /** The box spanned by the voxel centres of `grid` (a Volume, or any grid
   *  with its size, spacing and origin). */
  template <typename TGrid>
  static MeshDomain
  OfGrid(const TGrid & grid)
  {
    MeshDomain d;
    for (int a = 0; a < 3; ++a)
    {
      d.lower[a] = grid.origin[a];
      d.upper[a] = grid.origin[a] + grid.spacing[a] * static_cast<double>(grid.size[a] - 1);
    }
    return d;
  }
  Vec3
  Extent() const
  {
    return { upper[0] - lower[0], upper[1] - lower[1], upper[2] - lower[2] };
  }
};

/** How a point is held on the domain boundary during optimisation.
 *  Per axis: -1 pinned to the lower face, +1 to the upper face, 0 free.
 *  Corners have three pinned axes (fixed), points on box edges two (they slide
 *  along the edge), points on faces one (they slide within the face), inner
 *  points none. So both meshes always cover exactly the domain. */
using BoundaryPin = std::array<std::int8_t, 3>;

/** Where a mesh point came from (for inspection and export). */
enum class PointOrigin : std::int8_t
{
  Corner,
  BoundaryFace,
  Random,
  Contour,   ///< a spread-out contour point of a structure
  Surface,   ///< a vertex of a constraining structure surface
  Steiner,   ///< added by the tetrahedraliser to recover a surface
  Refinement, ///< at the circumcentre of a poorly shaped tetrahedron (removes slivers)
  Midpoint,   ///< of an edge bisected between mesh resolution levels (MeshRefinement.h)
  Shell       ///< on a shell at a set distance around a structure (MeshGeneratorOptions::shellOffsets)
};

/** The base mesh: one configuration of points plus topology and boundary pins. */
struct TetrahedralMesh
{
  MeshDomain                 domain;
  std::vector<Vec3>          points;
  std::vector<Tetrahedron>   tetrahedra; ///< positively oriented in `points`
  std::vector<BoundaryPin>   pins;       ///< one per point
  std::vector<PointOrigin>   origins;    ///< one per point
  std::vector<std::int32_t>  structures; ///< per point: structure index, -1 for none
  /** Structure-surface triangles the tetrahedralisation was constrained to
   *  keep (each is a union of mesh faces; a single face without Steiner points). */
  std::vector<std::array<std::uint32_t, 3>> constrainedFaces;

  std::size_t
  NumberOfPoints() const
  {
    return points.size();
  }
  std::size_t
  NumberOfTetrahedra() const
  {
    return tetrahedra.size();
  }
};

/** A solution of the dual-dynamic model: both meshes' point positions. */
struct DualMesh
{
  std::vector<Vec3> source; ///< on the moving image
  std::vector<Vec3> target; ///< on the fixed image

  /** Both meshes at the base configuration. */
  static DualMesh
  FromBase(const TetrahedralMesh & base)
  {
    return DualMesh{ base.points, base.points };
  }
};

/** Adjacency derived once from the tetrahedra: tetrahedra around each point and
 *  the unique edges. */
class MeshTopology
{
public:
  MeshTopology() = default;
  MeshTopology(const std::vector<Tetrahedron> & tetrahedra, std::size_t numberOfPoints);

  std::size_t
  NumberOfPoints() const
  {
    return m_PointTetOffsets.empty() ? 0 : m_PointTetOffsets.size() - 1;
  }
  std::size_t
  NumberOfTetrahedra() const
  {
    return m_Tetrahedra.size();
  }
  const std::vector<Tetrahedron> &
  Tetrahedra() const
  {
    return m_Tetrahedra;
  }
  /** Tetrahedra that have `point` as a vertex, ascending. */
  const std::uint32_t *
  TetrahedraOfPointBegin(std::size_t point) const
  {
    return m_PointTets.data() + m_PointTetOffsets[point];
  }
  const std::uint32_t *
  TetrahedraOfPointEnd(std::size_t point) const
  {
    return m_PointTets.data() + m_PointTetOffsets[point + 1];
  }
  std::vector<std::uint32_t>
  TetrahedraOfPoint(std::size_t point) const
  {
    return { TetrahedraOfPointBegin(point), TetrahedraOfPointEnd(point) };
  }
  /** Unique edges, sorted. */
  const std::vector<Edge> &
  Edges() const
  {
    return m_Edges;
  }
  /** Points sharing an edge with `point`, ascending. */
  std::vector<std::uint32_t>
  Neighbours(std::size_t point) const;

private:
  std::vector<Tetrahedron>   m_Tetrahedra;
  std::vector<std::size_t>   m_PointTetOffsets;
  std::vector<std::uint32_t> m_PointTets;
  std::vector<Edge>          m_Edges;
  std::vector<std::size_t>   m_PointEdgeOffsets;
  std::vector<std::uint32_t> m_PointNeighbours;
};

/** Six times the signed volume would lose precision for no gain: this is the
 *  true signed volume, det[b-a, c-a, d-a] / 6 (positive for a right-handed
 *  vertex order). */
double
SignedVolume(const Vec3 & a, const Vec3 & b, const Vec3 & c, const Vec3 & d);

inline double
SignedVolume(const Tetrahedron & t, const std::vector<Vec3> & points)
{
  return SignedVolume(points[t[0]], points[t[1]], points[t[2]], points[t[3]]);
}

/** Shape quality 6*sqrt(2)*V / l_rms^3: 1 for a regular tetrahedron, 0 for
 *  a flat one, negative when inverted. */
double
TetrahedronQuality(const Vec3 & a, const Vec3 & b, const Vec3 & c, const Vec3 & d);

/** Puts `p` back where `pin` allows: pinned axes on their face, free axes
 *  clamped into the domain. */
Vec3
ProjectToDomain(const Vec3 & p, const BoundaryPin & pin, const MeshDomain & domain);

/** The pin of a point lying on the domain boundary within `tolerance`. */
BoundaryPin
PinOf(const Vec3 & p, const MeshDomain & domain, double tolerance);
} // namespace morea_core

#endif
