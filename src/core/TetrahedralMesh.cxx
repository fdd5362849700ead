// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/TetrahedralMesh.h"

#include "morea_core/Error.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace morea_core
{
MeshTopology::MeshTopology(const std::vector<Tetrahedron> & tetrahedra, std::size_t numberOfPoints)
  : m_Tetrahedra(tetrahedra)
{
  // Tetrahedra around each point, as compressed rows.
  m_PointTetOffsets.assign(numberOfPoints + 1, 0);
  for (const Tetrahedron & t : m_Tetrahedra)
  {
    for (std::uint32_t v : t)
    {
      if (v >= numberOfPoints)
      {
        throw Error("mesh topology: tetrahedron refers to point " + std::to_string(v) + " of " +
                    std::to_string(numberOfPoints));
      }
      ++m_PointTetOffsets[v + 1];
    }
  }
  for (std::size_t p = 0; p < numberOfPoints; ++p)
  {
    m_PointTetOffsets[p + 1] += m_PointTetOffsets[p];
  }
  m_PointTets.resize(m_PointTetOffsets.back());
  std::vector<std::size_t> fill(m_PointTetOffsets.begin(), m_PointTetOffsets.end() - 1);
  for (std::size_t t = 0; t < m_Tetrahedra.size(); ++t)
  {
    for (std::uint32_t v : m_Tetrahedra[t])
    {
      m_PointTets[fill[v]++] = static_cast<std::uint32_t>(t);
    }
  }

  // Unique edges.
  m_Edges.reserve(m_Tetrahedra.size() * 6);
  for (const Tetrahedron & t : m_Tetrahedra)
  {
    for (int i = 0; i < 4; ++i)
    {
      for (int j = i + 1; j < 4; ++j)
      {
        m_Edges.push_back({ std::min(t[i], t[j]), std::max(t[i], t[j]) });
      }
    }
  }
  std::sort(m_Edges.begin(), m_Edges.end());
  m_Edges.erase(std::unique(m_Edges.begin(), m_Edges.end()), m_Edges.end());

  // Neighbours of each point, from the edges.
  m_PointEdgeOffsets.assign(numberOfPoints + 1, 0);
  for (const Edge & e : m_Edges)
  {
    ++m_PointEdgeOffsets[e[0] + 1];
    ++m_PointEdgeOffsets[e[1] + 1];
  }
  for (std::size_t p = 0; p < numberOfPoints; ++p)
  {
    m_PointEdgeOffsets[p + 1] += m_PointEdgeOffsets[p];
  }
  m_PointNeighbours.resize(m_PointEdgeOffsets.back());
  fill.assign(m_PointEdgeOffsets.begin(), m_PointEdgeOffsets.end() - 1);
  for (const Edge & e : m_Edges)
  {
    m_PointNeighbours[fill[e[0]]++] = e[1];
    m_PointNeighbours[fill[e[1]]++] = e[0];
  }
  for (std::size_t p = 0; p < numberOfPoints; ++p)
  {
    std::sort(m_PointNeighbours.begin() + static_cast<std::ptrdiff_t>(m_PointEdgeOffsets[p]),
              m_PointNeighbours.begin() + static_cast<std::ptrdiff_t>(m_PointEdgeOffsets[p + 1]));
  }
}

std::vector<std::uint32_t>
MeshTopology::Neighbours(std::size_t point) const
{
  return { m_PointNeighbours.begin() + static_cast<std::ptrdiff_t>(m_PointEdgeOffsets[point]),
           m_PointNeighbours.begin() + static_cast<std::ptrdiff_t>(m_PointEdgeOffsets[point + 1]) };
}

double
SignedVolume(const Vec3 & a, const Vec3 & b, const Vec3 & c, const Vec3 & d)
{
  const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
  const double vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
  const double wx = d[0] - a[0], wy = d[1] - a[1], wz = d[2] - a[2];
  return (ux * (vy * wz - vz * wy) - uy * (vx * wz - vz * wx) + uz * (vx * wy - vy * wx)) / 6.0;
}

double
TetrahedronQuality(const Vec3 & a, const Vec3 & b, const Vec3 & c, const Vec3 & d)
{
  const Vec3 * v[4] = { &a, &b, &c, &d };
  double       sum = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      for (int k = 0; k < 3; ++k)
        sum += ((*v[i])[k] - (*v[j])[k]) * ((*v[i])[k] - (*v[j])[k]);
  const double rms = std::sqrt(sum / 6.0);
  return rms > 0.0 ? 6.0 * std::sqrt(2.0) * SignedVolume(a, b, c, d) / (rms * rms * rms) : 0.0;
}

Vec3
ProjectToDomain(const Vec3 & p, const BoundaryPin & pin, const MeshDomain & domain)
{
  Vec3 q = p;
  for (int a = 0; a < 3; ++a)
  {
    if (pin[a] < 0)
      q[a] = domain.lower[a];
    else if (pin[a] > 0)
      q[a] = domain.upper[a];
    else
      q[a] = std::clamp(q[a], domain.lower[a], domain.upper[a]);
  }
  return q;
}

BoundaryPin
PinOf(const Vec3 & p, const MeshDomain & domain, double tolerance)
{
  BoundaryPin pin{ { 0, 0, 0 } };
  for (int a = 0; a < 3; ++a)
  {
    if (std::abs(p[a] - domain.lower[a]) <= tolerance)
      pin[a] = -1;
    else if (std::abs(p[a] - domain.upper[a]) <= tolerance)
      pin[a] = 1;
  }
  return pin;
}
} // namespace morea_core
