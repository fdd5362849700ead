// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/MagnitudeObjective.h"

#include "morea_core/Error.h"

#include <cmath>

namespace morea_core
{
namespace
{
double
Length(const Vec3 & a, const Vec3 & b)
{
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

Vec3
Centroid(const std::array<Vec3, 4> & p)
{
  Vec3 c{ { 0.0, 0.0, 0.0 } };
  for (const Vec3 & v : p)
    for (int a = 0; a < 3; ++a)
      c[a] += 0.25 * v[a];
  return c;
}
} // namespace

double
TetrahedronMagnitude(const std::array<Vec3, 4> & source, const std::array<Vec3, 4> & target, double elasticity)
{
  double sum = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
    {
      const double d = Length(source[i], source[j]) - Length(target[i], target[j]);
      sum += d * d;
    }
  const Vec3 cs = Centroid(source), ct = Centroid(target);
  for (int i = 0; i < 4; ++i)
  {
    const double d = Length(cs, source[i]) - Length(ct, target[i]);
    sum += d * d;
  }
  return elasticity * sum;
}

double
TetrahedronMagnitude(const Tetrahedron & t, const std::vector<Vec3> & source, const std::vector<Vec3> & target,
                     double elasticity)
{
  return TetrahedronMagnitude({ source[t[0]], source[t[1]], source[t[2]], source[t[3]] },
                              { target[t[0]], target[t[1]], target[t[2]], target[t[3]] }, elasticity);
}

double
MagnitudeObjective(const MeshTopology & topology, const DualMesh & solution, const std::vector<double> & elasticity,
                   const RigidityModel & rigidity)
{
  const std::size_t n = topology.NumberOfTetrahedra();
  if (!elasticity.empty() && elasticity.size() != n)
    throw Error("magnitude objective: " + std::to_string(elasticity.size()) + " elasticity factors for " +
                std::to_string(n) + " tetrahedra");
  if (solution.source.size() != topology.NumberOfPoints() || solution.target.size() != topology.NumberOfPoints())
    throw Error("magnitude objective: the solution's meshes do not match the topology");
  if (!rigidity.Empty() && rigidity.weights.size() != n)
    throw Error("magnitude objective: the rigidity model does not match the topology");
  double sum = 0.0;
  for (std::size_t t = 0; t < n; ++t)
  {
    const Tetrahedron & tet = topology.Tetrahedra()[t];
    sum += TetrahedronMagnitude(tet, solution.source, solution.target, elasticity.empty() ? 1.0 : elasticity[t]) +
           TetrahedronRigidity(rigidity, t, { solution.source[tet[0]], solution.source[tet[1]],
                                              solution.source[tet[2]], solution.source[tet[3]] },
                               { solution.target[tet[0]], solution.target[tet[1]], solution.target[tet[2]],
                                 solution.target[tet[3]] });
  }
  return n ? sum / (10.0 * static_cast<double>(n)) : 0.0;
}
} // namespace morea_core
