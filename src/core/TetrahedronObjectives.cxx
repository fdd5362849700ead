// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/TetrahedronObjectives.h"

#include "morea_core/Error.h"
#include "morea_core/MagnitudeObjective.h"
#include "morea_core/TetrahedronSampling.h"

#include <cmath>

namespace morea_core
{
Fitness
ObjectiveTotals::ToFitness(std::size_t numberOfTetrahedra) const
{
  Fitness f;
  f.objectives[0] = numberOfTetrahedra ? sum.magnitude / (10.0 * static_cast<double>(numberOfTetrahedra)) : 0.0;
  f.objectives[1] = sum.samples > 0.0 ? sum.intensity / sum.samples : 0.0;
  f.objectives[2] = sum.samples > 0.0 ? sum.guidance / sum.samples : 0.0;
  // The folded count is a sum of small integers held in a double: round so
  // that accumulated +/- updates cannot leave a feasible solution at 1e-16.
  f.feasible = std::llround(sum.folded) == 0;
  f.constraint = f.feasible ? 0.0 : std::max(0.0, sum.foldValue);
  return f;
}

namespace
{
const RigidityModel NoRigidStructures{};
} // namespace

TetrahedronEvaluator::TetrahedronEvaluator(const MeshTopology & topology, const FoldConstraint & constraint,
                                           const std::vector<double> & elasticity, const ObjectiveData & data)
  : TetrahedronEvaluator(topology, constraint, elasticity, NoRigidStructures, data)
{}

TetrahedronEvaluator::TetrahedronEvaluator(const MeshTopology & topology, const FoldConstraint & constraint,
                                           const std::vector<double> & elasticity, const RigidityModel & rigidity,
                                           const ObjectiveData & data)
  : m_Topology(&topology)
  , m_Constraint(&constraint)
  , m_Elasticity(&elasticity)
  , m_Rigidity(&rigidity)
  , m_Data(&data)
{
  if (!elasticity.empty() && elasticity.size() != topology.NumberOfTetrahedra())
    throw Error("objectives: " + std::to_string(elasticity.size()) + " elasticity factors for " +
                std::to_string(topology.NumberOfTetrahedra()) + " tetrahedra");
  if (!rigidity.Empty() && (rigidity.weights.size() != topology.NumberOfTetrahedra() ||
                            rigidity.inverseEdges.size() != 9 * topology.NumberOfTetrahedra()))
    throw Error("objectives: the rigidity model does not match the mesh's " +
                std::to_string(topology.NumberOfTetrahedra()) + " tetrahedra");
  const std::size_t channels = 1 + data.NumberOfGuidanceStructures();
  if (data.fixed.channels != channels || data.moving.channels != channels)
    throw Error("objectives: the images need " + std::to_string(channels) + " channels (intensity and " +
                std::to_string(channels - 1) + " distance maps)");
  for (const ChannelVolume * v : { &data.fixed, &data.moving })
    if (v->data.size() != v->channels * v->size[0] * v->size[1] * v->size[2] || v->data.empty())
      throw Error("objectives: an image's data does not match its size");
  if (!(data.voxelVolume > 0.0) || !(data.samplingRate > 0.0))
    throw Error("objectives: voxel volume and sampling rate must be positive");
}

std::size_t
TetrahedronEvaluator::SampleCount(const Corners & c) const
{
  const double volume = std::abs(SignedVolume(c[0], c[1], c[2], c[3]));
  const double n = std::round(m_Data->samplingRate * volume / m_Data->voxelVolume);
  return n < 1.0 ? 1 : static_cast<std::size_t>(n);
}

void
TetrahedronEvaluator::SampleDirection(const Corners & from, const Corners & to, const ChannelVolume & fromImage,
                                      const ChannelVolume & toImage, TetrahedronValues & values) const
{
  constexpr std::size_t MaxChannels = 64;
  const std::size_t     channels = fromImage.channels;
  if (channels > MaxChannels)
    throw Error("objectives: at most 63 guidance structures");
  const std::size_t structures = channels - 1;
  const double      r = m_Data->guidanceRadius;
  const std::size_t n = SampleCount(from);

  ScrambledSobol4 sobol(TetrahedronSeed(from[0], from[1], from[2], from[3]));
  float           a[MaxChannels];
  float           b[MaxChannels];
  double          intensity = 0.0, guidance = 0.0;
  for (std::size_t s = 0; s < n; ++s)
  {
    const auto w = UniformBarycentric(sobol.Next());
    Vec3       p{ { 0.0, 0.0, 0.0 } }, q{ { 0.0, 0.0, 0.0 } };
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < 3; ++k)
      {
        p[k] += w[i] * from[i][k];
        q[k] += w[i] * to[i][k];
      }
    fromImage.Sample(p, a);
    toImage.Sample(q, b);
    // Background rule: two background samples agree perfectly, one background
    // sample against tissue is the worst mismatch.
    if (a[0] > 0.0f && b[0] > 0.0f)
    {
      const double d = static_cast<double>(a[0]) - static_cast<double>(b[0]);
      intensity += d * d;
    }
    else if (a[0] > 0.0f || b[0] > 0.0f)
      intensity += 1.0;
    for (std::size_t g = 0; g < structures; ++g)
    {
      const double d = a[1 + g];
      if (d < r)
      {
        const double e = d - static_cast<double>(b[1 + g]);
        guidance += m_Data->guidanceWeights[g] * (r - d) / r * e * e;
      }
    }
  }
  values.intensity += intensity;
  values.guidance += guidance;
}

TetrahedronValues
TetrahedronEvaluator::EvaluateCorners(std::size_t t, const Corners & source, const Corners & target) const
{
  TetrahedronValues v;
  v.magnitude = TetrahedronMagnitude(source, target, m_Elasticity->empty() ? 1.0 : (*m_Elasticity)[t]) +
                TetrahedronRigidity(*m_Rigidity, t, source, target);
  for (const Corners * c : { &source, &target })
  {
    bool folded = false;
    v.foldValue += m_Constraint->TetrahedronViolation(t, (*c)[0], (*c)[1], (*c)[2], (*c)[3], folded);
    v.folded += folded ? 1.0 : 0.0;
  }
  v.foldValue += TetrahedronRigidViolation(*m_Rigidity, t, source, target, v.folded);
  v.samples = static_cast<double>(SampleCount(source)) + static_cast<double>(SampleCount(target));
  return v;
}

void
TetrahedronEvaluator::AddSampleSums(const Corners & source, const Corners & target, TetrahedronValues & values) const
{
  SampleDirection(source, target, m_Data->moving, m_Data->fixed, values);
  SampleDirection(target, source, m_Data->fixed, m_Data->moving, values);
}

TetrahedronValues
TetrahedronEvaluator::Evaluate(std::size_t t, const Corners & source, const Corners & target) const
{
  TetrahedronValues v = EvaluateCorners(t, source, target);
  AddSampleSums(source, target, v);
  return v;
}

TetrahedronValues
TetrahedronEvaluator::Evaluate(std::size_t t, const DualMesh & solution) const
{
  const Tetrahedron & tet = m_Topology->Tetrahedra()[t];
  return Evaluate(t, CornersOf(tet, solution.source), CornersOf(tet, solution.target));
}
} // namespace morea_core
