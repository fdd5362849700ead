#include "morea/MagnitudeObjective.h"

#include "morea/Error.h"

#include <cmath>

namespace morea
{
namespace
{
double
Length(const Vec3 & a, const Vec3 & b)
{
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

Vec3
Centroid(const Tetrahedron & t, const std::vector<Vec3> & p)
{
  Vec3 c{ { 0.0, 0.0, 0.0 } };
  for (std::uint32_t v : t)
    for (int a = 0; a < 3; ++a)
      c[a] += 0.25 * p[v][a];
  return c;
}
} // namespace

double
TetrahedronMagnitude(const Tetrahedron & t, const std::vector<Vec3> & source, const std::vector<Vec3> & target,
                     double elasticity)
{
  double sum = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
    {
      const double d = Length(source[t[i]], source[t[j]]) - Length(target[t[i]], target[t[j]]);
      sum += d * d;
    }
  const Vec3 cs = Centroid(t, source), ct = Centroid(t, target);
  for (int i = 0; i < 4; ++i)
  {
    const double d = Length(cs, source[t[i]]) - Length(ct, target[t[i]]);
    sum += d * d;
  }
  return elasticity * sum;
}

double
MagnitudeObjective(const MeshTopology & topology, const DualMesh & solution, const std::vector<double> & elasticity)
{
  const std::size_t n = topology.NumberOfTetrahedra();
  if (!elasticity.empty() && elasticity.size() != n)
    throw Error("magnitude objective: " + std::to_string(elasticity.size()) + " elasticity factors for " +
                std::to_string(n) + " tetrahedra");
  if (solution.source.size() != topology.NumberOfPoints() || solution.target.size() != topology.NumberOfPoints())
    throw Error("magnitude objective: the solution's meshes do not match the topology");
  double sum = 0.0;
  for (std::size_t t = 0; t < n; ++t)
    sum += TetrahedronMagnitude(topology.Tetrahedra()[t], solution.source, solution.target,
                                elasticity.empty() ? 1.0 : elasticity[t]);
  return n ? sum / (10.0 * static_cast<double>(n)) : 0.0;
}
} // namespace morea
