// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Launchers of the refusal screen (morea/RefusalBound.h) on the device, in
// plain C++ types: the rule of morea_core::RefusedWhateverItsSamples applied to
// every candidate of a batch once its corners are built, and the gathering
// of skipped candidates' items when the optimiser needs them sampled.
#ifndef morea_cuda_RefusalScreenKernels_h
#define morea_cuda_RefusalScreenKernels_h

#include "TetrahedronKernels.h"

#include <cstddef>
#include <cstdint>

namespace morea_core::cuda
{
/** One candidate's bound (morea_core::RefusalBound) as the screen reads it. */
struct CandidateBoundInput
{
  double        rest[6];   ///< the parent's totals less the element's tetrahedra:
                           ///< magnitude, intensity, guidance, samples, fold value, folded
  double        parent[3]; ///< the parent's objectives
  double        parentConstraint{ 0.0 };
  std::uint32_t screened{ 0 };
  std::uint32_t parentFeasible{ 0 };
};
static_assert(sizeof(CandidateBoundInput) == 88, "packed as the host writes it");

/** The batch's screen: bounds per candidate, the archive's objective vectors
 *  and how totals become a fitness. */
struct RefusalScreenView
{
  const CandidateBoundInput * bounds{ nullptr };
  const double *              archive{ nullptr }; ///< 3 per entry
  std::uint32_t               archiveSize{ 0 };
  double                      tetrahedra{ 0.0 };
  double                      guidanceLimit{ 0.0 }; ///< may be infinite
  double                      foldOffset{ 0.0 };    ///< morea_core::FoldConstraintOffset
};

/** For every candidate of `batch` whose items `corners` and `tetrahedra` hold
 *  (LaunchGatherCandidateCorners) and are all ItemSampled: bounds it from
 *  its items' magnitude, folds and sample counts; where the bound is
 *  refused, sets its items' `itemSkip` to ItemBoundSkipped and refusal[c]
 *  to 1 + the index of the archive entry that refused it (1 + archiveSize:
 *  refused as infeasible), else to 0. Asynchronous on `stream`. */
void
LaunchScreenCandidates(const EvaluationConstants & constants, const CandidateBatch & batch, const double * corners,
                       const std::uint32_t * tetrahedra, const RefusalScreenView & screen, std::uint8_t * itemSkip,
                       std::uint32_t * refusal, void * stream);

/** Copies items `items[i]` (count of them) of `corners` and `tetrahedra` to
 *  position i of `outCorners` and `outTetrahedra`. Asynchronous on `stream`. */
void
LaunchGatherItems(const double * corners, const std::uint32_t * tetrahedra, const std::uint64_t * items,
                  std::size_t count, double * outCorners, std::uint32_t * outTetrahedra, void * stream);
} // namespace morea_core::cuda

#endif
