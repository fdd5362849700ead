// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The refusal screen on the device (see RefusalScreenKernels.h). Its answer
// is a hint: the optimiser checks every skipped candidate exactly on the
// host and has those it does not refuse sampled, so rounding that differs
// from the host's sums can cost a fallback but never a decision.
#include "RefusalScreenKernels.h"

#include "DeviceMemory.h"
#include "TetrahedronDevice.cuh"

#include <cstdint>

namespace morea_core::cuda
{
namespace
{
using namespace device;

constexpr int ScreenThreads = 256;

__device__ double
WarpTotal(double x)
{
  for (int offset = 16; offset > 0; offset >>= 1)
    x += __shfl_xor_sync(0xffffffffu, x, offset);
  return x;
}

/** The bound's fitness, steered (morea_core::BoundFitness), and whether the
 *  candidate is refused whatever its samples (morea_core::RefusedWhateverItsSamples)
 *  but for the archive, which the caller scans when `scan` comes back true. */
__device__ bool
RefusedBeforeArchive(const CandidateBoundInput & b, const RefusalScreenView & screen, const double corners[4],
                     double low[3], bool & scan)
{
  const double magnitude = b.rest[0] + corners[0];
  const double intensity = b.rest[1], guidance = b.rest[2];
  const double samples = b.rest[3] + corners[1];
  const double foldValue = b.rest[4] + corners[2];
  const double folded = b.rest[5] + corners[3];
  low[0] = screen.tetrahedra > 0.0 ? magnitude / (10.0 * screen.tetrahedra) : 0.0;
  low[1] = samples > 0.0 ? intensity / samples : 0.0;
  low[2] = samples > 0.0 ? guidance / samples : 0.0;
  bool   feasible = llround(folded) == 0;
  double constraint = feasible ? 0.0 : fmax(0.0, foldValue);
  if (!feasible)
    constraint += screen.foldOffset;
  else if (low[2] > screen.guidanceLimit)
  {
    feasible = false;
    constraint = low[2] - screen.guidanceLimit;
  }
  // Constraint domination of the parent: then it may be accepted.
  bool dominates;
  if (feasible != (b.parentFeasible != 0))
    dominates = feasible;
  else if (!feasible)
    dominates = constraint < b.parentConstraint;
  else
  {
    bool worse = false, better = false;
    for (int j = 0; j < 3; ++j)
    {
      worse |= low[j] > b.parent[j];
      better |= low[j] < b.parent[j];
    }
    dominates = !worse && better;
  }
  scan = !dominates && feasible;
  return !dominates && !feasible;
}

/** One warp per candidate: its lanes sum its items' corner values, then
 *  scan the archive for an entry that equals or dominates the bound. */
__global__ void
ScreenCandidates(EvaluationConstants k, CandidateBatch batch, const double * __restrict__ corners,
                 const std::uint32_t * __restrict__ tetrahedra, RefusalScreenView screen, std::uint8_t * itemSkip,
                 std::uint32_t * refusal)
{
  const std::size_t c = batch.firstCandidate + (static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x) / 32;
  if (c >= batch.candidates)
    return;
  const int                 lane = static_cast<int>(threadIdx.x & 31);
  const std::size_t         first = batch.candidateFirstItem[c], end = batch.candidateFirstItem[c + 1];
  const CandidateBoundInput b = screen.bounds[c];
  bool                      sampled = true;
  double                    sums[4] = { 0.0, 0.0, 0.0, 0.0 }; // magnitude, samples, fold value, folded
  if (b.screened != 0)
    for (std::size_t item = first + lane; item < end; item += 32)
    {
      sampled = sampled && itemSkip[item] == ItemSampled;
      const double * source = corners + item * ItemCorners;
      const double * target = source + 12;
      const std::uint32_t t = tetrahedra[item];
      double              folded = 0.0;
      sums[0] += ItemMagnitude(k.elasticity, k.rigidWeights, k.rigidInverseEdges, t, source, target);
      sums[1] += SampleCount(k.samplingRate, k.voxelVolume, source) + SampleCount(k.samplingRate, k.voxelVolume, target);
      sums[2] += VolumeViolation(SignedVolume(source), k.referenceVolumes[t], k.volumeFraction, folded);
      sums[2] += VolumeViolation(SignedVolume(target), k.referenceVolumes[t], k.volumeFraction, folded);
      sums[2] += RigidViolation(k.rigidLimitVolumes, k.rigidStrainLimitSquared, k.rigidInverseEdges, t, source, target,
                                folded);
      sums[3] += folded;
    }
  const bool screened = b.screened != 0 && end > first && __all_sync(0xffffffffu, sampled);
  bool          refused = false;
  std::uint32_t by = screen.archiveSize; // the refusing entry; archiveSize: infeasible
  if (screened)
  {
    for (double & s : sums)
      s = WarpTotal(s);
    double low[3];
    bool   scan = false;
    refused = RefusedBeforeArchive(b, screen, sums, low, scan);
    if (scan)
      for (std::uint32_t e = lane; !refused && e - lane < screen.archiveSize; e += 32)
      {
        bool found = false;
        if (e < screen.archiveSize)
        {
          const double * y = screen.archive + 3 * static_cast<std::size_t>(e);
          found = y[0] <= low[0] && y[1] <= low[1] && y[2] <= low[2];
        }
        const unsigned finders = __ballot_sync(0xffffffffu, found);
        if (finders != 0)
        {
          refused = true;
          by = e - lane + static_cast<std::uint32_t>(__ffs(static_cast<int>(finders)) - 1);
        }
      }
  }
  if (refused)
    for (std::size_t item = first + lane; item < end; item += 32)
      itemSkip[item] = ItemBoundSkipped;
  if (lane == 0)
    refusal[c] = refused ? 1 + by : 0;
}

__global__ void
GatherItems(const double * __restrict__ corners, const std::uint32_t * __restrict__ tetrahedra,
            const std::uint64_t * __restrict__ items, std::size_t count, double * outCorners,
            std::uint32_t * outTetrahedra)
{
  const std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= count * ItemCorners)
    return;
  const std::size_t at = i / ItemCorners, j = i % ItemCorners;
  const std::uint64_t item = items[at];
  outCorners[i] = corners[item * ItemCorners + j];
  if (j == 0)
    outTetrahedra[at] = tetrahedra[item];
}
} // namespace

