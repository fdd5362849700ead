// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/RigidityTerm.h"

#include "morea_core/Error.h"
#include "morea_core/ParameterSet.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace morea_core
{
namespace
{
/** G = D B^-1 for the corners `c`: D's columns are the edges from corner 0. */
void
StrainGradient(const std::array<Vec3, 4> & c, const double inverseEdges[9], double g[9])
{
  for (int a = 0; a < 3; ++a)
    for (int j = 0; j < 3; ++j)
    {
      double sum = 0.0;
      for (int e = 0; e < 3; ++e)
        sum += (c[e + 1][a] - c[0][a]) * inverseEdges[3 * e + j];
      g[3 * a + j] = sum;
    }
}

bool
InvertEdges(const std::array<Vec3, 4> & c, double inverse[9])
{
  double d[9];
  for (int a = 0; a < 3; ++a)
    for (int e = 0; e < 3; ++e)
      d[3 * a + e] = c[e + 1][a] - c[0][a];
  const double det = d[0] * (d[4] * d[8] - d[5] * d[7]) - d[1] * (d[3] * d[8] - d[5] * d[6]) +
                     d[2] * (d[3] * d[7] - d[4] * d[6]);
  if (!(std::abs(det) > 0.0) || !std::isfinite(det))
    return false;
  inverse[0] = (d[4] * d[8] - d[5] * d[7]) / det;
  inverse[1] = (d[2] * d[7] - d[1] * d[8]) / det;
  inverse[2] = (d[1] * d[5] - d[2] * d[4]) / det;
  inverse[3] = (d[5] * d[6] - d[3] * d[8]) / det;
  inverse[4] = (d[0] * d[8] - d[2] * d[6]) / det;
  inverse[5] = (d[2] * d[3] - d[0] * d[5]) / det;
  inverse[6] = (d[3] * d[7] - d[4] * d[6]) / det;
  inverse[7] = (d[1] * d[6] - d[0] * d[7]) / det;
  inverse[8] = (d[0] * d[4] - d[1] * d[3]) / det;
  return true;
}

std::string
Lower(std::string s)
{
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}
} // namespace

RigidityModel
BuildRigidityModel(const TetrahedralMesh & base, const std::vector<double> & rigidFraction, double weight,
                   double strainLimit)
{
  const std::size_t n = base.NumberOfTetrahedra();
  if (rigidFraction.size() != n)
    throw Error("rigidity: " + std::to_string(rigidFraction.size()) + " fractions for " + std::to_string(n) +
                " tetrahedra");
  if (!(weight >= 0.0) || !std::isfinite(weight))
    throw Error("rigidity: the weight must be finite and non-negative");
  if (!(strainLimit >= 0.0) || !std::isfinite(strainLimit))
    throw Error("rigidity: the strain limit must be finite and non-negative");
  RigidityModel model;
  if (weight == 0.0 || std::none_of(rigidFraction.begin(), rigidFraction.end(), [](double f) { return f > 0.0; }))
    return model;
  double meanVolume = 0.0;
  for (const Tetrahedron & t : base.tetrahedra)
    meanVolume += std::abs(SignedVolume(t, base.points)) / static_cast<double>(n);
  const double length = std::cbrt(meanVolume);
  model.weights.assign(n, 0.0);
  model.inverseEdges.assign(9 * n, 0.0);
  for (std::size_t t = 0; t < n; ++t)
  {
    const Tetrahedron & tet = base.tetrahedra[t];
    const std::array<Vec3, 4> corners{ base.points[tet[0]], base.points[tet[1]], base.points[tet[2]],
                                       base.points[tet[3]] };
    // A degenerate base tetrahedron has no strain to measure: it keeps weight 0.
    if (rigidFraction[t] > 0.0 && InvertEdges(corners, &model.inverseEdges[9 * t]))
      model.weights[t] = weight * rigidFraction[t] * std::abs(SignedVolume(tet, base.points)) / length;
  }
  if (strainLimit > 0.0)
  {
    model.strainLimitSquared = strainLimit * strainLimit;
    model.limitVolumes.assign(n, 0.0);
    for (std::size_t t = 0; t < n; ++t)
      if (rigidFraction[t] >= 0.5 && model.weights[t] > 0.0)
        model.limitVolumes[t] = std::abs(SignedVolume(base.tetrahedra[t], base.points));
  }
  return model;
}

double
TetrahedronRigidDeviation(const std::array<Vec3, 4> & source, const std::array<Vec3, 4> & target,
                          const double inverseEdges[9])
{
  double gs[9], gt[9];
  StrainGradient(source, inverseEdges, gs);
  StrainGradient(target, inverseEdges, gt);
  double sum = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      // (G_t^T G_t - G_s^T G_s)_ij / 2
      double c = 0.0;
      for (int a = 0; a < 3; ++a)
        c += gt[3 * a + i] * gt[3 * a + j] - gs[3 * a + i] * gs[3 * a + j];
      sum += 0.25 * c * c;
    }
  return sum;
}

