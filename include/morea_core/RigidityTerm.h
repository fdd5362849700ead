// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: rigid structures (bones) in the deformation
// magnitude objective. The edge term fades where a bone is not a guidance
// structure (no mesh points on it, tetrahedra straddling it) and barely sees
// flat tetrahedra squashed across their thin side; this term measures the
// strain of the source-to-target map in each rigid tetrahedron directly, so a
// rigid motion costs 0 and any bend, shear or squash costs more.
#ifndef morea_RigidityTerm_h
#define morea_RigidityTerm_h

#include "morea_core/TetrahedralMesh.h"

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace morea_core
{
/** What the rigidity term needs per tetrahedron; empty when no structure is rigid. */
struct RigidityModel
{
  /** Per tetrahedron: weight * rigid fraction * |base volume| / l, with l the
   *  cube root of the base mesh's mean tetrahedron volume (so a term is a
   *  squared length, like the edge term's); 0 outside rigid structures. */
  std::vector<double> weights;
  /** Per tetrahedron 9 numbers: the inverse of the base mesh's edge matrix
   *  [p1 - p0, p2 - p0, p3 - p0], row-major. */
  std::vector<double> inverseEdges;
  /** The strain limit's constraint (morea_rigid_strain_limit): per
   *  tetrahedron at least half inside a rigid structure, its |base volume|
   *  (0 elsewhere; empty without a limit), and the limit squared. Such a
   *  tetrahedron whose deviation exceeds it counts as violated, like a fold,
   *  with (deviation - limit^2) * volume as its constraint value: a soft term
   *  alone lets the solutions at the front's best-guidance end bend bones. */
  std::vector<double> limitVolumes;
  double              strainLimitSquared{ 0.0 };

  bool
  Empty() const
  {
    return weights.empty();
  }
};

/** The model for `base` with `rigidFraction[t]` of tetrahedron t inside a
 *  rigid structure; empty when no fraction is positive or `weight` is 0. */
RigidityModel
BuildRigidityModel(const TetrahedralMesh & base, const std::vector<double> & rigidFraction, double weight,
                   double strainLimit = 0.0);

/** ||E_target - E_source||_F^2: E = (G^T G - I) / 2 is the Green strain of a
 *  mesh's tetrahedron against the base one (G = D B^-1, D its edge matrix),
 *  so the difference vanishes exactly when the source-to-target map of the
 *  tetrahedron is a rigid motion (or a mirror, which the fold constraint
 *  excludes). Polynomial in the corners: no decomposition, no division, so
 *  the CPU and CUDA compute it alike and it stays finite for flat tetrahedra. */
double
TetrahedronRigidDeviation(const std::array<Vec3, 4> & source, const std::array<Vec3, 4> & target,
                          const double inverseEdges[9]);

/** The rigidity term of tetrahedron t: weights[t] * deviation; 0 for an empty model. */
double
TetrahedronRigidity(const RigidityModel & model, std::size_t t, const std::array<Vec3, 4> & source,
                    const std::array<Vec3, 4> & target);

/** The strain limit's constraint value of tetrahedron t (0 when within it,
 *  outside rigid structures or without a limit); adds 1 to `violated` when
 *  it is exceeded. */
double
TetrahedronRigidViolation(const RigidityModel & model, std::size_t t, const std::array<Vec3, 4> & source,
                          const std::array<Vec3, 4> & target, double & violated);

/** Whether a structure's name says it is bone: bone(s), femur, femoral head,
 *  pelvic bone, sacrum, vertebra, spine, skull, rib (any case, any separator). */
bool
NameLooksRigid(const std::string & name);

/** The rigid structures among `available` for morea_rigid_structures:
 *  "auto" picks names that look like bone and structures whose elasticity
 *  factor in `factors` is at least 10; "none" or "" picks none; otherwise a
 *  comma-separated list, each name one of `available`. */
std::vector<std::string>
SelectRigidStructures(const std::string & key, const std::vector<std::string> & available,
                      const std::vector<std::pair<std::string, double>> & factors);
} // namespace morea_core

#endif
