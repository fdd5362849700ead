// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/MeshRefinement.h"

#include "morea_core/Error.h"
#include "morea_core/ParameterSet.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <string>
#include <tuple>
#include <unordered_map>

namespace morea_core
{
namespace
{
std::uint64_t
EdgeKey(std::uint32_t a, std::uint32_t b)
{
  if (a > b)
    std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

double
SquaredLength(const Vec3 & a, const Vec3 & b)
{
  const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
  return x * x + y * y + z * z;
}

constexpr int kEdgeCorners[6][2] = { { 0, 1 }, { 0, 2 }, { 0, 3 }, { 1, 2 }, { 1, 3 }, { 2, 3 } };

/** The longest edge of `t` in `points`; among equal lengths the one with the
 *  smallest key, so that neighbours agree and the result is deterministic. */
Edge
LongestEdge(const Tetrahedron & t, const std::vector<Vec3> & points)
{
  Edge   best{ 0, 0 };
  double bestLength = -1.0;
  for (const auto & c : kEdgeCorners)
  {
    const std::uint32_t a = std::min(t[c[0]], t[c[1]]), b = std::max(t[c[0]], t[c[1]]);
    const double        length = SquaredLength(points[a], points[b]);
    if (length > bestLength || (length == bestLength && EdgeKey(a, b) < EdgeKey(best[0], best[1])))
    {
      bestLength = length;
      best = { a, b };
    }
  }
  return best;
}

class Bisector
{
public:
  Bisector(const TetrahedralMesh & coarse, const std::vector<double> & density)
    : m_Density(density)
  {
    m_Result.mesh = coarse;
    m_Result.parentTetrahedron.resize(coarse.tetrahedra.size());
    for (std::uint32_t t = 0; t < coarse.tetrahedra.size(); ++t)
      m_Result.parentTetrahedron[t] = t;
    m_Version.assign(coarse.tetrahedra.size(), 0);
    for (std::uint32_t t = 0; t < coarse.tetrahedra.size(); ++t)
    {
      AddEdges(t);
      Push(t);
    }
  }

  void
  SplitNext()
  {
    while (!m_Queue.empty())
    {
      const auto [score, t, version] = m_Queue.top();
      m_Queue.pop();
      if (version != m_Version[t])
        continue; // cut since it was queued
      Split(TerminalEdge(t));
      if (m_Version[t] == version)
        m_Queue.emplace(score, t, version); // a neighbour's edge went first
      return;
    }
    throw Error("mesh refinement: no tetrahedron left to bisect");
  }

  MeshRefinement
  Take()
  {
    return std::move(m_Result);
  }

private:
  using Entry = std::tuple<double, std::uint32_t, std::uint32_t>; // score, tetrahedron, version

  struct Order
  {
    bool
    operator()(const Entry & x, const Entry & y) const
    {
      // Largest score first; ties: the lower index first.
      if (std::get<0>(x) != std::get<0>(y))
        return std::get<0>(x) < std::get<0>(y);
      return std::get<1>(x) > std::get<1>(y);
    }
  };

  /** The longest-edge propagation path from `t` (Rivara): follow longest
   *  edges to one that is the longest of every tetrahedron around it.
   *  Bisecting only such edges keeps the tetrahedra's shapes from
   *  degenerating. The path's edges grow strictly (length, then key), so it
   *  ends. */
  Edge
  TerminalEdge(std::uint32_t t) const
  {
    const TetrahedralMesh & mesh = m_Result.mesh;
    Edge                    edge = LongestEdge(mesh.tetrahedra[t], mesh.points);
    for (;;)
    {
      bool longestAround = true;
      for (const std::uint32_t u : m_EdgeTets.at(EdgeKey(edge[0], edge[1])))
      {
        const Edge longest = LongestEdge(mesh.tetrahedra[u], mesh.points);
        if (longest != edge)
        {
          edge = longest;
          longestAround = false;
          break;
        }
      }
      if (longestAround)
        return edge;
    }
  }

  void
  Push(std::uint32_t t)
  {
    const double volume = std::abs(SignedVolume(m_Result.mesh.tetrahedra[t], m_Result.mesh.points));
    m_Queue.emplace(m_Density[m_Result.parentTetrahedron[t]] * volume, t, m_Version[t]);
  }

  void
  AddEdges(std::uint32_t t)
  {
    const Tetrahedron & tet = m_Result.mesh.tetrahedra[t];
    for (const auto & c : kEdgeCorners)
      m_EdgeTets[EdgeKey(tet[c[0]], tet[c[1]])].push_back(t);
  }

  void
  RemoveEdges(std::uint32_t t)
  {
    const Tetrahedron & tet = m_Result.mesh.tetrahedra[t];
    for (const auto & c : kEdgeCorners)
    {
      const auto key = EdgeKey(tet[c[0]], tet[c[1]]);
      auto &     list = m_EdgeTets[key];
      list.erase(std::find(list.begin(), list.end(), t));
      if (list.empty())
        m_EdgeTets.erase(key);
    }
  }

  /** Bisects edge (a, b) and every tetrahedron around it. */
  void
  Split(const Edge & edge)
  {
    TetrahedralMesh & mesh = m_Result.mesh;
    const auto        a = edge[0], b = edge[1];
    const auto        m = static_cast<std::uint32_t>(mesh.points.size());
    Vec3              midpoint;
    BoundaryPin       pin;
    for (int axis = 0; axis < 3; ++axis)
    {
      midpoint[axis] = 0.5 * (mesh.points[a][axis] + mesh.points[b][axis]);
      // On a face only when both ends are on it.
      pin[axis] = mesh.pins[a][axis] == mesh.pins[b][axis] ? mesh.pins[a][axis] : std::int8_t{ 0 };
    }
    mesh.points.push_back(midpoint);
    mesh.pins.push_back(pin);
    mesh.origins.push_back(PointOrigin::Midpoint);
    mesh.structures.push_back(mesh.structures[a] == mesh.structures[b] ? mesh.structures[a] : -1);
    m_Result.midpointOf.push_back({ a, b });

    const std::vector<std::uint32_t> around = m_EdgeTets.at(EdgeKey(a, b));
    for (const std::uint32_t t : around)
    {
      RemoveEdges(t);
      Tetrahedron first = mesh.tetrahedra[t], second = mesh.tetrahedra[t];
      // Replacing a corner by a point halfway along one of its edges keeps
      // the orientation: the signed volume is affine in each corner.
      std::replace(first.begin(), first.end(), a, m);
      std::replace(second.begin(), second.end(), b, m);
      const auto other = static_cast<std::uint32_t>(mesh.tetrahedra.size());
      mesh.tetrahedra[t] = first;
      mesh.tetrahedra.push_back(second);
      m_Result.parentTetrahedron.push_back(m_Result.parentTetrahedron[t]);
      ++m_Version[t];
      m_Version.push_back(0);
      AddEdges(t);
      AddEdges(other);
      Push(t);
      Push(other);
    }
    // A constrained surface triangle on the edge splits in two as well.
    const std::size_t faces = mesh.constrainedFaces.size();
    for (std::size_t f = 0; f < faces; ++f)
    {
      auto & face = mesh.constrainedFaces[f];
      if (std::count(face.begin(), face.end(), a) && std::count(face.begin(), face.end(), b))
      {
        auto second = face;
        std::replace(face.begin(), face.end(), a, m);
        std::replace(second.begin(), second.end(), b, m);
        mesh.constrainedFaces.push_back(second);
      }
    }
  }

  const std::vector<double> &                               m_Density;
  MeshRefinement                                            m_Result;
  std::vector<std::uint32_t>                                m_Version;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> m_EdgeTets;
  std::priority_queue<Entry, std::vector<Entry>, Order>     m_Queue;
};
} // namespace

MeshLevelPlan
MeshLevelPlan::FromParameters(const ParameterSet & parameters)
{
  MeshLevelPlan plan;
  plan.levels = static_cast<std::size_t>(parameters.GetInteger("morea_max_num_mesh_levels"));
  plan.generationsPerLevel = static_cast<std::size_t>(parameters.GetInteger("morea_num_generations_per_level"));
  plan.generations = static_cast<std::size_t>(parameters.GetInteger("ea_num_generations"));
  plan.pointFactor = parameters.GetReal("morea_mesh_refinement_factor");
  if (plan.levels == 1 && plan.generationsPerLevel != 0)
    throw Error("morea_num_generations_per_level = " + std::to_string(plan.generationsPerLevel) +
                " needs morea_max_num_mesh_levels > 1 (it is 1: one mesh throughout); set it to 0 or add levels");
  if (plan.levels > 1 && plan.generationsPerLevel == 0)
    throw Error("morea_max_num_mesh_levels = " + std::to_string(plan.levels) +
                " needs morea_num_generations_per_level > 0: the generations of each level but the last");
  if (plan.levels > 1 && (plan.levels - 1) * plan.generationsPerLevel >= plan.generations)
    throw Error("morea_max_num_mesh_levels = " + std::to_string(plan.levels) + " with morea_num_generations_per_level = " +
                std::to_string(plan.generationsPerLevel) + " leaves the last level no generation of ea_num_generations = " +
                std::to_string(plan.generations) + ": use fewer levels, fewer generations per level or more generations");
  if (plan.levels > 1 && plan.pointFactor <= 1.0)
    throw Error("morea_mesh_refinement_factor must be above 1 with more than one mesh level");
  return plan;
}

std::size_t
MeshLevelPlan::PointsAt(std::size_t level, std::size_t coarsePoints) const
{
  return static_cast<std::size_t>(std::llround(static_cast<double>(coarsePoints) *
                                               std::pow(pointFactor, static_cast<double>(level))));
}

MeshRefinement
RefineMesh(const TetrahedralMesh & coarse, const std::vector<double> & density, std::size_t targetPoints)
{
  if (density.size() != coarse.tetrahedra.size())
    throw Error("mesh refinement: " + std::to_string(density.size()) + " densities for " +
                std::to_string(coarse.tetrahedra.size()) + " tetrahedra");
  for (const double d : density)
    if (!(d > 0.0) || !std::isfinite(d))
      throw Error("mesh refinement: a tetrahedron's density is not positive and finite");
  if (coarse.pins.size() != coarse.points.size() || coarse.origins.size() != coarse.points.size() ||
      coarse.structures.size() != coarse.points.size())
    throw Error("mesh refinement: the mesh's per-point data do not match its points");
  Bisector bisector(coarse, density);
  for (std::size_t n = coarse.points.size(); n < targetPoints; ++n)
    bisector.SplitNext();
  return bisector.Take();
}

DualMesh
CarryOver(const MeshRefinement & refinement, const DualMesh & coarse)
{
  const std::size_t coarsePoints = refinement.mesh.points.size() - refinement.midpointOf.size();
  if (coarse.source.size() != coarsePoints || coarse.target.size() != coarsePoints)
    throw Error("mesh refinement: a solution of " + std::to_string(coarse.source.size()) +
                " points does not belong to the coarse mesh of " + std::to_string(coarsePoints));
  DualMesh refined = coarse;
  refined.source.reserve(refinement.mesh.points.size());
  refined.target.reserve(refinement.mesh.points.size());
  for (const auto & [a, b] : refinement.midpointOf)
  {
    Vec3 s, t;
    for (int axis = 0; axis < 3; ++axis)
    {
      s[axis] = 0.5 * (refined.source[a][axis] + refined.source[b][axis]);
      t[axis] = 0.5 * (refined.target[a][axis] + refined.target[b][axis]);
    }
    refined.source.push_back(s);
    refined.target.push_back(t);
  }
  return refined;
}

std::vector<double>
RefinementDensity(const TetrahedralMesh & base, const std::vector<std::vector<TetrahedronValues>> & values)
{
  const std::size_t   tets = base.tetrahedra.size();
  std::vector<double> intensity(tets, 0.0), guidance(tets, 0.0), strain(tets, 0.0), volume(tets, 0.0);
  for (const auto & solution : values)
    if (solution.size() != tets)
      throw Error("mesh refinement: a solution's values do not match the mesh");
  auto finite = [](double v) { return std::isfinite(v) ? v : 0.0; };
  for (std::size_t t = 0; t < tets; ++t)
  {
    const Tetrahedron & tet = base.tetrahedra[t];
    volume[t] = std::abs(SignedVolume(tet, base.points));
    double squaredEdges = 0.0;
    for (const auto & c : kEdgeCorners)
      squaredEdges += SquaredLength(base.points[tet[c[0]]], base.points[tet[c[1]]]);
    for (const auto & solution : values)
    {
      const TetrahedronValues & v = solution[t];
      const double              samples = std::max(1.0, v.samples);
      intensity[t] += finite(v.intensity / samples);
      guidance[t] += finite(v.guidance / samples);
      strain[t] += squaredEdges > 0.0 ? finite(v.magnitude / squaredEdges) : 0.0;
    }
  }
  // Each term scaled to a volume-weighted mean of 1 and capped at 10, so that
  // no single tetrahedron takes all the points.
  std::vector<double> density(tets, 1.0);
  for (const std::vector<double> * term : { &intensity, &guidance, &strain })
  {
    double weighted = 0.0, total = 0.0;
    for (std::size_t t = 0; t < tets; ++t)
    {
      weighted += (*term)[t] * volume[t];
      total += volume[t];
    }
    if (!(weighted > 0.0) || !(total > 0.0))
      continue;
    const double mean = weighted / total;
    for (std::size_t t = 0; t < tets; ++t)
      density[t] += std::min(10.0, (*term)[t] / mean);
  }
  return density;
}
} // namespace morea_core
