// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The fold check and the Gaussian repair of partial candidates on the device,
// mirroring CheckCandidateFolds / RepairPoints (src/core): the same points in
// the same order, the same moves (RepairNoise.h), the same star terms
// (RepairStar.h) and sums in the same order, rounded as on the host (no fused
// multiply-adds: a repaired point's bits seed its tetrahedra's samples); only
// the 64 trials of a point run side by side, one lane each.
#include "FoldRepairKernels.h"

#include "DeviceMemory.h"
#include "TetrahedronDevice.cuh"

#include "morea_core/RepairNoise.h"
#include "morea_core/RepairStar.h"

#include <cstdint>

namespace morea_core::cuda
{
namespace
{
using repair_noise::Add;
using repair_noise::Div;
using repair_noise::Mul;
using repair_noise::Sub;

constexpr int          RepairThreads = 128;
constexpr unsigned     FullMask = 0xffffffffu;
constexpr std::uint32_t NoPoint = 0xffffffffu;

/** One side of one candidate: its parent's points with the element's points
 *  replaced by the candidate's (owned by this warp, written in place). */
struct SideView
{
  const std::uint32_t * tetrahedra;
  const double *        parent;        ///< 3 per point
  double *              moved;         ///< 6 per element point (this side's half)
  const std::uint32_t * elementPoints; ///< the warp's copy in shared memory
  std::uint32_t         count;

  /** From shared memory: on an H100 the fold checks of late generations
   *  took 25.3-25.6 ms per generation against 26.3-26.6 ms with the scan
   *  over global memory. (The same scan without the early exit took
   *  30.9 ms.) */
  __device__ int
  Local(std::uint32_t v) const
  {
    for (std::uint32_t k = 0; k < count; ++k)
      if (elementPoints[k] == v)
        return static_cast<int>(k);
    return -1;
  }

  __device__ const double *
  Point(std::uint32_t v) const
  {
    const int k = Local(v);
    return k < 0 ? parent + 3 * static_cast<std::size_t>(v) : moved + 6 * k;
  }
};

/** FoldConstraint::VolumeViolation. */
__device__ double
VolumeViolation(const FoldRepairConstants & k, std::uint32_t t, const double * const c[4], bool & folded)
{
  double corners[12];
  for (int j = 0; j < 4; ++j)
    for (int a = 0; a < 3; ++a)
      corners[3 * j + a] = c[j][a];
  double count = 0.0;
  const double value =
    device::CornersVolumeViolation(corners, k.referenceVolumes[t], k.volumeFraction, count);
  folded = count > 0.0;
  return value;
}

/** Tetrahedron t's violation (the constraint's triple product). */
__device__ double
TetrahedronViolation(const FoldRepairConstants & k, const SideView & s, std::uint32_t t, bool & folded)
{
  const double * c[4];
  for (int j = 0; j < 4; ++j)
    c[j] = s.Point(s.tetrahedra[4 * static_cast<std::size_t>(t) + j]);
  return VolumeViolation(k, t, c, folded);
}

/** The element's points (bits of their local indices: at most
 *  MaxRepairElementPoints, as the backend checks) that lie in a folded
 *  tetrahedron among the `n` (lanes share them), the same for every lane.
 *  Every one of those tetrahedra has a point of the element, so the result is
 *  0 exactly when none folds. */
__device__ unsigned long long
FoldedElementPoints(const FoldRepairConstants & k, const SideView & s, const std::uint32_t * tets, std::uint32_t n,
                    unsigned lane)
{
  unsigned long long flagged = 0;
  for (std::uint32_t i = lane; i < n; i += 32)
  {
    bool folded = false;
    TetrahedronViolation(k, s, tets[i], folded);
    if (folded)
      for (int j = 0; j < 4; ++j)
      {
        const int local = s.Local(s.tetrahedra[4 * static_cast<std::size_t>(tets[i]) + j]);
        if (local >= 0)
          flagged |= 1ull << local;
      }
  }
  for (int offset = 16; offset > 0; offset /= 2)
    flagged |= __shfl_xor_sync(FullMask, flagged, offset);
  return flagged;
}

/** The star term (RepairStar.h) of tetrahedron t around its corner p. The
 *  other corners are picked by comparisons rather than gathered into an
 *  array by a running index, which put the array in local memory. */
__device__ void
SideStarTerm(const FoldRepairConstants & k, const SideView & s, std::uint32_t p, std::uint32_t t, StarTerm & term)
{
  const std::uint32_t * v = s.tetrahedra + 4 * static_cast<std::size_t>(t);
  const int             slot = v[0] == p ? 0 : (v[1] == p ? 1 : (v[2] == p ? 2 : 3));
  const double * const  other[3] = { s.Point(v[slot == 0 ? 1 : 0]), s.Point(v[slot <= 1 ? 2 : 1]),
                                     s.Point(v[slot <= 2 ? 3 : 2]) };
  MakeStarTerm(other, slot, k.referenceVolumes[t], k.volumeFraction, term);
}

/** BoundedViolation (MeshRepair.cxx) of point p at `position` for a star too
 *  large for PointStar: the terms made on the way, in ascending order,
 *  false once the sum exceeds `bound`. */
__device__ bool
PointViolation(const FoldRepairConstants & k, const SideView & s, std::uint32_t p, const double * position,
               double bound, double & value, std::uint32_t & folded)
{
  value = 0.0;
  folded = 0;
  for (std::uint32_t i = k.pointTetrahedronOffsets[p]; i < k.pointTetrahedronOffsets[p + 1]; ++i)
  {
    StarTerm term;
    SideStarTerm(k, s, p, k.pointTetrahedra[i], term);
    bool f = false;
    value = Add(value, StarTermViolation(term, position, f));
    folded += f;
    if (value > bound)
      return false;
  }
  return true;
}

/** Distance of x to the plane of face f (false for a degenerate face),
 *  rounded as RepairPoints rounds it on the host. */
__device__ bool
FacePlaneDistance(const double * const f[3], const double * x, double & distance)
{
  double u[3], w[3], d[3];
  for (int a = 0; a < 3; ++a)
  {
    u[a] = Sub(f[1][a], f[0][a]);
    w[a] = Sub(f[2][a], f[0][a]);
    d[a] = Sub(x[a], f[0][a]);
  }
  const double normal[3] = { Sub(Mul(u[1], w[2]), Mul(u[2], w[1])), Sub(Mul(u[2], w[0]), Mul(u[0], w[2])),
                             Sub(Mul(u[0], w[1]), Mul(u[1], w[0])) };
  const double area2 = sqrt(Add(Add(Mul(normal[0], normal[0]), Mul(normal[1], normal[1])), Mul(normal[2], normal[2])));
  if (area2 == 0.0)
    return false;
  distance = Div(fabs(Add(Add(Mul(normal[0], d[0]), Mul(normal[1], d[1])), Mul(normal[2], d[2]))), area2);
  return true;
}

/** The mean of the face-plane distances of x, summed in the order the
 *  faces are added (degenerate faces left out), as RepairPoints sums them. */
struct MeanFaceDistance
{
  double        sum{ 0.0 };
  std::uint32_t n{ 0 };

