// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/MeshRasterizer.h"

#include "morea_core/Error.h"
#include "morea_core/ParallelForThreads.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace morea_core
{
namespace
{
using Mat3 = std::array<Vec3, 3>; // rows

constexpr std::uint32_t NoTetrahedron = std::numeric_limits<std::uint32_t>::max();

/** Barycentric slack: a voxel centre on a shared face (or a hair outside the
 *  mesh boundary through round-off) still counts as inside; the lowest
 *  tetrahedron index wins, so the slack cannot make the result depend on
 *  thread scheduling. */
constexpr double BarycentricTolerance = 1e-9;

/** Everything the rasteriser needs of one tetrahedron of `from`. */
struct TetrahedronMap
{
  bool                       valid{ false };       ///< false for (near-)degenerate tetrahedra of `from`
  Vec3                       anchor{};             ///< vertex 0 in `from`
  Mat3                       toBarycentric{};      ///< inverse edge matrix: (l1,l2,l3) = toBarycentric * (x - anchor)
  Vec3                       anchorDisplacement{}; ///< u at the anchor: vertex 0 in `to` minus in `from`
  Mat3                       gradient{};           ///< du/dx, constant in the tetrahedron
  std::array<std::size_t, 3> lower{};              ///< voxel index bounding box, inclusive
  std::array<std::size_t, 3> upper{};
  bool                       inGrid{ false };
};

Vec3
Minus(const Vec3 & a, const Vec3 & b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}

double
Norm(const Vec3 & a)
{
  return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

/** Inverse of the matrix whose columns are e0, e1, e2, or false when it is
 *  (nearly) singular relative to the edge lengths. */
bool
InvertColumns(const Vec3 & e0, const Vec3 & e1, const Vec3 & e2, Mat3 & inverse)
{
  // Rows of the inverse are the cross products of the columns over the determinant.
  const Vec3   c12{ e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
  const Vec3   c20{ e2[1] * e0[2] - e2[2] * e0[1], e2[2] * e0[0] - e2[0] * e0[2], e2[0] * e0[1] - e2[1] * e0[0] };
  const Vec3   c01{ e0[1] * e1[2] - e0[2] * e1[1], e0[2] * e1[0] - e0[0] * e1[2], e0[0] * e1[1] - e0[1] * e1[0] };
  const double det = e0[0] * c12[0] + e0[1] * c12[1] + e0[2] * c12[2];
  // Relative to the edge lengths, so the test does not depend on the unit of length.
  const double scale = Norm(e0) * Norm(e1) * Norm(e2);
  if (!(std::abs(det) > 1e-12 * scale))
  {
    return false;
  }
  for (int c = 0; c < 3; ++c)
  {
    inverse[0][c] = c12[c] / det;
    inverse[1][c] = c20[c] / det;
    inverse[2][c] = c01[c] / det;
  }
  return true;
}

TetrahedronMap
MakeTetrahedronMap(const Tetrahedron & t, const std::vector<Vec3> & from, const std::vector<Vec3> & to,
                   const Volume<Vec3> & grid)
{
  TetrahedronMap m;
  const Vec3 &   a = from[t[0]];
  const Vec3     e[3] = { Minus(from[t[1]], a), Minus(from[t[2]], a), Minus(from[t[3]], a) };
  if (!InvertColumns(e[0], e[1], e[2], m.toBarycentric))
  {
    return m;
  }
  m.valid = true;
  m.anchor = a;
  // Vertex displacements relative to the anchor's: gradient = dU * E^-1. Working
  // with displacements (not positions) makes identical meshes give exactly zero.
  m.anchorDisplacement = Minus(to[t[0]], a);
  Vec3 dU[3];
  for (int v = 0; v < 3; ++v)
  {
    dU[v] = Minus(Minus(to[t[v + 1]], from[t[v + 1]]), m.anchorDisplacement);
  }
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      m.gradient[r][c] =
        dU[0][r] * m.toBarycentric[0][c] + dU[1][r] * m.toBarycentric[1][c] + dU[2][r] * m.toBarycentric[2][c];
    }
  }

  // Voxel bounding box, with a small margin: the barycentric test decides.
  m.inGrid = true;
  for (int d = 0; d < 3; ++d)
  {
    double lo = a[d];
    double hi = a[d];
    for (int v = 1; v < 4; ++v)
    {
      lo = std::min(lo, from[t[v]][d]);
      hi = std::max(hi, from[t[v]][d]);
    }
    const double first = std::ceil((lo - grid.origin[d]) / grid.spacing[d] - 1e-6);
    const double last = std::floor((hi - grid.origin[d]) / grid.spacing[d] + 1e-6);
    const double maxIndex = static_cast<double>(grid.size[d]) - 1.0;
    if (last < 0.0 || first > maxIndex)
    {
      m.inGrid = false;
      return m;
    }
    m.lower[d] = static_cast<std::size_t>(std::max(first, 0.0));
    m.upper[d] = static_cast<std::size_t>(std::min(last, maxIndex));
  }
  return m;
}

Vec3
DisplacementAt(const TetrahedronMap & m, const Vec3 & x)
{
  const Vec3 r = Minus(x, m.anchor);
  Vec3       u;
  for (int d = 0; d < 3; ++d)
  {
    u[d] = m.anchorDisplacement[d] + m.gradient[d][0] * r[0] + m.gradient[d][1] * r[1] + m.gradient[d][2] * r[2];
  }
  return u;
}

/** Marks each voxel of the tetrahedron's scanlines within slices [kBegin, kEnd)
 *  with `index` unless a lower-indexed tetrahedron already holds it. */
void
MarkTetrahedron(const TetrahedronMap & m, std::uint32_t index, const Volume<Vec3> & grid, std::size_t kBegin,
                std::size_t kEnd, std::vector<std::uint32_t> & owner)
{
  // Barycentric coordinates are affine in the voxel index: l(i,j,k) = base + i*di + j*dj + k*dk.
  Vec3       base;    // l1..l3 at voxel (0,0,0)
  Vec3       step[3]; // step[axis][b]: change of l(b+1) per voxel along axis
  const Vec3 r0 = Minus(grid.origin, m.anchor);
  for (int b = 0; b < 3; ++b)
  {
    base[b] = m.toBarycentric[b][0] * r0[0] + m.toBarycentric[b][1] * r0[1] + m.toBarycentric[b][2] * r0[2];
    for (int axis = 0; axis < 3; ++axis)
    {
      step[axis][b] = m.toBarycentric[b][axis] * grid.spacing[axis];
    }
  }
  // Coordinate 0 is 1 - l1 - l2 - l3; keep all four as (value, i-slope) pairs.
  double slopeI[4];
  slopeI[0] = -(step[0][0] + step[0][1] + step[0][2]);
  for (int b = 0; b < 3; ++b)
  {
    slopeI[b + 1] = step[0][b];
  }

  const std::size_t k0 = std::max(m.lower[2], kBegin);
  const std::size_t k1 = std::min(m.upper[2] + 1, kEnd);
  const double      iMax = static_cast<double>(m.upper[0]);
  for (std::size_t k = k0; k < k1; ++k)
  {
    for (std::size_t j = m.lower[1]; j <= m.upper[1]; ++j)
    {
      double value[4];
      double sum = 0.0;
      for (int b = 0; b < 3; ++b)
      {
        value[b + 1] = base[b] + static_cast<double>(j) * step[1][b] + static_cast<double>(k) * step[2][b];
        sum += value[b + 1];
      }
      value[0] = 1.0 - sum;
      // The scanline interval where all four coordinates are >= -tolerance.
      double lo = static_cast<double>(m.lower[0]);
      double hi = iMax;
      for (int b = 0; b < 4 && lo <= hi; ++b)
      {
        const double s = slopeI[b];
        if (s > 0.0)
        {
          lo = std::max(lo, std::ceil((-BarycentricTolerance - value[b]) / s));
        }
        else if (s < 0.0)
        {
          hi = std::min(hi, std::floor((-BarycentricTolerance - value[b]) / s));
        }
        else if (value[b] < -BarycentricTolerance)
        {
          hi = lo - 1.0;
        }
      }
      if (lo > hi)
      {
        continue;
      }
      const std::size_t row = grid.Offset(0, j, k);
      for (auto i = static_cast<std::size_t>(lo); i <= static_cast<std::size_t>(hi); ++i)
      {
        std::uint32_t & o = owner[row + i];
        o = std::min(o, index);
      }
    }
  }
}

/** Gives every unowned voxel the owner of the nearest owned voxel (breadth-first
 *  over 6-neighbours, sequential and in a fixed order, so deterministic);
 *  marks the unowned voxels in `outsideMask` (when given) if there are any. */
std::size_t
ExtendOwnersOutsideMesh(const Volume<Vec3> & grid, std::vector<std::uint32_t> & owner,
                        std::vector<std::uint8_t> * outsideMask)
{
  const std::size_t        nx = grid.size[0];
  const std::size_t        ny = grid.size[1];
  const std::size_t        nz = grid.size[2];
  const std::size_t        count = owner.size();
  std::size_t              outside = 0;
  std::vector<std::size_t> queue;
  auto                     forEachNeighbour = [&](std::size_t o, auto visit) {
    const std::size_t i = o % nx;
    const std::size_t j = (o / nx) % ny;
    const std::size_t k = o / (nx * ny);
    if (i > 0)
      visit(o - 1);
    if (i + 1 < nx)
      visit(o + 1);
    if (j > 0)
      visit(o - nx);
    if (j + 1 < ny)
      visit(o + nx);
    if (k > 0)
      visit(o - nx * ny);
    if (k + 1 < nz)
      visit(o + nx * ny);
  };
  // Seeds: owned voxels next to unowned ones, in offset order.
  for (std::size_t o = 0; o < count; ++o)
  {
    if (owner[o] == NoTetrahedron)
    {
      ++outside;
      if (outsideMask != nullptr)
      {
        if (outsideMask->empty())
          outsideMask->assign(count, 0);
        (*outsideMask)[o] = 1;
      }
      continue;
    }
    bool border = false;
    forEachNeighbour(o, [&](std::size_t n) { border = border || owner[n] == NoTetrahedron; });
    if (border)
    {
      queue.push_back(o);
    }
  }
  for (std::size_t head = 0; head < queue.size(); ++head)
  {
    const std::size_t o = queue[head];
    forEachNeighbour(o, [&](std::size_t n) {
      if (owner[n] == NoTetrahedron)
      {
        owner[n] = owner[o];
        queue.push_back(n);
      }
    });
  }
  return outside;
}
} // namespace

void
RasterizeDisplacement(const MeshTopology & topology, const std::vector<Vec3> & from, const std::vector<Vec3> & to,
                      Volume<Vec3> & field, RasterizationReport * report)
{
  if (from.size() != topology.NumberOfPoints() || to.size() != topology.NumberOfPoints())
  {
    throw Error("mesh rasterisation: the topology has " + std::to_string(topology.NumberOfPoints()) +
                " points but the meshes have " + std::to_string(from.size()) + " and " + std::to_string(to.size()));
  }
  for (const auto * points : { &from, &to })
  {
    for (const Vec3 & p : *points)
    {
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      {
        throw Error("mesh rasterisation: a mesh point is not finite");
      }
    }
  }
  for (int d = 0; d < 3; ++d)
  {
    if (!(field.spacing[d] > 0.0) || !std::isfinite(field.spacing[d]) || !std::isfinite(field.origin[d]))
    {
      throw Error("mesh rasterisation: the grid's spacing must be positive and its origin finite");
    }
  }
  const std::size_t voxels = field.NumberOfVoxels();
  field.data.assign(voxels, Vec3{ { 0.0, 0.0, 0.0 } });
  if (report != nullptr)
  {
    *report = RasterizationReport{ voxels, 0, {} };
  }
  if (voxels == 0)
  {
    return;
  }
  const auto & tetrahedra = topology.Tetrahedra();
  if (tetrahedra.size() >= NoTetrahedron)
  {
    throw Error("mesh rasterisation: too many tetrahedra");
  }

  std::vector<TetrahedronMap> maps(tetrahedra.size());
  ParallelForOnNewThreads(tetrahedra.size(), [&](std::size_t t) { maps[t] = MakeTetrahedronMap(tetrahedra[t], from, to, field); });

  // Ownership by z-slabs: each slab is written by one thread only, and within a
  // slab the lowest tetrahedron index wins, whatever the order of work.
  constexpr std::size_t                   SlabThickness = 4;
  const std::size_t                       slabs = (field.size[2] + SlabThickness - 1) / SlabThickness;
  std::vector<std::vector<std::uint32_t>> slabTetrahedra(slabs);
  for (std::size_t t = 0; t < maps.size(); ++t)
  {
    if (maps[t].valid && maps[t].inGrid)
    {
      for (std::size_t s = maps[t].lower[2] / SlabThickness; s <= maps[t].upper[2] / SlabThickness; ++s)
      {
        slabTetrahedra[s].push_back(static_cast<std::uint32_t>(t));
      }
    }
  }
  std::vector<std::uint32_t> owner(voxels, NoTetrahedron);
  ParallelForOnNewThreads(slabs, [&](std::size_t s) {
    const std::size_t kBegin = s * SlabThickness;
    const std::size_t kEnd = std::min(kBegin + SlabThickness, field.size[2]);
    for (std::uint32_t t : slabTetrahedra[s])
    {
      MarkTetrahedron(maps[t], t, field, kBegin, kEnd, owner);
    }
  });

  if (std::all_of(owner.begin(), owner.end(), [](std::uint32_t o) { return o == NoTetrahedron; }))
  {
    throw Error("mesh rasterisation: no voxel centre of the grid lies inside the mesh");
  }
  const std::size_t outside =
    ExtendOwnersOutsideMesh(field, owner, report != nullptr ? &report->outsideMask : nullptr);
  if (report != nullptr)
  {
    report->outsideMesh = outside;
  }

  // Each voxel evaluates its owner's affine map (extrapolating outside the mesh).
  const std::size_t nx = field.size[0];
  const std::size_t ny = field.size[1];
  ParallelForOnNewThreads(field.size[2], [&](std::size_t k) {
    for (std::size_t j = 0; j < ny; ++j)
    {
      for (std::size_t i = 0; i < nx; ++i)
      {
        const std::size_t o = field.Offset(i, j, k);
        field.data[o] = DisplacementAt(maps[owner[o]], field.PointAt(i, j, k));
      }
    }
  });
}
} // namespace morea_core
