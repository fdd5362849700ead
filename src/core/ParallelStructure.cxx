// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/ParallelStructure.h"

#include "morea_core/Error.h"

#include <algorithm>
#include <set>
#include <tuple>

namespace morea_core
{
std::vector<Edge>
GreedyEdgeCover(const MeshTopology & topology)
{
  const std::size_t n = topology.NumberOfPoints();
  std::vector<bool> covered(n, false);
  // Free neighbours per point; a min-first queue keeps the matching large
  // (points with few options are matched before their options run out).
  std::vector<std::size_t>                       freeNeighbours(n);
  std::set<std::pair<std::size_t, std::uint32_t>> queue;
  for (std::size_t p = 0; p < n; ++p)
  {
    freeNeighbours[p] = topology.Neighbours(p).size();
    queue.insert({ freeNeighbours[p], static_cast<std::uint32_t>(p) });
  }
  const auto cover = [&](std::uint32_t p) {
    covered[p] = true;
    queue.erase({ freeNeighbours[p], p });
    for (std::uint32_t q : topology.Neighbours(p))
    {
      if (covered[q])
        continue;
      queue.erase({ freeNeighbours[q], q });
      --freeNeighbours[q];
      queue.insert({ freeNeighbours[q], q });
    }
  };

  std::vector<Edge> edges;
  std::vector<std::uint32_t> leftOver;
  while (!queue.empty())
  {
    const std::uint32_t p = queue.begin()->second;
    if (queue.begin()->first == 0)
    {
      // No free neighbour left: covered later by an edge to a covered point.
      queue.erase(queue.begin());
      covered[p] = true;
      leftOver.push_back(p);
      continue;
    }
    std::uint32_t best = 0;
    std::size_t   bestFree = SIZE_MAX;
    for (std::uint32_t q : topology.Neighbours(p))
      if (!covered[q] && freeNeighbours[q] < bestFree)
      {
        bestFree = freeNeighbours[q];
        best = q;
      }
    cover(p);
    cover(best);
    edges.push_back({ std::min(p, best), std::max(p, best) });
  }
  for (std::uint32_t p : leftOver)
  {
    const std::vector<std::uint32_t> nb = topology.Neighbours(p);
    if (nb.empty())
      throw Error("mesh point " + std::to_string(p) + " belongs to no tetrahedron");
    // The neighbour with the fewest tetrahedra keeps the element's dependent set small.
    const std::uint32_t q = *std::min_element(nb.begin(), nb.end(), [&](std::uint32_t a, std::uint32_t b) {
      return std::make_tuple(topology.TetrahedraOfPointEnd(a) - topology.TetrahedraOfPointBegin(a), a) <
             std::make_tuple(topology.TetrahedraOfPointEnd(b) - topology.TetrahedraOfPointBegin(b), b);
    });
    edges.push_back({ std::min(p, q), std::max(p, q) });
  }
  std::sort(edges.begin(), edges.end());
  return edges;
}

std::vector<std::vector<std::uint32_t>>
GreedyPointGroups(const MeshTopology & topology, const std::vector<Vec3> & points, std::size_t size)
{
  const std::size_t n = topology.NumberOfPoints();
  if (points.size() != n)
    throw Error("point groups: " + std::to_string(points.size()) + " coordinates for a mesh of " + std::to_string(n) +
                " points");
  if (size == 0)
    throw Error("point groups: a group size of 0");
  constexpr std::uint32_t free = UINT32_MAX;
  std::vector<std::uint32_t> group(n, free);
  // Free neighbours per point, smallest first, as in GreedyEdgeCover: points
  // in corners are grouped before their options run out.
  std::vector<std::size_t>                        freeNeighbours(n);
  std::set<std::pair<std::size_t, std::uint32_t>> queue;
  for (std::size_t p = 0; p < n; ++p)
  {
    freeNeighbours[p] = topology.Neighbours(p).size();
    queue.insert({ freeNeighbours[p], static_cast<std::uint32_t>(p) });
  }
  std::vector<std::vector<std::uint32_t>> groups;
  const auto take = [&](std::uint32_t p) {
    group[p] = static_cast<std::uint32_t>(groups.size() - 1);
    groups.back().push_back(p);
    queue.erase({ freeNeighbours[p], p });
    for (std::uint32_t q : topology.Neighbours(p))
      if (group[q] == free)
      {
        queue.erase({ freeNeighbours[q], q });
        --freeNeighbours[q];
        queue.insert({ freeNeighbours[q], q });
      }
  };
  const auto squaredDistance = [&](std::uint32_t a, std::uint32_t b) {
    double d = 0.0;
    for (int i = 0; i < 3; ++i)
      d += (points[a][i] - points[b][i]) * (points[a][i] - points[b][i]);
    return d;
  };
  while (!queue.empty())
  {
    const std::uint32_t first = queue.begin()->second;
    groups.emplace_back();
    take(first);
    // The group's free neighbours, nearest to its first point first.
    std::set<std::pair<double, std::uint32_t>> frontier;
    const auto widen = [&](std::uint32_t p) {
      for (std::uint32_t q : topology.Neighbours(p))
        if (group[q] == free)
          frontier.insert({ squaredDistance(first, q), q });
    };
    widen(first);
    while (groups.back().size() < size && !frontier.empty())
    {
      const std::uint32_t q = frontier.begin()->second;
      frontier.erase(frontier.begin());
      if (group[q] != free)
        continue;
      take(q);
      widen(q);
    }
  }
  // Small groups join their smallest neighbouring group, unless that would
  // make it larger than twice the size (the mesh is connected through shared
  // tetrahedra, so a small group has neighbours unless it is the whole mesh).
  const std::size_t smallest = (size + 1) / 2;
  for (std::size_t g = 0; g < groups.size(); ++g)
  {
    if (groups[g].size() >= smallest)
      continue;
    std::size_t target = groups.size();
    for (std::uint32_t p : groups[g])
      for (std::uint32_t q : topology.Neighbours(p))
      {
        const std::uint32_t h = group[q];
        if (h != g && (target == groups.size() || groups[h].size() < groups[target].size() ||
                       (groups[h].size() == groups[target].size() && h < target)))
          target = h;
      }
    if (target == groups.size() || groups[target].size() + groups[g].size() > 2 * size)
      continue;
    for (std::uint32_t p : groups[g])
    {
      group[p] = static_cast<std::uint32_t>(target);
      groups[target].push_back(p);
    }
    groups[g].clear(); // merged (no other group is empty)
  }
  std::vector<std::vector<std::uint32_t>> result;
  for (auto & g : groups)
    if (!g.empty())
    {
      std::sort(g.begin(), g.end());
      result.push_back(std::move(g));
    }
  return result;
}

std::vector<std::uint32_t>
DependentTetrahedra(const MeshTopology & topology, const std::vector<std::uint32_t> & points)
{
  std::vector<std::uint32_t> tets;
  for (std::uint32_t p : points)
    tets.insert(tets.end(), topology.TetrahedraOfPointBegin(p), topology.TetrahedraOfPointEnd(p));
  std::sort(tets.begin(), tets.end());
  tets.erase(std::unique(tets.begin(), tets.end()), tets.end());
  return tets;
}

std::vector<std::vector<std::uint32_t>>
InteractionGraph(const std::vector<FosElement> & elements, std::size_t numberOfTetrahedra)
{
  std::vector<std::vector<std::uint32_t>> users(numberOfTetrahedra);
  for (std::size_t e = 0; e < elements.size(); ++e)
    for (std::uint32_t t : elements[e].dependentTetrahedra)
    {
      if (t >= numberOfTetrahedra)
        throw Error("FOS element depends on a tetrahedron that does not exist");
      users[t].push_back(static_cast<std::uint32_t>(e));
    }
  std::vector<std::vector<std::uint32_t>> graph(elements.size());
  for (const auto & u : users)
    for (std::size_t i = 0; i < u.size(); ++i)
      for (std::size_t j = i + 1; j < u.size(); ++j)
      {
        graph[u[i]].push_back(u[j]);
        graph[u[j]].push_back(u[i]);
      }
  for (auto & adjacency : graph)
  {
    std::sort(adjacency.begin(), adjacency.end());
    adjacency.erase(std::unique(adjacency.begin(), adjacency.end()), adjacency.end());
  }
  return graph;
}

std::vector<std::uint32_t>
DsaturColouring(const std::vector<std::vector<std::uint32_t>> & graph)
{
  constexpr std::uint32_t uncoloured = UINT32_MAX;
  const std::size_t       n = graph.size();
  std::vector<std::uint32_t>         colour(n, uncoloured);
  std::vector<std::set<std::uint32_t>> neighbourColours(n);
  std::vector<std::size_t>           uncolouredDegree(n);
  // Highest saturation first, then highest degree among uncoloured vertices, then lowest index.
  using Key = std::tuple<std::size_t, std::size_t, std::uint32_t>;
  const auto key = [&](std::size_t v) {
    return Key{ neighbourColours[v].size(), uncolouredDegree[v], static_cast<std::uint32_t>(n - 1 - v) };
  };
  std::set<Key> queue;
  for (std::size_t v = 0; v < n; ++v)
  {
    uncolouredDegree[v] = graph[v].size();
    queue.insert(key(v));
  }
  while (!queue.empty())
  {
    const auto it = std::prev(queue.end());
    const std::size_t v = n - 1 - std::get<2>(*it);
    queue.erase(it);
    std::uint32_t c = 0;
    while (neighbourColours[v].count(c))
      ++c;
    colour[v] = c;
    for (std::uint32_t w : graph[v])
    {
      if (colour[w] != uncoloured)
        continue;
      queue.erase(key(w));
      neighbourColours[w].insert(c);
      --uncolouredDegree[w];
      queue.insert(key(w));
    }
  }
  return colour;
}

ParallelStructure
BuildParallelStructure(const MeshTopology & topology)
{
  std::vector<std::vector<std::uint32_t>> elementPoints;
  for (const Edge & e : GreedyEdgeCover(topology))
    elementPoints.push_back({ e[0], e[1] });
  return BuildParallelStructure(topology, elementPoints);
}

ParallelStructure
BuildParallelStructure(const MeshTopology & topology, const std::vector<std::vector<std::uint32_t>> & elementPoints)
{
  ParallelStructure structure;
  for (const auto & points : elementPoints)
  {
    if (points.empty())
      throw Error("a FOS element without points");
    FosElement element;
    element.points = points;
    element.dependentTetrahedra = DependentTetrahedra(topology, element.points);
    structure.elements.push_back(std::move(element));
  }
  structure.interactions = InteractionGraph(structure.elements, topology.NumberOfTetrahedra());
  structure.colour = DsaturColouring(structure.interactions);
  for (std::size_t e = 0; e < structure.elements.size(); ++e)
  {
    const std::uint32_t c = structure.colour[e];
    if (structure.groups.size() <= c)
      structure.groups.resize(c + 1);
    structure.groups[c].push_back(static_cast<std::uint32_t>(e));
  }
  return structure;
}
} // namespace morea_core