  __device__ void
  AddFace(const double * const f[3], const double * x)
  {
    double distance = 0.0;
    if (FacePlaneDistance(f, x, distance))
      AddDistance(distance);
  }
  __device__ void
  AddDistance(double distance)
  {
    sum = Add(sum, distance);
    ++n;
  }
  __device__ double
  Value() const
  {
    return n ? Div(sum, static_cast<double>(n)) : 0.0;
  }
};

/** Mean distance of p to the planes of the faces opposite it. */
__device__ double
DistanceToSurroundingPolyhedron(const FoldRepairConstants & k, const SideView & s, std::uint32_t p)
{
  const double *   x = s.Point(p);
  MeanFaceDistance mean;
  for (std::uint32_t i = k.pointTetrahedronOffsets[p]; i < k.pointTetrahedronOffsets[p + 1]; ++i)
  {
    const std::uint32_t * v = s.tetrahedra + 4 * static_cast<std::size_t>(k.pointTetrahedra[i]);
    const int             slot = v[0] == p ? 0 : (v[1] == p ? 1 : (v[2] == p ? 2 : 3));
    const double * const  f[3] = { s.Point(v[slot == 0 ? 1 : 0]), s.Point(v[slot <= 1 ? 2 : 1]),
                                   s.Point(v[slot <= 2 ? 3 : 2]) };
    mean.AddFace(f, x);
  }
  return mean.Value();
}

/** The tetrahedra around one point as the repair's trials see them: every
 *  corner but the point itself stays where it is while the point's 64 trial
 *  positions are tried, so the lanes make the star's terms (RepairStar.h)
 *  in shared memory once (one tetrahedron each) and every trial then reads
 *  them with broadcast loads. The values and the order of the sums are those
 *  of the uncached path. */
constexpr std::uint32_t MaxStarTetrahedra = 64;

/** A star term padded to 72 bytes in shared memory: the lanes that make a
 *  star's terms side by side write them 18 words apart, so that at most
 *  two share a bank (at 64 bytes, 16 did). */
struct PaddedStarTerm
{
  StarTerm term;
  double   padding;
};

struct PointStar
{
  /** A term takes 64 bytes, where the three other corners and the base
   *  volume took 80 and a trial's triple product 23 operations. */
  PaddedStarTerm terms[MaxStarTetrahedra];
  std::uint32_t count;
  /** Per tetrahedron a term of a sum that the lanes compute side by side
   *  and then add in order (StarViolationOfAll, StarDistance), and whether
   *  it counts (folded, or a face that is not degenerate). */
  double        term[MaxStarTetrahedra];
  std::uint8_t  counts[MaxStarTetrahedra];
  /** Per lane the position of its best trial so far: the winner's is read
   *  from here instead of being drawn again. */
  double        best[32][3];
  /** The side's element points (SideView::elementPoints). */
  std::uint32_t elementPoints[MaxRepairElementPoints];
};

/** Fills `star` for point p (whose tetrahedra number at most MaxStarTetrahedra). */
__device__ void
GatherStar(const FoldRepairConstants & k, const SideView & s, std::uint32_t p, unsigned lane, PointStar & star)
{
  const std::uint32_t first = k.pointTetrahedronOffsets[p];
  const std::uint32_t count = k.pointTetrahedronOffsets[p + 1] - first;
  __syncwarp(); // no lane still reads the previous point's star
  for (std::uint32_t i = lane; i < count; i += 32)
    SideStarTerm(k, s, p, k.pointTetrahedra[first + i], star.terms[i].term);
  if (lane == 0)
    star.count = count;
  __syncwarp();
}

/** PointViolation from the star, the point at `position`. (Making the
 *  terms two or four at a time before adding them in order, for more
 *  independent work per warp, was no faster on an H100: 26.7 and 27.7 ms
 *  of fold checks per late generation against 26.3-26.6 ms.) */
__device__ bool
StarViolation(const PointStar & star, const double * position, double bound, double & value, std::uint32_t & folded)
{
  value = 0.0;
  folded = 0;
  for (std::uint32_t i = 0; i < star.count; ++i)
  {
    bool f = false;
    value = Add(value, StarTermViolation(star.terms[i].term, position, f));
    folded += f;
    if (value > bound)
      return false;
  }
  return true;
}

/** StarViolation without a bound, the same value for every lane: the lanes
 *  compute the terms side by side, then each adds them in order. (With each
 *  lane going through all the terms itself, this took a sixth of the
 *  repair's time, and StarDistance as much.) */
__device__ void
StarViolationOfAll(PointStar & star, const double * position, unsigned lane, double & value, std::uint32_t & folded)
{
  __syncwarp(); // no lane still reads the terms of the previous sum
  for (std::uint32_t i = lane; i < star.count; i += 32)
  {
    bool f = false;
    star.term[i] = StarTermViolation(star.terms[i].term, position, f);
    star.counts[i] = f;
  }
  __syncwarp();
  value = 0.0;
  folded = 0;
  for (std::uint32_t i = 0; i < star.count; ++i)
  {
    value = Add(value, star.term[i]);
    folded += star.counts[i];
  }
}

/** DistanceToSurroundingPolyhedron from the star, the faces' distances
 *  computed side by side, added in order by every lane (MeanFaceDistance).
 *  A term's normal is its face's normal, negated or not, and its volume the
 *  dot product FacePlaneDistance takes, negated alike: the same bits once
 *  the sign is dropped. */
__device__ double
StarDistance(PointStar & star, const double * x, unsigned lane)
{
  __syncwarp(); // no lane still reads the terms of the previous sum
  for (std::uint32_t i = lane; i < star.count; i += 32)
  {
    const double * n = star.terms[i].term.normal;
    const double   area2 = sqrt(Add(Add(Mul(n[0], n[0]), Mul(n[1], n[1])), Mul(n[2], n[2])));
    star.counts[i] = area2 != 0.0;
    star.term[i] = area2 != 0.0 ? Div(fabs(StarTermVolume(star.terms[i].term, x)), area2) : 0.0;
  }
  __syncwarp();
  MeanFaceDistance mean;
  for (std::uint32_t i = 0; i < star.count; ++i)
    if (star.counts[i])
      mean.AddDistance(star.term[i]);
  return mean.Value();
}

/** Trial `trial` of point p (pin `pin`) around `original`, in the domain. */
__device__ void
TrialPosition(const FoldRepairConstants & k, std::uint64_t seed, std::uint32_t round, std::uint32_t p,
              std::uint32_t trial, const double * original, double scale, const std::int8_t * pin, double * out)
{
  double move[3];
  RepairTrialNormals(seed, round, p, trial, move);
  for (int a = 0; a < 3; ++a)
  {
    const double q = Add(original[a], Mul(scale, move[a]));
    out[a] = pin[a] < 0 ? k.lower[a] : (pin[a] > 0 ? k.upper[a] : fmin(fmax(q, k.lower[a]), k.upper[a]));
  }
}

/** RepairPoints over one side, whose element points in a folded tetrahedron
 *  are `flagged` (FoldedElementPoints); true when it ends fold-free. */
__device__ bool
RepairSide(const FoldRepairConstants & k, const SideView & s, const std::uint32_t * dependent, std::uint32_t n,
           unsigned long long flagged, std::uint64_t seed, unsigned lane, PointStar & star)
{
  for (std::uint32_t round = 0; round < k.maxRounds; ++round)
  {
    bool          movedAny = false;
    std::uint32_t previous = 0;
    bool          first = true;
    while (true)
    {
      // The next flagged point in ascending index, as the host visits them.
      int           next = -1;
      std::uint32_t p = 0;
      for (std::uint32_t m = 0; m < s.count; ++m)
        if ((flagged >> m) & 1ull)
        {
          const std::uint32_t v = s.elementPoints[m];
          if ((first || v > previous) && (next < 0 || v < p))
          {
            next = static_cast<int>(m);
            p = v;
          }
        }
      if (next < 0)
        break;
      first = false;
      previous = p;
      const std::int8_t * pin = k.pins + 3 * static_cast<std::size_t>(p);
      if (pin[0] != 0 && pin[1] != 0 && pin[2] != 0)
        continue; // corners never move
      // Every lane computes the same current value and scale; the trials
      // are spread over the lanes.
      const bool    cached = k.pointTetrahedronOffsets[p + 1] - k.pointTetrahedronOffsets[p] <= MaxStarTetrahedra;
      double *      position = s.moved + 6 * next;
      double        original[3] = { position[0], position[1], position[2] };
      double        currentValue = 0.0;
      std::uint32_t currentFolded = 0;
      if (cached)
      {
        GatherStar(k, s, p, lane, star);
        StarViolationOfAll(star, original, lane, currentValue, currentFolded);
      }
      else
        PointViolation(k, s, p, original, INFINITY, currentValue, currentFolded);
      if (currentFolded == 0)
        continue; // fixed by an earlier move in this pass
      const double scale = cached ? StarDistance(star, original, lane) : DistanceToSurroundingPolyhedron(k, s, p);
      if (!(scale > 0.0))
        continue;

      // Each lane: the first of its trials with the lowest (value, folded),
      // if below the current; then the lowest over the lanes, ties to the
      // lower trial: the trial the host's sequential scan keeps.
      double        bestValue = currentValue;
      std::uint32_t bestFolded = currentFolded;
      std::uint32_t bestTrial = NoPoint;
      for (std::uint32_t first = 0; first < k.samplesPerPoint; first += 32) // warp-uniform
      {
        // A trial whose partial sum passes the lowest value any lane has
        // found so far cannot be kept: the sums only grow (terms >= 0).
        double bound = bestValue;
        if (first > 0)
          for (int offset = 16; offset > 0; offset /= 2)
            bound = fmin(bound, __shfl_xor_sync(FullMask, bound, offset));
        const std::uint32_t trial = first + lane;
        if (trial >= k.samplesPerPoint)
          continue;
        double candidate[3];
        TrialPosition(k, seed, round, p, trial, original, scale, pin, candidate);
        double        value = 0.0;
        std::uint32_t folded = 0;
        const bool    within = cached ? StarViolation(star, candidate, bound, value, folded)
                                      : PointViolation(k, s, p, candidate, bound, value, folded);
        if (within && (value < bestValue || (value <= bestValue && folded < bestFolded)))
        {
          bestValue = value;
          bestFolded = folded;
          bestTrial = trial;
          for (int a = 0; a < 3; ++a)
            star.best[lane][a] = candidate[a];
        }
      }
      for (int offset = 16; offset > 0; offset /= 2)
      {
        const double        otherValue = __shfl_xor_sync(FullMask, bestValue, offset);
        const std::uint32_t otherFolded = __shfl_xor_sync(FullMask, bestFolded, offset);
        const std::uint32_t otherTrial = __shfl_xor_sync(FullMask, bestTrial, offset);
        const bool          better =
          otherValue < bestValue ||
          (otherValue == bestValue && (otherFolded < bestFolded || (otherFolded == bestFolded && otherTrial < bestTrial)));
        if (better)
        {
          bestValue = otherValue;
          bestFolded = otherFolded;
          bestTrial = otherTrial;
        }
      }
      if (bestTrial == NoPoint)
        continue;
      __syncwarp(); // the winning lane's position is written
      const double chosen[3] = { star.best[bestTrial % 32][0], star.best[bestTrial % 32][1],
                                 star.best[bestTrial % 32][2] };
      if (lane == 0)
        for (int a = 0; a < 3; ++a)
          position[a] = chosen[a];
      __syncwarp();
      if (chosen[0] != original[0] || chosen[1] != original[1] || chosen[2] != original[2])
        movedAny = true;
    }
    // The next round's points: the check that ends this round finds them.
    flagged = FoldedElementPoints(k, s, dependent, n, lane);
    if (flagged == 0)
      return true;
    if (!movedAny)
      return false;
  }
  return false;
}

/** One warp per side of a candidate. Tried and not kept (H100, late
 *  generations, fold checks per generation): at most 80 registers for 6
 *  resident blocks per SM (a few spills), 0.0432 s against 0.0421 s; a
 *  trial first summing the tetrahedra violated at the current position, to
 *  stop sooner, 0.0458 s against 0.0435 s. */
__global__ void
CheckCandidateFolds(CandidateBatch b, FoldRepairConstants k, const std::uint8_t * check,
                    const std::uint64_t * sideSeeds, double * moved, std::uint8_t * outcome, std::size_t first,
                    std::size_t count)
{
  __shared__ PointStar stars[RepairThreads / 32];
  const std::size_t warp = (static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x) / 32;
  const unsigned    lane = threadIdx.x % 32;
  if (warp >= 2 * count)
    return; // whole warps only: the block size is a multiple of 32
  const std::size_t c = first + warp / 2;
  const int         side = static_cast<int>(warp % 2);
  if (!check[c])
    return;
  const std::uint32_t e = b.candidateElement[c];
  SideView            s;
  s.tetrahedra = b.tetrahedra;
  s.parent = b.parents + static_cast<std::size_t>(b.candidateParent[c]) * 6 * b.points +
             static_cast<std::size_t>(side) * 3 * b.points;
  s.moved = moved + 6 * static_cast<std::size_t>(b.candidateMoved[c]) + 3 * side;
  PointStar &           star = stars[threadIdx.x / 32];
  const std::uint32_t * elementPoints = b.elementPoints + b.elementPointOffsets[e];
  s.count = b.elementPointOffsets[e + 1] - b.elementPointOffsets[e];
  for (std::uint32_t m = lane; m < s.count; m += 32)
    star.elementPoints[m] = elementPoints[m];
  __syncwarp();
  s.elementPoints = star.elementPoints;
  const std::uint32_t * dependent = b.elementTetrahedra + b.elementTetrahedronOffsets[e];
  const std::uint32_t   n = b.elementTetrahedronOffsets[e + 1] - b.elementTetrahedronOffsets[e];

  std::uint8_t result = 0;
  const unsigned long long flagged = FoldedElementPoints(k, s, dependent, n, lane);
  if (flagged != 0)
  {
    result = SideFolded;
    if (k.repair && RepairSide(k, s, dependent, n, flagged, sideSeeds[2 * c + side], lane, star))
      result |= SideRepaired;
  }
  if (lane == 0)
    outcome[2 * c + side] = result;
}
} // namespace

void
LaunchCheckCandidateFolds(const CandidateBatch & batch, const FoldRepairConstants & constants,
                          const std::uint8_t * check, const std::uint64_t * sideSeeds, double * moved,
                          std::uint8_t * outcome, std::size_t first, std::size_t count, void * stream)
{
  if (count == 0)
    return;
  if (first + count > batch.candidates)
    throw Error("fold checks: candidates beyond the batch");
  const std::size_t threads = 2 * count * 32;
  const unsigned    blocks = static_cast<unsigned>((threads + RepairThreads - 1) / RepairThreads);
  CheckCandidateFolds<<<blocks, RepairThreads, 0, static_cast<cudaStream_t>(stream)>>>(
    batch, constants, check, sideSeeds, moved, outcome, first, count);
  Check(cudaGetLastError(), "launching the fold check kernel");
}
} // namespace morea_core::cuda
