// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the three objectives and the fold
// constraint, computed per tetrahedron (SPEC 5) so that a partial evaluation
// (the dependent tetrahedra of one FOS element) updates a solution's totals
// exactly: total(after) = total(before) - part(before) + part(after).
#ifndef morea_TetrahedronObjectives_h
#define morea_TetrahedronObjectives_h

#include "morea_core/FoldConstraint.h"
#include "morea_core/ObjectiveData.h"
#include "morea_core/ParetoFront.h"
#include "morea_core/RigidityTerm.h"
#include "morea_core/TetrahedralMesh.h"

#include <array>
#include <cstdint>
#include <vector>

namespace morea_core
{
/** One tetrahedron's contributions, both directions summed. */
struct TetrahedronValues
{
  double magnitude{ 0.0 }; ///< c_t * sum over 10 edges of (|e_s| - |e_t|)^2, plus its rigidity term
  double intensity{ 0.0 }; ///< sum of h over the samples
  double guidance{ 0.0 };  ///< sum of weighted guidance terms over the samples
  double samples{ 0.0 };   ///< number of samples
  double foldValue{ 0.0 }; ///< |signed volume| of the folded ones of its two copies
  double folded{ 0.0 };    ///< how many of its two copies are folded (0, 1, 2)
};

/** Sums of TetrahedronValues over a set of tetrahedra. */
struct ObjectiveTotals
{
  TetrahedronValues sum;

  void
  Add(const TetrahedronValues & v, double sign = 1.0)
  {
    sum.magnitude += sign * v.magnitude;
    sum.intensity += sign * v.intensity;
    sum.guidance += sign * v.guidance;
    sum.samples += sign * v.samples;
    sum.foldValue += sign * v.foldValue;
    sum.folded += sign * v.folded;
  }
  /** The normalised objectives of SPEC 5 for a mesh of `numberOfTetrahedra`. */
  Fitness
  ToFitness(std::size_t numberOfTetrahedra) const;
};

using Corners = std::array<Vec3, 4>;

/** Evaluates tetrahedra of a mesh model against the objective data. */
class TetrahedronEvaluator
{
public:
  /** `elasticity`: one factor per tetrahedron (empty: all 1). The references
   *  must outlive the evaluator. */
  TetrahedronEvaluator(const MeshTopology & topology, const FoldConstraint & constraint,
                       const std::vector<double> & elasticity, const ObjectiveData & data);
  /** With rigid structures: `rigidity` (empty: none) adds its term to each
   *  tetrahedron's magnitude. It must outlive the evaluator too. */
  TetrahedronEvaluator(const MeshTopology & topology, const FoldConstraint & constraint,
                       const std::vector<double> & elasticity, const RigidityModel & rigidity,
                       const ObjectiveData & data);

  /** Tetrahedron `t` with the given corners in the source (moving image) and
   *  target (fixed image) meshes. */
  TetrahedronValues
  Evaluate(std::size_t t, const Corners & source, const Corners & target) const;

  /** What Evaluate() finds from the corners alone: magnitude, fold value,
   *  folds and sample counts; intensity and guidance 0. */
  TetrahedronValues
  EvaluateCorners(std::size_t t, const Corners & source, const Corners & target) const;

  /** Adds the sampled intensity and guidance sums to `values` (from
   *  EvaluateCorners): Evaluate() is the two, with the same result. */
  void
  AddSampleSums(const Corners & source, const Corners & target, TetrahedronValues & values) const;

  /** Tetrahedron `t` of a whole solution. */
  TetrahedronValues
  Evaluate(std::size_t t, const DualMesh & solution) const;

  /** Samples one direction gets: rate * |volume| / voxel volume, at least 1. */
  std::size_t
  SampleCount(const Corners & corners) const;

  const MeshTopology &
  Topology() const
  {
    return *m_Topology;
  }
  const ObjectiveData &
  Data() const
  {
    return *m_Data;
  }
  const FoldConstraint &
  Constraint() const
  {
    return *m_Constraint;
  }
  /** One factor per tetrahedron, or empty (all 1). */
  const std::vector<double> &
  Elasticity() const
  {
    return *m_Elasticity;
  }
  /** The rigidity term's per-tetrahedron data, or an empty model. */
  const RigidityModel &
  Rigidity() const
  {
    return *m_Rigidity;
  }

private:
  /** Sums over the samples drawn in `from` (seeded by its coordinates),
   *  mapped to `to`, added to `values`' intensity and guidance;
   *  `fromImage`/`toImage` are the images the two meshes live on. */
  void
  SampleDirection(const Corners & from, const Corners & to, const ChannelVolume & fromImage,
                  const ChannelVolume & toImage, TetrahedronValues & values) const;

  const MeshTopology *  m_Topology;
  const FoldConstraint * m_Constraint;
  const std::vector<double> * m_Elasticity;
  const RigidityModel *       m_Rigidity;
  const ObjectiveData *  m_Data;
};

/** Corners of tetrahedron `t` in `points`. */
inline Corners
CornersOf(const Tetrahedron & t, const std::vector<Vec3> & points)
{
  return { points[t[0]], points[t[1]], points[t[2]], points[t[3]] };
}
} // namespace morea_core

#endif
