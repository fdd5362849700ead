// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Test helper: a box split into a grid of cubes, each cube into six positively
// oriented tetrahedra (Kuhn/Freudenthal split, so neighbouring cubes' faces
// match), plus a fold-free random perturbation of its points.
#ifndef morea_test_BoxMesh_h
#define morea_test_BoxMesh_h

#include "morea_core/TetrahedralMesh.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <random>
#include <utility>
#include <vector>

namespace morea_test
{
struct BoxMesh
{
  morea_core::MeshDomain               domain;
  std::vector<morea_core::Vec3>        points;
  std::vector<morea_core::Tetrahedron> tetrahedra;
  std::array<std::size_t, 3>      cells{};
};

inline BoxMesh
MakeBoxMesh(const morea_core::MeshDomain & domain, std::array<std::size_t, 3> cells)
{
  BoxMesh mesh;
  mesh.domain = domain;
  mesh.cells = cells;
  const std::size_t nx = cells[0] + 1;
  const std::size_t ny = cells[1] + 1;
  auto              id = [&](std::size_t i, std::size_t j, std::size_t k) {
    return static_cast<std::uint32_t>(i + nx * (j + ny * k));
  };
  for (std::size_t k = 0; k <= cells[2]; ++k)
    for (std::size_t j = 0; j <= cells[1]; ++j)
      for (std::size_t i = 0; i <= cells[0]; ++i)
      {
        const std::array<std::size_t, 3> index{ { i, j, k } };
        morea_core::Vec3                      p;
        for (int a = 0; a < 3; ++a)
        {
          // The last layer is exactly on the upper face (no round-off).
          p[a] = index[a] == cells[a]
                   ? domain.upper[a]
                   : domain.lower[a] + (domain.upper[a] - domain.lower[a]) * static_cast<double>(index[a]) /
                                         static_cast<double>(cells[a]);
        }
        mesh.points.push_back(p);
      }
  // Each tetrahedron walks from corner (0,0,0) to (1,1,1) of the cube along one
  // permutation of the axes.
  const int permutations[6][3] = { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 }, { 2, 1, 0 } };
  for (std::size_t k = 0; k < cells[2]; ++k)
    for (std::size_t j = 0; j < cells[1]; ++j)
      for (std::size_t i = 0; i < cells[0]; ++i)
        for (const auto & order : permutations)
        {
          std::array<std::size_t, 3> c{ { i, j, k } };
          morea_core::Tetrahedron         t;
          t[0] = id(c[0], c[1], c[2]);
          for (int step = 0; step < 3; ++step)
          {
            ++c[order[step]];
            t[step + 1] = id(c[0], c[1], c[2]);
          }
          if (morea_core::SignedVolume(t, mesh.points) < 0.0)
            std::swap(t[2], t[3]);
          mesh.tetrahedra.push_back(t);
        }
  return mesh;
}

/** Moves points by up to `fraction` of the cell size per axis, keeping points
 *  on the box boundary on their faces (so the perturbed mesh covers the box). */
inline std::vector<morea_core::Vec3>
Perturb(const BoxMesh & mesh, double fraction, unsigned seed)
{
  std::mt19937                           random(seed);
  std::uniform_real_distribution<double> offset(-fraction, fraction);
  std::vector<morea_core::Vec3>               moved = mesh.points;
  for (auto & p : moved)
  {
    for (int a = 0; a < 3; ++a)
    {
      const double cell = (mesh.domain.upper[a] - mesh.domain.lower[a]) / static_cast<double>(mesh.cells[a]);
      const double shift = offset(random) * cell; // drawn always, so the sequence does not depend on pins
      if (p[a] != mesh.domain.lower[a] && p[a] != mesh.domain.upper[a])
        p[a] += shift;
    }
  }
  return moved;
}

inline double
MinimumSignedVolume(const std::vector<morea_core::Tetrahedron> & tetrahedra, const std::vector<morea_core::Vec3> & points)
{
  double smallest = 1e300;
  for (const auto & t : tetrahedra)
    smallest = std::min(smallest, morea_core::SignedVolume(t, points));
  return smallest;
}
} // namespace morea_test

#endif
