// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Builds the corners of every dependent tetrahedron of a batch of partial
// candidates on the device, from the parents' points and each candidate's
// moved points, so that the host uploads a few megabytes of points per batch
// instead of 24 doubles per tetrahedron.
#include "TetrahedronKernels.h"

#include "DeviceMemory.h"
#include "FoldRepairKernels.h"

#include <cstdint>

namespace morea_core::cuda
{
namespace
{
constexpr int GatherThreads = 256;

/** One warp per candidate (a few dozen dependent tetrahedra): no search for
 *  an item's candidate. (One thread per item with a binary search over the
 *  candidates took 0.78 ms per batch of the paper's configuration on an
 *  H100.) The lanes write the candidate's corners as one contiguous run of
 *  doubles, lane l the l-th of each 32, so that every store of the warp
 *  fills whole sectors: with a lane per item, each store instruction wrote
 *  32 doubles 192 bytes apart, and the kernel took 7.9 ms of a late
 *  generation (Nsight Compute, one H100). */
__global__ void
GatherCandidateCorners(CandidateBatch b, FoldedCandidateSkip skip, double * corners, std::uint32_t * tetrahedra,
                       std::uint8_t * itemSkip)
{
  const std::size_t c = b.firstCandidate + (static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x) / 32;
  if (c >= b.candidates)
    return;
  const int           lane = static_cast<int>(threadIdx.x & 31);
  const std::uint32_t e = b.candidateElement[c];
  const std::size_t   first = b.candidateFirstItem[c], end = b.candidateFirstItem[c + 1];
  const std::uint32_t * dependent = b.elementTetrahedra + b.elementTetrahedronOffsets[e];
  const double *        source = b.parents + static_cast<std::size_t>(b.candidateParent[c]) * 6 * b.points;
  const double *        target = source + 3 * static_cast<std::size_t>(b.points);
  const std::uint32_t   firstPoint = b.elementPointOffsets[e], endPoint = b.elementPointOffsets[e + 1];
  const double *        moved = b.moved + 6 * static_cast<std::size_t>(b.candidateMoved[c]);
  const auto            leftFolded = [&skip, c](int side) {
    const std::uint8_t o = skip.outcome[2 * c + side];
    return (o & SideFolded) != 0 && (o & SideRepaired) == 0;
  };
  const std::uint8_t skipped = skip.skipIfFolded && skip.skipIfFolded[c] && (leftFolded(0) || leftFolded(1)) ? ItemUnused : ItemSampled;
  for (std::size_t item = first + lane; item < end; item += 32)
  {
    tetrahedra[item] = dependent[item - first];
    itemSkip[item] = skipped;
  }
  // Double d of the run: item d / 24, then source (0) or target (1) side,
  // corner, axis (ItemCorners' layout).
  const std::size_t count = ItemCorners * (end - first);
  double *          out = corners + first * ItemCorners;
  for (std::size_t d = static_cast<std::size_t>(lane); d < count; d += 32)
  {
    const auto          within = static_cast<std::uint32_t>(d % ItemCorners);
    const std::uint32_t side = within / 12, corner = within % 12 / 3, axis = within % 3;
    const std::uint32_t t = dependent[d / ItemCorners];
    const std::uint32_t v = b.tetrahedra[4 * static_cast<std::size_t>(t) + corner];
    const double *      p = (side == 0 ? source : target) + 3 * static_cast<std::size_t>(v);
    for (std::uint32_t m = firstPoint; m < endPoint; ++m)
      if (b.elementPoints[m] == v)
      {
        p = moved + 6 * static_cast<std::size_t>(m - firstPoint) + 3 * side;
        break;
      }
    out[d] = p[axis];
  }
}

__global__ void
ScatterParents(const double * __restrict__ staged, const std::uint32_t * __restrict__ slots, std::size_t count,
               std::size_t perParent, double * store)
{
  const std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < count * perParent)
    store[static_cast<std::size_t>(slots[i / perParent]) * perParent + i % perParent] = staged[i];
}
/** Thread d writes double d of the corners of whole solutions: item
 *  s * tetrahedra + t is solution s's tetrahedron t (ItemCorners' layout),
 *  so the stores are contiguous. */
__global__ void
GatherSolutionCorners(const double * __restrict__ solutions, std::size_t count, const std::uint32_t * __restrict__ mesh,
                      std::uint32_t tetrahedraPerSolution, std::uint32_t points, double * corners,
                      std::uint32_t * tetrahedra)
{
  const std::size_t d = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (d >= count * tetrahedraPerSolution * ItemCorners)
    return;
  const std::size_t   item = d / ItemCorners;
  const auto          within = static_cast<std::uint32_t>(d % ItemCorners);
  const std::uint32_t side = within / 12, corner = within % 12 / 3, axis = within % 3;
  const std::size_t   s = item / tetrahedraPerSolution;
  const auto          t = static_cast<std::uint32_t>(item % tetrahedraPerSolution);
  const std::uint32_t v = mesh[4 * static_cast<std::size_t>(t) + corner];
  corners[d] = solutions[(2 * s + side) * 3 * static_cast<std::size_t>(points) + 3 * static_cast<std::size_t>(v) + axis];
  if (within == 0)
    tetrahedra[item] = t;
}
} // namespace

