// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: surface elements on the voxel-corner grid.
 *
 *  The surface representation of DeepMind's surface-distance package
 *  (Nikolov et al. 2018, arXiv:1809.04430), which pymia 0.3.4 ports: every
 *  voxel corner whose 2x2x2 neighbourhood holds inside and outside voxels is a
 *  surface element, weighted by the area of the surface that passes through
 *  the cell spanned by those eight voxel centres.
 *
 *  Per-code areas. The package looks them up in a table of marching-cubes
 *  triangles. Here they are derived from the configuration of the cell:
 *   1. Marching cubes on a binary image at level 1/2: the surface passes
 *      through the midpoint of every cell edge that joins an inside and an
 *      outside corner.
 *   2. Ambiguous faces (two inside corners on one diagonal, two outside on the
 *      other) are resolved as in the original marching-cubes cases: the
 *      corners of the smaller set (the inside ones when at most four are
 *      inside, else the outside ones) are kept apart, and each edge-connected
 *      group of them is cut off by one closed polygon through the midpoints of
 *      the edges that leave the group. With four inside corners both sets give
 *      the same areas, and a code and its complement have the same area.
 *   3. Each polygon is triangulated with the fewest planar pieces. The
 *      polygons of one corner (triangle), two corners (rectangle), four
 *      corners of a face (square) and a corner with its three neighbours
 *      (regular hexagon) are planar. Two are not: three corners on a face give
 *      a pentagon = a triangle + a planar quadrilateral; a chain of four
 *      corners along three different axes gives a hexagon = a planar
 *      quadrilateral + two triangles (two mirror-image choices whose area
 *      vectors agree component-wise in magnitude, hence in area for every
 *      spacing).
 *   4. The area is the sum of the triangles' areas after scaling the cell by
 *      the voxel spacing (the direction matrix is a rotation and changes no
 *      area).
 *  This gives the areas of the surface-distance table for every code, for
 *  isotropic and anisotropic spacings (checked against pymia numerically;
 *  study/tests/test_pymia_crosscheck.py compares HD95 end to end).
 *=========================================================================*/
#include "itkSurfaceElements.h"

