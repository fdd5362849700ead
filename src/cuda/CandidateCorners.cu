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

__global__ void
GatherCandidateCorners(CandidateBatch b, std::size_t items, FoldedCandidateSkip skip, double * corners,
                       std::uint32_t * tetrahedra, std::uint8_t * itemSkip)
{
  const std::size_t item = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (item >= items)
    return;
  // The candidate is the last one whose first item is <= item (candidates
  // without dependent tetrahedra own no item and are skipped this way).
  std::size_t lo = 0, hi = b.candidates;
  while (hi - lo > 1)
  {
    const std::size_t mid = (lo + hi) / 2;
    if (b.candidateFirstItem[mid] <= item)
      lo = mid;
    else
      hi = mid;
  }
  const std::size_t   c = lo;
  const std::uint32_t e = b.candidateElement[c];
  const std::uint32_t t =
    b.elementTetrahedra[b.elementTetrahedronOffsets[e] + static_cast<std::uint32_t>(item - b.candidateFirstItem[c])];
  const double *      source = b.parents + static_cast<std::size_t>(b.candidateParent[c]) * 6 * b.points;
  const double *      target = source + 3 * static_cast<std::size_t>(b.points);
  const std::uint32_t firstPoint = b.elementPointOffsets[e], endPoint = b.elementPointOffsets[e + 1];
  double *            out = corners + item * ItemCorners;
  for (int j = 0; j < 4; ++j)
  {
    const std::uint32_t v = b.tetrahedra[4 * static_cast<std::size_t>(t) + j];
    const double *      s = source + 3 * static_cast<std::size_t>(v);
    const double *      g = target + 3 * static_cast<std::size_t>(v);
    for (std::uint32_t m = firstPoint; m < endPoint; ++m)
      if (b.elementPoints[m] == v)
      {
        s = b.moved + 6 * static_cast<std::size_t>(b.candidateMoved[c] + (m - firstPoint));
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
  const auto leftFolded = [&skip, c](int side) {
    const std::uint8_t o = skip.outcome[2 * c + side];
    return (o & SideFolded) != 0 && (o & SideRepaired) == 0;
  };
  itemSkip[item] = skip.skipIfFolded && skip.skipIfFolded[c] && (leftFolded(0) || leftFolded(1)) ? 1 : 0;
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
  const unsigned blocks = static_cast<unsigned>((items + GatherThreads - 1) / GatherThreads);
  GatherCandidateCorners<<<blocks, GatherThreads, 0, static_cast<cudaStream_t>(stream)>>>(
    batch, items, skip, corners, tetrahedra, itemSkip);
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