double
TetrahedronRigidity(const RigidityModel & model, std::size_t t, const std::array<Vec3, 4> & source,
                    const std::array<Vec3, 4> & target)
{
  if (model.Empty() || model.weights[t] == 0.0)
    return 0.0;
  return model.weights[t] * TetrahedronRigidDeviation(source, target, &model.inverseEdges[9 * t]);
}

double
TetrahedronRigidViolation(const RigidityModel & model, std::size_t t, const std::array<Vec3, 4> & source,
                          const std::array<Vec3, 4> & target, double & violated)
{
  if (model.limitVolumes.empty() || model.limitVolumes[t] == 0.0)
    return 0.0;
  const double deviation = TetrahedronRigidDeviation(source, target, &model.inverseEdges[9 * t]);
  if (!(deviation > model.strainLimitSquared))
    return 0.0;
  violated += 1.0;
  return (deviation - model.strainLimitSquared) * model.limitVolumes[t];
}

bool
NameLooksRigid(const std::string & name)
{
  const std::string lower = Lower(name);
  for (const char * part : { "bone", "femur", "femoral", "sacrum", "vertebra", "skull", "mandible" })
    if (lower.find(part) != std::string::npos)
      return true;
  // Short words only as whole words: "rib" but not "distribution".
  std::string word;
  for (std::size_t i = 0; i <= lower.size(); ++i)
  {
    if (i < lower.size() && std::isalpha(static_cast<unsigned char>(lower[i])))
    {
      word += lower[i];
      continue;
    }
    if (word == "rib" || word == "ribs" || word == "spine")
      return true;
    word.clear();
  }
  return false;
}

std::vector<std::string>
SelectRigidStructures(const std::string & key, const std::vector<std::string> & available,
                      const std::vector<std::pair<std::string, double>> & factors)
{
  std::vector<std::string> rigid;
  if (key == "none" || key.empty())
    return rigid;
  if (key == "auto")
  {
    for (const std::string & name : available)
    {
      const auto factor = std::find_if(factors.begin(), factors.end(), [&](const auto & f) { return f.first == name; });
      if (NameLooksRigid(name) || (factor != factors.end() && factor->second >= 10.0))
        rigid.push_back(name);
    }
    return rigid;
  }
  for (const std::string & name : ParseNameList(key))
  {
    if (std::find(available.begin(), available.end(), name) == available.end())
    {
      std::string known;
      for (const std::string & a : available)
        known += (known.empty() ? "" : ", ") + a;
      throw Error("parameter morea_rigid_structures: no structure " + name + " (known: " + known + ")");
    }
    if (std::find(rigid.begin(), rigid.end(), name) == rigid.end())
      rigid.push_back(name);
  }
  return rigid;
}
} // namespace morea_core