void
LaunchScreenCandidates(const EvaluationConstants & constants, const CandidateBatch & batch, const double * corners,
                       const std::uint32_t * tetrahedra, const RefusalScreenView & screen, std::uint8_t * itemSkip,
                       std::uint32_t * refusal, void * stream)
{
  if (batch.firstCandidate >= batch.candidates)
    return;
  const std::size_t threads = 32 * (batch.candidates - batch.firstCandidate);
  const unsigned    blocks = static_cast<unsigned>((threads + ScreenThreads - 1) / ScreenThreads);
  ScreenCandidates<<<blocks, ScreenThreads, 0, static_cast<cudaStream_t>(stream)>>>(constants, batch, corners,
                                                                                    tetrahedra, screen, itemSkip,
                                                                                    refusal);
  Check(cudaGetLastError(), "launching the refusal screen");
}

void
LaunchGatherItems(const double * corners, const std::uint32_t * tetrahedra, const std::uint64_t * items,
                  std::size_t count, double * outCorners, std::uint32_t * outTetrahedra, void * stream)
{
  if (count == 0)
    return;
  const std::size_t threads = count * ItemCorners;
  const unsigned    blocks = static_cast<unsigned>((threads + 255) / 256);
  GatherItems<<<blocks, 256, 0, static_cast<cudaStream_t>(stream)>>>(corners, tetrahedra, items, count, outCorners,
                                                                      outTetrahedra);
  Check(cudaGetLastError(), "launching the item gather");
}
} // namespace morea_core::cuda
