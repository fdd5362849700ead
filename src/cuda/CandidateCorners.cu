// Builds the corners of every dependent tetrahedron of a batch of partial
// candidates on the device, from the parents' points and each candidate's
// moved points, so that the host uploads a few megabytes of points per batch
// instead of 24 doubles per tetrahedron.
#include "TetrahedronKernels.h"

#include "DeviceMemory.h"
#include "FoldRepairKernels.h"

#include <cstdint>

namespace morea::cuda
{
namespace
{
constexpr int GatherThreads = 256;

/** One warp per candidate, its lanes over the candidate's items (a few
 *  dozen dependent tetrahedra): no search for an item's candidate. (One
 *  thread per item with a binary search over the candidates took 0.78 ms
 *  per batch of the paper's configuration on an H100.) */
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
    const std::uint32_t t = dependent[item - first];
    double *            out = corners + item * ItemCorners;
    for (int j = 0; j < 4; ++j)
    {
      const std::uint32_t v = b.tetrahedra[4 * static_cast<std::size_t>(t) + j];
      const double *      s = source + 3 * static_cast<std::size_t>(v);
      const double *      g = target + 3 * static_cast<std::size_t>(v);
      for (std::uint32_t m = firstPoint; m < endPoint; ++m)
        if (b.elementPoints[m] == v)
        {
          s = moved + 6 * static_cast<std::size_t>(m - firstPoint);
          g = s + 3;
          break;
        }
      for (int a = 0; a < 3; ++a)
      {
        out[3 * j + a] = s[a];
        out[12 + 3 * j + a] = g[a];
      }
    }
    tetrahedra[item] = t;
    itemSkip[item] = skipped;
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
} // namespace

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
} // namespace morea::cuda
