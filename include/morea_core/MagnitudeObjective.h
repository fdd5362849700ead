// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the deformation magnitude objective (SPEC 5),
// per tetrahedron so that partial evaluation is exact.
#ifndef morea_MagnitudeObjective_h
#define morea_MagnitudeObjective_h

#include "morea_core/RigidityTerm.h"
#include "morea_core/TetrahedralMesh.h"

#include <array>
#include <vector>

namespace morea_core
{
/** c_t times the sum over the tetrahedron's 10 edges (its 6 edges and the 4
 *  spokes from its centroid to its corners) of (|e_source| - |e_target|)^2.
 *  The objective is the sum of these over all tetrahedra divided by 10 |T|. */
double
TetrahedronMagnitude(const Tetrahedron & t, const std::vector<Vec3> & source, const std::vector<Vec3> & target,
                     double elasticity);

/** The same for corners given directly (source[i] and target[i] are one point). */
double
TetrahedronMagnitude(const std::array<Vec3, 4> & source, const std::array<Vec3, 4> & target, double elasticity);
/** The whole objective: sum over t of TetrahedronMagnitude plus its
 *  TetrahedronRigidity, divided by 10 |T|. `elasticity` holds one factor per
 *  tetrahedron (empty: all 1); `rigidity` may be empty (no rigid structures). */
double
MagnitudeObjective(const MeshTopology & topology, const DualMesh & solution, const std::vector<double> & elasticity,
                   const RigidityModel & rigidity = {});
} // namespace morea_core

#endif
