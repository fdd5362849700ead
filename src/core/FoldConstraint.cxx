// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/FoldConstraint.h"

#include "morea_core/Error.h"

#include <cmath>

namespace morea_core
{
FoldConstraint::FoldConstraint(const MeshTopology & topology, const std::vector<Vec3> & reference,
                               double volumeFraction)
  : m_Topology(&topology)
  , m_VolumeFraction(volumeFraction)
{
  if (!(volumeFraction >= 0.0 && volumeFraction < 1.0))
    throw Error("fold constraint: the volume fraction must lie in [0, 1), not " + std::to_string(volumeFraction));
  if (reference.size() != topology.NumberOfPoints())
    throw Error("fold constraint: reference has " + std::to_string(reference.size()) + " points, the mesh " +
                std::to_string(topology.NumberOfPoints()));
  m_ReferenceVolumes.reserve(topology.NumberOfTetrahedra());
  for (const Tetrahedron & t : topology.Tetrahedra())
  {
    const double v = SignedVolume(t, reference);
    if (v == 0.0)
      throw Error("fold constraint: the base mesh has a flat tetrahedron");
    m_ReferenceVolumes.push_back(v);
  }
}

double
FoldConstraint::VolumeViolation(std::size_t t, double v, bool & folded) const
{
  const double reference = m_ReferenceVolumes[t];
  const double size = std::abs(reference);
  const double oriented = reference > 0.0 ? v : -v; // positive while unfolded
  const double lower = m_VolumeFraction * size;
  if (!(oriented > lower))
  {
    folded = true;
    return lower - oriented;
  }
  if (m_VolumeFraction > 0.0 && oriented * m_VolumeFraction > size)
  {
    folded = true;
    return oriented - size / m_VolumeFraction;
  }
  folded = false;
  return 0.0;
}

double
FoldConstraint::TetrahedronViolation(std::size_t t, const std::vector<Vec3> & points, bool & folded) const
{
  return VolumeViolation(t, SignedVolume(m_Topology->Tetrahedra()[t], points), folded);
}

double
FoldConstraint::TetrahedronViolation(std::size_t t, const Vec3 & a, const Vec3 & b, const Vec3 & c, const Vec3 & d,
                                     bool & folded) const
{
  return VolumeViolation(t, SignedVolume(a, b, c, d), folded);
}

FoldViolation
FoldConstraint::Evaluate(const std::vector<Vec3> & points, std::vector<double> * perTetrahedron) const
{
  if (points.size() != m_Topology->NumberOfPoints())
    throw Error("fold constraint: solution has " + std::to_string(points.size()) + " points, the mesh " +
                std::to_string(m_Topology->NumberOfPoints()));
  FoldViolation total;
  if (perTetrahedron)
    perTetrahedron->assign(m_Topology->NumberOfTetrahedra(), 0.0);
  for (std::size_t t = 0; t < m_Topology->NumberOfTetrahedra(); ++t)
  {
    bool         folded = false;
    const double v = TetrahedronViolation(t, points, folded);
    total.value += v;
    total.folded += folded;
    if (perTetrahedron)
      (*perTetrahedron)[t] = v;
  }
  return total;
}

FoldViolation
FoldConstraint::Evaluate(const DualMesh & solution) const
{
  FoldViolation total = Evaluate(solution.source);
  total += Evaluate(solution.target);
  return total;
}

FoldViolation
FoldConstraint::Partial(const std::vector<Vec3> & points, const std::vector<std::uint32_t> & touched) const
{
  FoldViolation total;
  for (std::uint32_t t : touched)
  {
    bool folded = false;
    total.value += TetrahedronViolation(t, points, folded);
    total.folded += folded;
  }
  return total;
}

std::vector<std::uint32_t>
FoldConstraint::FoldedTetrahedra(const std::vector<Vec3> & points) const
{
  std::vector<std::uint32_t> folded;
  for (std::size_t t = 0; t < m_Topology->NumberOfTetrahedra(); ++t)
  {
    bool f = false;
    TetrahedronViolation(t, points, f);
    if (f)
      folded.push_back(static_cast<std::uint32_t>(t));
  }
  return folded;
}
} // namespace morea_core
