// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the initial population (SPEC 5): the base
// mesh pair plus fold-free random deformations from Gaussian radial basis
// kernels that pull mesh points towards them, in incremental rounds.
#ifndef morea_InitialPopulation_h
#define morea_InitialPopulation_h

#include "morea_core/FoldConstraint.h"
#include "morea_core/Random.h"
#include "morea_core/TetrahedralMesh.h"

#include <cstdint>
#include <vector>

namespace morea_core
{
class ParameterSet;

struct InitialPopulationOptions
{
  double      noiseFactor{ 1.0 };   ///< morea_init_noise_factor; 0 gives copies of the base
  std::size_t kernelsPerMesh{ 4 };  ///< attractors per image
  std::size_t maxRounds{ 10 };      ///< each solution takes 1..maxRounds rounds
  double      roundStep{ 0.006 };   ///< largest move per round, as a fraction of the domain's smallest extent
  /** A round is also refused when it would shrink or grow a tetrahedron by
   *  more than this factor against the base mesh: kernels pull points
   *  together, and unchecked rounds compress their centres so much that the
   *  inverse map is far from smooth. */
  double      volumeRatioLimit{ 2.0 };

  /** morea_init_noise_method ("none" sets the factor to 0) and morea_init_noise_factor. */
  static InitialPopulationOptions
  FromParameters(const ParameterSet & parameters);
};

/** Deforms one mesh in place: kernels with random centres, widths and
 *  weights; each round moves every point by the kernels' pull (largest move
 *  roundStep * noiseFactor * smallest extent, pins respected) and is kept only
 *  if no tetrahedron folds or changes volume beyond volumeRatioLimit; after a
 *  refused round the step halves (at most four times). Returns the rounds applied. */
std::size_t
ApplyRadialBasisDeformation(std::vector<Vec3> & points, const TetrahedralMesh & base,
                            const FoldConstraint & constraint, RandomGenerator & random,
                            const InitialPopulationOptions & options);

/** `size` solutions: the base mesh pair first, then independent deformations
 *  of both meshes. Solution i depends only on (seed, i); multi-threaded. */
std::vector<DualMesh>
GenerateInitialPopulation(const TetrahedralMesh & base, const FoldConstraint & constraint, std::size_t size,
                          std::uint64_t seed, const InitialPopulationOptions & options = {});
} // namespace morea_core

#endif