#include "itkContinuousIndex.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace itk
{
namespace morea
{
namespace
{
using Point3 = std::array<double, 3>;
using Triangle = std::array<std::size_t, 3>;
using Triangulation = std::vector<Triangle>;

constexpr unsigned int CellCorners = 8; // corner i of a cell: offset (i & 1, (i >> 1) & 1, (i >> 2) & 1)

bool
Has(unsigned int corners, unsigned int corner)
{
  return ((corners >> corner) & 1u) != 0;
}

Point3
CornerPoint(unsigned int corner)
{
  return { { static_cast<double>(corner & 1u), static_cast<double>((corner >> 1) & 1u),
             static_cast<double>((corner >> 2) & 1u) } };
}

Point3
Minus(const Point3 & a, const Point3 & b)
{
  return { { a[0] - b[0], a[1] - b[1], a[2] - b[2] } };
}

Point3
Cross(const Point3 & a, const Point3 & b)
{
  return { { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] } };
}

double
Dot(const Point3 & a, const Point3 & b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/** Edge-connected groups of the cell corners in `corners` (bit i = corner i). */
std::vector<unsigned int>
ConnectedGroups(unsigned int corners)
{
  std::vector<unsigned int> groups;
  unsigned int              left = corners;
  while (left != 0)
  {
    unsigned int group = left & (~left + 1u); // the lowest corner left
    for (unsigned int previous = 0; previous != group;)
    {
      previous = group;
      for (unsigned int c = 0; c < CellCorners; ++c)
      {
        for (unsigned int d = 0; d < Dimension && Has(group, c); ++d)
        {
          const unsigned int neighbour = c ^ (1u << d);
          if (Has(left, neighbour))
          {
            group |= 1u << neighbour;
          }
        }
      }
    }
    groups.push_back(group);
    left &= ~group;
  }
  return groups;
}

/** The closed polygon that cuts `group` off the rest of the cell: the midpoints
 *  of the edges from the group to the other corners, in order. Two midpoints
 *  are consecutive when they lie on one cell face: a face holding corners of a
 *  group of at most four holds them in one run, so it has exactly two such
 *  edges. (A midpoint has two coordinates in {0, 1}, the faces it lies on.) */
std::vector<Point3>
CutPolygon(unsigned int group)
{
  std::vector<Point3> midpoints;
  for (unsigned int c = 0; c < CellCorners; ++c)
  {
    for (unsigned int d = 0; d < Dimension && Has(group, c); ++d)
    {
      if (!Has(group, c ^ (1u << d)))
      {
        auto m = CornerPoint(c);
        m[d] = 0.5;
        midpoints.push_back(m);
      }
    }
  }
  const auto shareFace = [](const Point3 & a, const Point3 & b) {
    for (unsigned int d = 0; d < Dimension; ++d)
    {
      if (a[d] == b[d] && a[d] != 0.5)
      {
        return true;
      }
    }
    return false;
  };
  std::vector<Point3> polygon{ midpoints.front() };
  std::vector<bool>   used(midpoints.size(), false);
  used.front() = true;
  while (polygon.size() < midpoints.size())
  {
    std::size_t next{ 0 };
    while (next < midpoints.size() && (used[next] || !shareFace(polygon.back(), midpoints[next])))
    {
      ++next;
    }
    if (next == midpoints.size())
    {
      throw std::logic_error("surface elements: the cut of a corner group is not one closed polygon");
    }
    used[next] = true;
    polygon.push_back(midpoints[next]);
  }
  if (polygon.size() < 3 || !shareFace(polygon.back(), polygon.front()))
  {
    throw std::logic_error("surface elements: the cut of a corner group does not close");
  }
  return polygon;
}

/** Every triangulation of the polygon with the vertices `chain` (in order) by
 *  non-crossing diagonals: the side (first, last) lies in a triangle with one
 *  other vertex k, which splits the rest into two smaller polygons. */
std::vector<Triangulation>
Triangulations(const std::vector<std::size_t> & chain)
{
  if (chain.size() < 3)
  {
    return { Triangulation{} };
  }
  std::vector<Triangulation> all;
  for (std::size_t k = 1; k + 1 < chain.size(); ++k)
  {
    const auto left = Triangulations({ chain.begin(), chain.begin() + static_cast<std::ptrdiff_t>(k) + 1 });
    const auto right = Triangulations({ chain.begin() + static_cast<std::ptrdiff_t>(k), chain.end() });
    for (const auto & l : left)
    {
      for (const auto & r : right)
      {
        Triangulation t = l;
        t.insert(t.end(), r.begin(), r.end());
        t.push_back({ { chain.front(), chain[k], chain.back() } });
        all.push_back(std::move(t));
      }
    }
  }
  return all;
}

/** Planar pieces of a triangulation: triangles, less the diagonals whose two
 *  triangles are coplanar. Exact: cell coordinates are 0, 1/2 or 1. */
std::size_t
PlanarPieces(const std::vector<Point3> & v, const Triangulation & t)
{
  std::size_t coplanarDiagonals{ 0 };
  for (std::size_t i = 0; i < t.size(); ++i)
  {
    const auto normal = Cross(Minus(v[t[i][1]], v[t[i][0]]), Minus(v[t[i][2]], v[t[i][0]]));
    for (std::size_t j = i + 1; j < t.size(); ++j)
    {
      std::size_t shared{ 0 };
      std::size_t other{ 0 };
      for (const auto vertex : t[j])
      {
        if (std::find(t[i].begin(), t[i].end(), vertex) != t[i].end())
        {
          ++shared;
        }
        else
        {
          other = vertex;
        }
      }
      if (shared == 2 && Dot(normal, Minus(v[other], v[t[i][0]])) == 0.0)
      {
        ++coplanarDiagonals;
      }
    }
  }
  return t.size() - coplanarDiagonals;
}

double
ScaledArea(const std::vector<Point3> & v, const Triangulation & t, const MaskType::SpacingType & spacing)
{
  double area{ 0.0 };
  for (const auto & triangle : t)
  {
    Point3 e1 = Minus(v[triangle[1]], v[triangle[0]]);
    Point3 e2 = Minus(v[triangle[2]], v[triangle[0]]);
    for (unsigned int d = 0; d < Dimension; ++d)
    {
      e1[d] *= spacing[d];
      e2[d] *= spacing[d];
    }
    const auto n = Cross(e1, e2);
    area += 0.5 * std::sqrt(Dot(n, n));
  }
  return area;
}

/** Area of the surface piece that cuts `group` off, after scaling by `spacing`. */
double
GroupArea(unsigned int group, const MaskType::SpacingType & spacing)
{
  const auto               polygon = CutPolygon(group);
  std::vector<std::size_t> chain(polygon.size());
  for (std::size_t i = 0; i < chain.size(); ++i)
  {
    chain[i] = i;
  }
  const auto  candidates = Triangulations(chain);
  std::size_t fewest = std::numeric_limits<std::size_t>::max();
  double      area{ 0.0 };
  for (const auto & t : candidates)
  {
    const auto pieces = PlanarPieces(polygon, t);
    if (pieces < fewest)
    {
      fewest = pieces;
      area = ScaledArea(polygon, t, spacing);
    }
  }
  return area;
}
} // namespace

SurfaceElementAreaTable
SurfaceElementAreas(const MaskType::SpacingType & spacing)
{
  for (unsigned int d = 0; d < Dimension; ++d)
  {
    if (!(spacing[d] > 0.0) || !std::isfinite(spacing[d]))
    {
      itkGenericExceptionMacro(<< "surface element areas: the spacing must be positive and finite, got " << spacing);
    }
  }
  SurfaceElementAreaTable areas{};
  for (unsigned int code = 1; code + 1 < areas.size(); ++code)
  {
    unsigned int inside{ 0 };
    for (unsigned int c = 0; c < CellCorners; ++c)
    {
      inside += Has(code, c);
    }
    const unsigned int separated = inside <= CellCorners / 2 ? code : (~code & 0xFFu);
    for (const auto group : ConnectedGroups(separated))
    {
      areas[code] += GroupArea(group, spacing);
    }
  }
  return areas;
}

namespace detail
{
SurfaceElements
ExtractSurfaceElements(const MaskType *                mask,
                       const MaskType *                region,
                       const VoxelBox &                lower,
                       const VoxelBox &                upper,
                       const SurfaceElementAreaTable & areas)
{
  const auto imageSize = mask->GetLargestPossibleRegion().GetSize();
  const auto imageStride = std::array<SizeValueType, Dimension>{ { 1, imageSize[0], imageSize[0] * imageSize[1] } };
  // The box with one outside voxel on every side, so that every corner reads eight voxels.
  std::array<SizeValueType, Dimension> padded{};
  MaskType::SizeType                   gridSize;
  for (unsigned int d = 0; d < Dimension; ++d)
  {
    padded[d] = upper[d] - lower[d] + 3;
    gridSize[d] = upper[d] - lower[d] + 2;
  }
  const std::array<SizeValueType, Dimension> stride{ { 1, padded[0], padded[0] * padded[1] } };
  std::vector<unsigned char>                 inside(padded[0] * padded[1] * padded[2], 0);
  const auto *                               in = mask->GetBufferPointer();
  for (SizeValueType z = lower[2]; z <= upper[2]; ++z)
  {
    for (SizeValueType y = lower[1]; y <= upper[1]; ++y)
    {
      for (SizeValueType x = lower[0]; x <= upper[0]; ++x)
      {
        inside[(x - lower[0] + 1) + stride[1] * (y - lower[1] + 1) + stride[2] * (z - lower[2] + 1)] =
          in[x + imageStride[1] * y + imageStride[2] * z] != 0 ? 1 : 0;
      }
    }
  }
  // Corner c reads the padded voxels c + o: the voxels lower + c - 1 + o.
  std::array<SizeValueType, CellCorners> neighbour{};
  for (unsigned int c = 0; c < CellCorners; ++c)
  {
    neighbour[c] = (c & 1u) * stride[0] + ((c >> 1) & 1u) * stride[1] + ((c >> 2) & 1u) * stride[2];
  }
  // Whether every voxel of corner (x, y, z)'s neighbourhood that lies in the image is in the region.
  const auto * regionBuffer = region != nullptr ? region->GetBufferPointer() : nullptr;
  const auto   inRegion = [&](SizeValueType x, SizeValueType y, SizeValueType z) {
    const std::array<SizeValueType, Dimension> corner{ { x, y, z } };
    for (unsigned int c = 0; c < CellCorners; ++c)
    {
      SizeValueType offset{ 0 };
      bool          inImage{ true };
      for (unsigned int d = 0; d < Dimension && inImage; ++d)
      {
        // voxel index lower + corner - 1 + o, kept unsigned: wraps to a huge value below 0
        const SizeValueType v = lower[d] + corner[d] + ((c >> d) & 1u) - 1;
        inImage = v < imageSize[d];
        offset += v * imageStride[d];
      }
      if (inImage && regionBuffer[offset] == 0)
      {
        return false;
      }
    }
    return true;
  };

  SurfaceElements elements;
  elements.grid = MaskType::New();
  elements.grid->SetRegions(MaskType::RegionType{ gridSize });
  elements.grid->SetSpacing(mask->GetSpacing());
  elements.grid->SetDirection(mask->GetDirection());
  ContinuousIndex<double, Dimension> firstCorner;
  for (unsigned int d = 0; d < Dimension; ++d)
  {
    firstCorner[d] = static_cast<double>(lower[d]) - 0.5;
  }
  MaskType::PointType origin;
  mask->TransformContinuousIndexToPhysicalPoint(firstCorner, origin);
  elements.grid->SetOrigin(origin);
  elements.grid->Allocate(true);
  auto * out = elements.grid->GetBufferPointer();

  SizeValueType o{ 0 };
  for (SizeValueType z = 0; z < gridSize[2]; ++z)
  {
    for (SizeValueType y = 0; y < gridSize[1]; ++y)
    {
      for (SizeValueType x = 0; x < gridSize[0]; ++x, ++o)
      {
        const SizeValueType base = x + stride[1] * y + stride[2] * z;
        unsigned int        code{ 0 };
        for (unsigned int c = 0; c < CellCorners; ++c)
        {
          code |= static_cast<unsigned int>(inside[base + neighbour[c]]) << c;
        }
        if (code == 0 || code == 255)
        {
          continue;
        }
        out[o] = 1;
        ++elements.count;
        if (regionBuffer == nullptr || inRegion(x, y, z))
        {
          elements.scored.push_back({ o, areas[code] });
        }
      }
    }
  }
  return elements;
}
} // namespace detail

} // namespace morea
} // namespace itk
