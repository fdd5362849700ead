// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/ElasticityFactors.h"

#include "morea_core/Error.h"
#include "morea_core/ParameterSet.h"
#include "morea_core/Random.h"

#include <algorithm>
#include <cmath>

namespace morea_core
{
namespace
{
bool
Inside(const Volume<std::uint8_t> & mask, const Vec3 & p)
{
  std::size_t index[3];
  for (int a = 0; a < 3; ++a)
  {
    const double c = std::floor((p[a] - mask.origin[a]) / mask.spacing[a] + 0.5);
    if (c < 0.0 || c >= static_cast<double>(mask.size[a]))
      return false;
    index[a] = static_cast<std::size_t>(c);
  }
  return mask(index[0], index[1], index[2]) != 0;
}

/** Calls visit(t, inside) for each sample point of each tetrahedron, where
 *  inside[s] tells whether the point lies in mask s; returns samples per tetrahedron. */
template <typename Visit>
std::vector<std::size_t>
SampleTetrahedra(const TetrahedralMesh & mesh, const std::vector<const Volume<std::uint8_t> *> & masks, Visit visit)
{
  std::vector<std::size_t> samples(mesh.NumberOfTetrahedra(), 0);
  if (masks.empty())
    return samples;
  for (const auto * m : masks)
    if (m == nullptr || m->data.empty())
      throw Error("elasticity: a structure has no mask");
  const double      voxelVolume = masks[0]->spacing[0] * masks[0]->spacing[1] * masks[0]->spacing[2];
  std::vector<bool> inside(masks.size());
  for (std::size_t t = 0; t < mesh.NumberOfTetrahedra(); ++t)
  {
    const Tetrahedron & tet = mesh.tetrahedra[t];
    const double        volume = std::abs(SignedVolume(tet, mesh.points));
    const auto          n = static_cast<std::size_t>(std::clamp(volume / voxelVolume, 64.0, 4096.0));
    RandomGenerator     random(HashCombine(0x656c6173ull, t)); // "elas"
    for (std::size_t i = 0; i < n; ++i)
    {
      // Uniform in the tetrahedron: normalised exponential barycentric weights.
      double w[4], sum = 0.0;
      for (double & x : w)
        sum += (x = -std::log(1.0 - random.Uniform()));
      Vec3 p{ { 0.0, 0.0, 0.0 } };
      for (int v = 0; v < 4; ++v)
        for (int a = 0; a < 3; ++a)
          p[a] += w[v] / sum * mesh.points[tet[v]][a];
      for (std::size_t s = 0; s < masks.size(); ++s)
        inside[s] = Inside(*masks[s], p);
      visit(t, inside);
    }
    samples[t] = n;
  }
  return samples;
}
} // namespace

std::vector<std::vector<double>>
StructureOverlapFractions(const TetrahedralMesh & mesh, const std::vector<const Volume<std::uint8_t> *> & masks)
{
  std::vector<std::vector<double>> fractions(masks.size(), std::vector<double>(mesh.NumberOfTetrahedra(), 0.0));
  const auto samples = SampleTetrahedra(mesh, masks, [&](std::size_t t, const std::vector<bool> & inside) {
    for (std::size_t s = 0; s < inside.size(); ++s)
      fractions[s][t] += inside[s];
  });
  for (auto & f : fractions)
    for (std::size_t t = 0; t < f.size(); ++t)
      f[t] /= static_cast<double>(samples[t]);
  return fractions;
}

std::vector<double>
UnionOverlapFractions(const TetrahedralMesh & mesh, const std::vector<const Volume<std::uint8_t> *> & masks)
{
  std::vector<double> fractions(mesh.NumberOfTetrahedra(), 0.0);
  const auto samples = SampleTetrahedra(mesh, masks, [&](std::size_t t, const std::vector<bool> & inside) {
    fractions[t] += std::find(inside.begin(), inside.end(), true) != inside.end() ? 1.0 : 0.0;
  });
  for (std::size_t t = 0; t < fractions.size(); ++t)
    fractions[t] = samples[t] ? fractions[t] / static_cast<double>(samples[t]) : 0.0;
  return fractions;
}

std::vector<double>
ComputeElasticityFactors(const TetrahedralMesh & mesh, const std::vector<ElasticStructure> & structures)
{
  std::vector<const Volume<std::uint8_t> *> masks;
  for (const auto & s : structures)
  {
    if (!(s.factor > 0.0))
      throw Error("elasticity factor of " + s.name + " must be positive");
    masks.push_back(s.mask);
  }
  std::vector<double> factors(mesh.NumberOfTetrahedra(), 0.0);
  const auto samples = SampleTetrahedra(mesh, masks, [&](std::size_t t, const std::vector<bool> & inside) {
    double      sum = 0.0;
    std::size_t in = 0;
    for (std::size_t s = 0; s < inside.size(); ++s)
      if (inside[s])
      {
        sum += structures[s].factor;
        ++in;
      }
    factors[t] += in ? sum / static_cast<double>(in) : 1.0;
  });
  for (std::size_t t = 0; t < factors.size(); ++t)
    factors[t] = samples[t] ? factors[t] / static_cast<double>(samples[t]) : 1.0;
  return factors;
}

std::vector<std::pair<std::string, double>>
ParseElasticityFactors(const std::string & text)
{
  auto factors = ParseNamedValues(text, "morea_elasticity_factors");
  for (const auto & [name, factor] : factors)
    if (!(factor > 0.0))
      throw Error("parameter morea_elasticity_factors: factor of " + name + " must be positive");
  return factors;
}
} // namespace morea_core
