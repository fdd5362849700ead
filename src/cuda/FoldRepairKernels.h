// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Launcher of the CUDA fold check and repair of partial candidates, in plain
// C++ types (see TetrahedronKernels.h).
#ifndef morea_cuda_FoldRepairKernels_h
#define morea_cuda_FoldRepairKernels_h

#include "TetrahedronKernels.h"

#include <cstddef>
#include <cstdint>

namespace morea_core::cuda
{
/** The fold constraint and the repair's fixed data on the device. */
struct FoldRepairConstants
{
  const double *        referenceVolumes{ nullptr };        ///< signed base volume per tetrahedron
  double                volumeFraction{ 0.0 };
  const std::uint32_t * pointTetrahedronOffsets{ nullptr }; ///< per point, plus one
  const std::uint32_t * pointTetrahedra{ nullptr };         ///< each point's tetrahedra, ascending
  const std::int8_t *   pins{ nullptr };                    ///< 3 per point (BoundaryPin)
  double                lower[3]{ 0.0, 0.0, 0.0 };          ///< the mesh domain
  double                upper[3]{ 0.0, 0.0, 0.0 };
  bool                  repair{ false };
  std::uint32_t         samplesPerPoint{ 64 };
  std::uint32_t         maxRounds{ 10 };
};

/** Per candidate and side: folded as sampled, and fold-free after the repair. */
constexpr std::uint8_t SideFolded = 1;
constexpr std::uint8_t SideRepaired = 2;

/** Elements with more points than this are refused (a bit mask per warp). */
constexpr std::uint32_t MaxRepairElementPoints = 64;

/** Checks each side of every candidate of `batch` whose `check` byte is set
 *  for folds over its element's dependent tetrahedra and, with
 *  constants.repair, repairs a folded side as RepairPoints does on the host:
 *  one warp per side, a point's trials spread over the lanes. `moved` (the
 *  batch's moved points) is rewritten in place; side s of candidate c draws
 *  its moves with seed sideSeeds[2 c + s] and reports in outcome[2 c + s].
 *  Candidates [first, first + count) only. Asynchronous on `stream`. */
void
LaunchCheckCandidateFolds(const CandidateBatch & batch, const FoldRepairConstants & constants,
                          const std::uint8_t * check, const std::uint64_t * sideSeeds, double * moved,
                          std::uint8_t * outcome, std::size_t first, std::size_t count, void * stream);
} // namespace morea_core::cuda

#endif
