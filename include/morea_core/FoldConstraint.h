// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: mesh folds (SPEC 5, constraint). A mesh has
// folded where a tetrahedron's signed volume no longer has the sign it had in
// the base mesh; the constraint value is the sum of the folded tetrahedra's
// |signed volume| over both meshes. Feasible means no folded tetrahedron.
//
// An optional volume fraction f > 0 tightens this: a tetrahedron also counts
// as folded when its oriented volume leaves [f, 1/f] times its base volume.
// A mesh can be fold-free while two neighbouring tetrahedra are squeezed
// almost flat; a displacement field rasterised from it then shows
// non-positive finite-difference Jacobians where the stencil straddles them.
// The violation (distance of the volume to the allowed interval) is
// continuous and equals SPEC 5's |signed volume| when f = 0.
#ifndef morea_FoldConstraint_h
#define morea_FoldConstraint_h

#include "morea_core/TetrahedralMesh.h"

#include <cstdint>
#include <vector>

namespace morea_core
{
/** Per mesh: the folded tetrahedra's count and total |signed volume| (mm^3).
 *  The count decides feasibility exactly; the value ranks infeasible solutions. */
struct FoldViolation
{
  double      value{ 0.0 };
  std::size_t folded{ 0 };

  bool
  Feasible() const
  {
    return folded == 0;
  }
  FoldViolation &
  operator+=(const FoldViolation & o)
  {
    value += o.value;
    folded += o.folded;
    return *this;
  }
};

class FoldConstraint
{
public:
  /** Reference volumes from the base configuration `reference`;
   *  `volumeFraction` in [0, 1) (0: sign changes only, SPEC 5). */
  FoldConstraint(const MeshTopology & topology, const std::vector<Vec3> & reference, double volumeFraction = 0.0);

  /** How far tetrahedron t's volume in `points` lies outside the allowed
   *  interval (|signed volume| of a sign change when the fraction is 0; a zero
   *  volume counts as folded with severity 0), else 0; `folded` tells which. */
  double
  TetrahedronViolation(std::size_t t, const std::vector<Vec3> & points, bool & folded) const;

  /** The same for a tetrahedron given by its corners. */
  double
  TetrahedronViolation(std::size_t t, const Vec3 & a, const Vec3 & b, const Vec3 & c, const Vec3 & d,
                       bool & folded) const;
  /** All tetrahedra of one mesh; fills `perTetrahedron` when given. */
  FoldViolation
  Evaluate(const std::vector<Vec3> & points, std::vector<double> * perTetrahedron = nullptr) const;
  /** Both meshes of a solution. */
  FoldViolation
  Evaluate(const DualMesh & solution) const;

  /** Only the tetrahedra `touched` (e.g. a FOS element's dependent set) of one
   *  mesh: their violation summed. Evaluate(after) = Evaluate(before)
   *  - Partial(before, touched) + Partial(after, touched), exactly in the count. */
  FoldViolation
  Partial(const std::vector<Vec3> & points, const std::vector<std::uint32_t> & touched) const;

  /** Folded tetrahedra of one mesh, ascending. */
  std::vector<std::uint32_t>
  FoldedTetrahedra(const std::vector<Vec3> & points) const;

  const MeshTopology &
  Topology() const
  {
    return *m_Topology;
  }
  double
  VolumeFraction() const
  {
    return m_VolumeFraction;
  }
  /** Signed volume of each tetrahedron in the base mesh. */
  const std::vector<double> &
  ReferenceVolumes() const
  {
    return m_ReferenceVolumes;
  }

private:
  /** The violation of one tetrahedron whose signed volume is `v`. */
  double
  VolumeViolation(std::size_t t, double v, bool & folded) const;

  const MeshTopology * m_Topology;
  std::vector<double>  m_ReferenceVolumes;
  double               m_VolumeFraction{ 0.0 };
};
} // namespace morea_core

#endif
