// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: per-tetrahedron tissue elasticity factors
// of the deformation magnitude objective (SPEC 4.5, paper appendix A).
#ifndef morea_ElasticityFactors_h
#define morea_ElasticityFactors_h

#include "morea_core/TetrahedralMesh.h"

#include <cstdint>
#include <string>
#include <vector>

namespace morea_core
{
struct ElasticStructure
{
  std::string                  name;
  const Volume<std::uint8_t> * mask{ nullptr }; ///< on the image the base mesh lies on
  double                       factor{ 1.0 };
};

/** The fraction of each tetrahedron of `mesh` covered by each mask: sampled
 *  at max(64, volume / voxel volume) points (at most 4096) drawn uniformly
 *  in the tetrahedron from a seed of its index; nearest-voxel lookup, outside
 *  the mask's grid counts as outside. fractions[s][t]. */
std::vector<std::vector<double>>
StructureOverlapFractions(const TetrahedralMesh & mesh, const std::vector<const Volume<std::uint8_t> *> & masks);

/** The fraction of each tetrahedron inside any of `masks` (their union):
 *  the rigid share of a tetrahedron (RigidityTerm.h). Same samples as
 *  StructureOverlapFractions; all 0 without masks. */
std::vector<double>
UnionOverlapFractions(const TetrahedralMesh & mesh, const std::vector<const Volume<std::uint8_t> *> & masks);

/** c_t = sum_s f_s * factor_s + (1 - sum_s f_s) * 1 for masks that do not
 *  overlap; where they do, a sample point inside several masks takes the
 *  mean of their factors. Same samples as StructureOverlapFractions. */
std::vector<double>
ComputeElasticityFactors(const TetrahedralMesh & mesh, const std::vector<ElasticStructure> & structures);

/** Structure factors from "name=factor, ..." (morea_elasticity_factors);
 *  factors must be positive. */
std::vector<std::pair<std::string, double>>
ParseElasticityFactors(const std::string & text);
} // namespace morea_core

#endif
