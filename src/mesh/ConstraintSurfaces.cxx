// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "ConstraintSurfaces.h"

#include "morea_core/Error.h"
#include "morea_core/SurfaceCheck.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace morea_core
{
namespace
{
bool
InsideShrunk(const Vec3 & p, const MeshDomain & domain, double margin)
{
  for (int a = 0; a < 3; ++a)
    if (p[a] < domain.lower[a] + margin || p[a] > domain.upper[a] - margin)
      return false;
  return true;
}

/** A copy of `mask` without the voxels closer than `inset` to the domain's faces. */
Volume<std::uint8_t>
ClearNearBoundary(const Volume<std::uint8_t> & mask, const MeshDomain & domain, double inset)
{
  Volume<std::uint8_t> cleared = mask;
  for (std::size_t k = 0; k < mask.size[2]; ++k)
    for (std::size_t j = 0; j < mask.size[1]; ++j)
      for (std::size_t i = 0; i < mask.size[0]; ++i)
        if (!InsideShrunk(mask.PointAt(i, j, k), domain, inset))
          cleared(i, j, k) = 0;
  return cleared;
}

std::string
Millimetres(double mm)
{
  char text[32];
  std::snprintf(text, sizeof text, "%.1f mm", mm);
  return text;
}
} // namespace

std::optional<TriangleSurface>
PrepareConstraintSurface(const std::string & name, const Volume<std::uint8_t> & mask, const MeshDomain & domain,
                         std::size_t targetVertices, double margin, const std::vector<TriangleSurface> & others,
                         std::vector<std::string> & notes)
{
  const auto inside = [&](const TriangleSurface & s) {
    return std::all_of(s.vertices.begin(), s.vertices.end(), [&](const Vec3 & p) { return InsideShrunk(p, domain, margin); });
  };
  const Volume<std::uint8_t> * source = &mask;
  Volume<std::uint8_t>         cleared;
  TriangleSurface              surface = ExtractStructureSurface(mask, targetVertices);
  if (!surface.triangles.empty() && !inside(surface))
  {
    // A structure cut by the crop (lungs, say): close its surface a few
    // voxels inside the domain so it stays a closed constraint.
    const double inset = std::max(3.0 * *std::max_element(mask.spacing.begin(), mask.spacing.end()), 4.0 * margin);
    cleared = ClearNearBoundary(mask, domain, inset);
    source = &cleared;
    surface = ExtractStructureSurface(cleared, targetVertices);
    if (!surface.triangles.empty() && inside(surface))
      notes.push_back("surface of " + name + " reaches the domain boundary; closed " + Millimetres(inset) +
                      " inside it");
  }
  if (surface.triangles.empty() || !inside(surface))
  {
    notes.push_back("surface of " + name + (surface.triangles.empty() ? " is empty" : " reaches the domain boundary") +
                    "; its contour points are used instead");
    return std::nullopt;
  }

  // Decimation can fold a thin part onto itself; other levels usually do not.
  SurfaceDefects defects = CheckSurface(surface);
  const std::string first = defects.Describe();
  const std::size_t firstVertices = surface.vertices.size();
  for (const double fraction : { 0.8, 0.6, 0.45 })
  {
    if (defects.Valid())
      break;
    const auto target = std::max<std::size_t>(4, static_cast<std::size_t>(fraction * static_cast<double>(targetVertices)));
    TriangleSurface again = ExtractStructureSurface(*source, target);
    if (again.triangles.empty() || !inside(again))
      continue;
    SurfaceDefects d = CheckSurface(again);
    if (d.Valid() || d.crossingPairs + d.openEdges < defects.crossingPairs + defects.openEdges)
    {
      surface = std::move(again);
      defects = d;
    }
  }
  if (!defects.Valid())
  {
    notes.push_back("surface of " + name + " is not a closed surface without self-intersections (" +
                    defects.Describe() + "); its contour points are used instead");
    return std::nullopt;
  }
  if (!first.empty())
    notes.push_back("surface of " + name + " decimated to " + std::to_string(firstVertices) + " vertices had " + first +
                    "; made again with " + std::to_string(surface.vertices.size()) + " vertices");
  for (std::size_t o = 0; o < others.size(); ++o)
  {
    const std::size_t crossings = CountCrossings(surface, others[o]);
    if (crossings > 0)
    {
      notes.push_back("surface of " + name + " meets another structure's surface (" + std::to_string(crossings) +
                      " pairs of triangles); its contour points are used instead");
      return std::nullopt;
    }
  }
  return surface;
}

void
ConstrainedTetrahedralization::AddSurface(std::string name, std::vector<std::array<std::uint32_t, 3>> triangles)
{
  m_Surfaces.push_back({ std::move(name), std::move(triangles) });
}

std::vector<std::array<std::uint32_t, 3>>
ConstrainedTetrahedralization::TrianglesOf(const std::vector<Surface> & surfaces) const
{
  std::vector<std::array<std::uint32_t, 3>> all;
  for (const Surface & s : surfaces)
    all.insert(all.end(), s.triangles.begin(), s.triangles.end());
  return all;
}

std::vector<std::array<std::uint32_t, 3>>
ConstrainedTetrahedralization::Triangles() const
{
  return TrianglesOf(m_Surfaces);
}

TetrahedralizationResult
ConstrainedTetrahedralization::Run(const std::vector<Vec3> & points, bool mayDropSurfaces,
                                   std::vector<std::string> & notes)
{
  if (m_Surfaces.empty())
    return Tetrahedralize(points, {}, m_Options);
  try
  {
    return Tetrahedralize(points, Triangles(), m_Options);
  }
  catch (const Error & e)
  {
    if (!mayDropSurfaces)
      throw;
    if (m_Surfaces.size() == 1)
    {
      notes.push_back("surface constraint of " + m_Surfaces[0].name + " dropped (its vertices stay mesh points): " +
                      e.what());
      m_Surfaces.clear();
      return Tetrahedralize(points, {}, m_Options);
    }
  }
  // Several surfaces: keep, one by one, those TetGen manages together.
  std::vector<Surface>                    kept;
  std::optional<TetrahedralizationResult> result;
  for (Surface & s : m_Surfaces)
  {
    std::vector<Surface> trial = kept;
    trial.push_back(s);
    try
    {
      result = Tetrahedralize(points, TrianglesOf(trial), m_Options);
      kept = std::move(trial);
    }
    catch (const Error & e)
    {
      notes.push_back("surface constraint of " + s.name + " dropped (its vertices stay mesh points): " + e.what());
    }
  }
  m_Surfaces = std::move(kept);
  if (m_Surfaces.empty())
    return Tetrahedralize(points, {}, m_Options);
  return std::move(*result);
}
} // namespace morea_core
