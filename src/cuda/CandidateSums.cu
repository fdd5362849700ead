// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Per-candidate sums of a batch's tetrahedron values on the device: the host
// needs every tetrahedron's values only for the few candidates it accepts
// (about 2 % of a generation's late in a paper-scale run), but the sum over
// each candidate's tetrahedra for all of them.
#include "TetrahedronKernels.h"

#include "DeviceMemory.h"

#include <cstdint>

namespace morea_core::cuda
{
namespace
{
constexpr int SumThreads = 256;

/** One warp per candidate: lane k reads the values of the candidate's item
 *  k (of each 32), and every lane adds them in item order from 0, as the
 *  host adds a candidate's values (ObjectiveTotals::Add): the same sums, bit
 *  for bit. An item's values are those the host unpacks: the item's
 *  magnitude and fold values, each direction's intensity, guidance and
 *  samples added. */
__global__ void
SumCandidateValues(CandidateBatch b, const double * __restrict__ itemValues,
                   const double * __restrict__ directionValues, double * sums)
{
  const std::size_t c = b.firstCandidate + (static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x) / 32;
  if (c >= b.candidates) // whole warps leave together
    return;
  const unsigned    lane = threadIdx.x & 31u;
  const std::size_t first = b.candidateFirstItem[c], end = b.candidateFirstItem[c + 1];
  double            sum[CandidateSumValues] = {};
  for (std::size_t base = first; base < end; base += 32)
  {
    double            mine[CandidateSumValues] = {};
    const std::size_t item = base + lane;
    if (item < end)
    {
      const double * v = itemValues + item * ItemValues;
      const double * d = directionValues + item * 2 * DirectionValues;
      // TetrahedronValues' order: magnitude, intensity, guidance, samples,
      // fold value, folded.
      mine[0] = v[0];
      mine[1] = d[0] + d[3];
      mine[2] = d[1] + d[4];
      mine[3] = d[2] + d[5];
      mine[4] = v[1];
      mine[5] = v[2];
    }
    const int count = static_cast<int>(end - base < 32 ? end - base : 32);
    for (int k = 0; k < count; ++k)
#pragma unroll
      for (int a = 0; a < CandidateSumValues; ++a)
        sum[a] += __shfl_sync(0xffffffffu, mine[a], k);
  }
  if (lane == 0)
#pragma unroll
    for (int a = 0; a < CandidateSumValues; ++a)
      sums[c * CandidateSumValues + a] = sum[a];
}
} // namespace

void
LaunchSumCandidateValues(const CandidateBatch & batch, const double * itemValues, const double * directionValues,
                         double * sums, void * stream)
{
  if (batch.firstCandidate >= batch.candidates)
    return;
  const std::size_t warps = batch.candidates - batch.firstCandidate;
  const unsigned    blocks = static_cast<unsigned>((warps * 32 + SumThreads - 1) / SumThreads);
  SumCandidateValues<<<blocks, SumThreads, 0, static_cast<cudaStream_t>(stream)>>>(batch, itemValues,
                                                                                 directionValues, sums);
  Check(cudaGetLastError(), "launching the candidate sum kernel");
}
} // namespace morea_core::cuda
