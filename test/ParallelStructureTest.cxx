// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of the linkage model: edge set cover, point groups, interaction graph,
// DSATUR groups.
#include "MeshTestSupport.h"

#include "morea_core/Error.h"
#include "morea_core/ParallelStructure.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <set>

namespace
{
std::vector<std::vector<std::uint32_t>>
Cycle(std::uint32_t n)
{
  std::vector<std::vector<std::uint32_t>> g(n);
  for (std::uint32_t i = 0; i < n; ++i)
  {
    g[i].push_back((i + 1) % n);
    g[(i + 1) % n].push_back(i);
  }
  return g;
}

std::size_t
ColourCount(const std::vector<std::uint32_t> & colour)
{
  return std::set<std::uint32_t>(colour.begin(), colour.end()).size();
}

void
ExpectProperColouring(const std::vector<std::vector<std::uint32_t>> & g, const std::vector<std::uint32_t> & colour)
{
  for (std::size_t v = 0; v < g.size(); ++v)
    for (std::uint32_t w : g[v])
      EXPECT_NE(colour[v], colour[w]) << v << "-" << w;
}

TEST(ParallelStructure, DsaturColoursCyclesAndCliquesOptimally)
{
  const auto even = Cycle(10), odd = Cycle(9);
  const auto ce = morea_core::DsaturColouring(even), co = morea_core::DsaturColouring(odd);
  ExpectProperColouring(even, ce);
  ExpectProperColouring(odd, co);
  EXPECT_EQ(ColourCount(ce), 2u);
  EXPECT_EQ(ColourCount(co), 3u);
  std::vector<std::vector<std::uint32_t>> k5(5);
  for (std::uint32_t i = 0; i < 5; ++i)
    for (std::uint32_t j = 0; j < 5; ++j)
      if (i != j)
        k5[i].push_back(j);
  EXPECT_EQ(ColourCount(morea_core::DsaturColouring(k5)), 5u);
  // A crown graph (complete bipartite minus a perfect matching) defeats
  // greedy colouring in index order; DSATUR colours it with 2.
  std::vector<std::vector<std::uint32_t>> crown(12);
  for (std::uint32_t i = 0; i < 6; ++i)
    for (std::uint32_t j = 0; j < 6; ++j)
      if (i != j)
      {
        crown[2 * i].push_back(2 * j + 1);
        crown[2 * j + 1].push_back(2 * i);
      }
  const auto cc = morea_core::DsaturColouring(crown);
  ExpectProperColouring(crown, cc);
  EXPECT_EQ(ColourCount(cc), 2u);
}

TEST(ParallelStructure, InteractionMeansSharedTetrahedra)
{
  std::vector<morea_core::FosElement> elements(3);
  elements[0].dependentTetrahedra = { 0, 1 };
  elements[1].dependentTetrahedra = { 1, 2 };
  elements[2].dependentTetrahedra = { 3 };
  const auto g = morea_core::InteractionGraph(elements, 4);
  EXPECT_EQ(g[0], (std::vector<std::uint32_t>{ 1 }));
  EXPECT_EQ(g[1], (std::vector<std::uint32_t>{ 0 }));
  EXPECT_TRUE(g[2].empty());
}

TEST(ParallelStructure, PhantomMeshCoverAndGroups)
{
  const auto &              pm = morea_test::PhantomMesh600();
  const morea_core::MeshTopology topology(pm.mesh.tetrahedra, pm.mesh.NumberOfPoints());
  const auto                structure = morea_core::BuildParallelStructure(topology);

  // Every point is covered; every element is a mesh edge.
  std::vector<int> coveredBy(topology.NumberOfPoints(), 0);
  const auto &     edges = topology.Edges();
  for (const auto & e : structure.elements)
  {
    ASSERT_EQ(e.points.size(), 2u);
    EXPECT_TRUE(std::binary_search(edges.begin(), edges.end(), morea_core::Edge{ { e.points[0], e.points[1] } }));
    EXPECT_EQ(e.dependentTetrahedra, morea_core::DependentTetrahedra(topology, e.points));
    for (auto p : e.points)
      ++coveredBy[p];
  }
  for (std::size_t p = 0; p < coveredBy.size(); ++p)
    EXPECT_GE(coveredBy[p], 1) << "point " << p << " is in no FOS element";
  // Close to a perfect matching: few points varied twice.
  EXPECT_LT(structure.elements.size(), topology.NumberOfPoints() * 6 / 10);

  // No two elements of a group share a tetrahedron (checked on the sets, not the graph).
  std::size_t grouped = 0;
  for (const auto & group : structure.groups)
  {
    std::vector<int> owner(topology.NumberOfTetrahedra(), -1);
    for (std::uint32_t e : group)
    {
      ++grouped;
      for (std::uint32_t t : structure.elements[e].dependentTetrahedra)
      {
        EXPECT_EQ(owner[t], -1) << "elements " << owner[t] << " and " << e << " share tetrahedron " << t;
        owner[t] = static_cast<int>(e);
      }
    }
  }
  EXPECT_EQ(grouped, structure.elements.size());
  ExpectProperColouring(structure.interactions, structure.colour);
  std::cout << "phantom mesh: " << structure.elements.size() << " FOS elements, " << structure.groups.size()
            << " parallel groups (colours)\n";
}

/** Whether `members` are connected through mesh edges among themselves. */
bool
Connected(const morea_core::MeshTopology & topology, const std::vector<std::uint32_t> & members)
{
  const std::set<std::uint32_t> inside(members.begin(), members.end());
  std::set<std::uint32_t>       reached{ members.front() };
  std::vector<std::uint32_t>    stack{ members.front() };
  while (!stack.empty())
  {
    const std::uint32_t p = stack.back();
    stack.pop_back();
    for (std::uint32_t q : topology.Neighbours(p))
      if (inside.count(q) && reached.insert(q).second)
        stack.push_back(q);
  }
  return reached.size() == inside.size();
}

TEST(ParallelStructure, PointGroupsCoverOnceConnectedAndSized)
{
  const auto &                   pm = morea_test::PhantomMesh600();
  const morea_core::MeshTopology topology(pm.mesh.tetrahedra, pm.mesh.NumberOfPoints());
  const std::size_t              n = topology.NumberOfPoints();
  for (const std::size_t size : { 1u, 2u, 5u, 10u })
  {
    const auto groups = morea_core::GreedyPointGroups(topology, pm.mesh.points, size);
    std::vector<int> coveredBy(n, 0);
    std::size_t      largest = 0;
    for (const auto & g : groups)
    {
      ASSERT_FALSE(g.empty());
      EXPECT_TRUE(std::is_sorted(g.begin(), g.end()));
      EXPECT_TRUE(Connected(topology, g)) << "a group of " << g.size() << " points is not connected";
      EXPECT_LE(g.size(), 2 * size) << "a merged group beyond twice the size";
      largest = std::max(largest, g.size());
      for (auto p : g)
        ++coveredBy[p];
    }
    for (std::size_t p = 0; p < n; ++p)
      EXPECT_EQ(coveredBy[p], 1) << "point " << p << " with group size " << size;
    // Small groups were merged: few are left below half the size.
    EXPECT_LE(std::count_if(groups.begin(), groups.end(), [&](const auto & g) { return g.size() < (size + 1) / 2; }),
              static_cast<std::ptrdiff_t>(groups.size() / 20 + 1))
      << "group size " << size;
    EXPECT_LE(largest, 2 * size) << "group size " << size;
    // About n / size groups: few are cut short by their corner.
    EXPECT_GE(groups.size(), n / size / 2) << "group size " << size;
    EXPECT_LE(groups.size(), n / size + n / size / 2 + 1) << "group size " << size;
    if (size == 1)
      EXPECT_EQ(groups.size(), n);
  }
  EXPECT_THROW(morea_core::GreedyPointGroups(topology, pm.mesh.points, 0), morea_core::Error);
  EXPECT_THROW(morea_core::GreedyPointGroups(topology, { pm.mesh.points.begin(), pm.mesh.points.end() - 1 }, 4),
               morea_core::Error);
}

TEST(ParallelStructure, GroupedStructureHasTheGroupsAsElements)
{
  const auto &                   pm = morea_test::PhantomMesh600();
  const morea_core::MeshTopology topology(pm.mesh.tetrahedra, pm.mesh.NumberOfPoints());
  const auto                     groups = morea_core::GreedyPointGroups(topology, pm.mesh.points, 8);
  const auto                     structure = morea_core::BuildParallelStructure(topology, groups);
  ASSERT_EQ(structure.elements.size(), groups.size());
  for (std::size_t e = 0; e < groups.size(); ++e)
  {
    EXPECT_EQ(structure.elements[e].points, groups[e]);
    EXPECT_EQ(structure.elements[e].dependentTetrahedra, morea_core::DependentTetrahedra(topology, groups[e]));
  }
  ExpectProperColouring(structure.interactions, structure.colour);
  // Fewer, larger elements than the edge cover, in more colours.
  const auto edges = morea_core::BuildParallelStructure(topology);
  EXPECT_LT(structure.elements.size(), edges.elements.size() / 3);
  std::cout << "phantom mesh, groups of 8: " << structure.elements.size() << " FOS elements, "
            << structure.groups.size() << " parallel groups (colours)\n";
  EXPECT_THROW(morea_core::BuildParallelStructure(topology, { {} }), morea_core::Error);
}
} // namespace