void
LaunchGatherSolutionCorners(const double * solutions, std::size_t count, const std::uint32_t * mesh,
                            std::size_t tetrahedraPerSolution, std::size_t points, double * corners,
                            std::uint32_t * tetrahedra, void * stream)
{
  const std::size_t doubles = count * tetrahedraPerSolution * ItemCorners;
  if (doubles == 0)
    return;
  const unsigned blocks = static_cast<unsigned>((doubles + GatherThreads - 1) / GatherThreads);
  GatherSolutionCorners<<<blocks, GatherThreads, 0, static_cast<cudaStream_t>(stream)>>>(
    solutions, count, mesh, static_cast<std::uint32_t>(tetrahedraPerSolution), static_cast<std::uint32_t>(points),
    corners, tetrahedra);
  Check(cudaGetLastError(), "launching the solution corner kernel");
}

void
LaunchGatherCandidateCorners(const CandidateBatch & batch, std::size_t items, const FoldedCandidateSkip & skip,
                             double * corners, std::uint32_t * tetrahedra, std::uint8_t * itemSkip, void * stream)
{
  if (items == 0)
    return;
  if ((skip.skipIfFolded == nullptr) != (skip.outcome == nullptr))
    throw Error("CUDA backend: skipping folded candidates needs both their flags and the fold checks' outcome");
  if (batch.firstCandidate >= batch.candidates)
    return;
  const std::size_t warps = batch.candidates - batch.firstCandidate;
  const unsigned    blocks = static_cast<unsigned>((warps * 32 + GatherThreads - 1) / GatherThreads);
  GatherCandidateCorners<<<blocks, GatherThreads, 0, static_cast<cudaStream_t>(stream)>>>(batch, skip, corners,
                                                                                        tetrahedra, itemSkip);
  Check(cudaGetLastError(), "launching the corner gathering kernel");
}

void
LaunchScatterParents(const double * staged, const std::uint32_t * slots, std::size_t count, std::size_t perParent,
                     double * store, void * stream)
{
  if (count == 0)
    return;
  const std::size_t values = count * perParent;
  const unsigned    blocks = static_cast<unsigned>((values + GatherThreads - 1) / GatherThreads);
  ScatterParents<<<blocks, GatherThreads, 0, static_cast<cudaStream_t>(stream)>>>(staged, slots, count, perParent,
                                                                                  store);
  Check(cudaGetLastError(), "launching the parent scatter kernel");
}
} // namespace morea_core::cuda
