// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/FieldFoldRepair.h"

#include "morea_core/Error.h"
#include "morea_core/ThreadPool.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace morea_core
{
namespace
{
using Index3 = std::array<std::size_t, 3>;

Index3
IndexOf(const Volume<Vec3> & field, std::size_t offset)
{
  const std::size_t i = offset % field.size[0];
  const std::size_t rest = offset / field.size[0];
  return { { i, rest % field.size[1], rest / field.size[1] } };
}

/** Calls f(offset) for every voxel within Chebyshev distance `radius` of `centre`. */
template <typename F>
void
ForEachInCube(const Volume<Vec3> & field, const Index3 & centre, std::size_t radius, F && f)
{
  Index3 lo;
  Index3 hi;
  for (int d = 0; d < 3; ++d)
  {
    lo[d] = centre[d] > radius ? centre[d] - radius : 0;
    hi[d] = std::min(centre[d] + radius, field.size[d] - 1);
  }
  for (std::size_t k = lo[2]; k <= hi[2]; ++k)
    for (std::size_t j = lo[1]; j <= hi[1]; ++j)
      for (std::size_t i = lo[0]; i <= hi[0]; ++i)
        f(field.Offset(i, j, k));
}

/** The voxels a determinant reads: along each axis d, d(x + u)/dx_d is
 *  (u[hi] - u[lo]) * weight, a central difference inside the grid and a
 *  one-sided one at its faces (lo or hi is then the voxel itself); weight is
 *  0 along an axis one voxel thick. */
struct Stencil
{
  std::size_t lo[3];
  std::size_t hi[3];
  double      weight[3];
};

Stencil
StencilAt(const Volume<Vec3> & field, std::size_t centre)
{
  const Index3      index = IndexOf(field, centre);
  const std::size_t stride[3] = { 1, field.size[0], field.size[0] * field.size[1] };
  Stencil           s;
  for (int d = 0; d < 3; ++d)
  {
    const bool hasLower = index[d] > 0;
    const bool hasUpper = index[d] + 1 < field.size[d];
    s.lo[d] = hasLower ? centre - stride[d] : centre;
    s.hi[d] = hasUpper ? centre + stride[d] : centre;
    const double steps = static_cast<double>(hasLower) + static_cast<double>(hasUpper);
    s.weight[d] = steps > 0.0 ? 1.0 / (steps * field.spacing[d]) : 0.0;
  }
  return s;
}

/** jac[c][d] = d(x + u)_c / d x_d. */
void
JacobianOf(const Volume<Vec3> & field, const Stencil & s, double jac[3][3])
{
  for (int d = 0; d < 3; ++d)
    for (int c = 0; c < 3; ++c)
      jac[c][d] = (field.data[s.hi[d]][c] - field.data[s.lo[d]][c]) * s.weight[d] + (c == d ? 1.0 : 0.0);
}

double
Determinant(const double m[3][3])
{
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

/** cof[c][d] = d det / d m[c][d]. */
void
Cofactors(const double m[3][3], double cof[3][3])
{
  for (int c = 0; c < 3; ++c)
    for (int d = 0; d < 3; ++d)
    {
      const int c1 = (c + 1) % 3, c2 = (c + 2) % 3, d1 = (d + 1) % 3, d2 = (d + 2) % 3;
      cof[c][d] = m[c1][d1] * m[c2][d2] - m[c1][d2] * m[c2][d1];
    }
}

/** Calls f(offset) for the voxel and its face neighbours inside the grid:
 *  the determinants that read its displacement. */
template <typename F>
void
ForEachReader(const Volume<Vec3> & field, std::size_t centre, F && f)
{
  const Index3      index = IndexOf(field, centre);
  const std::size_t stride[3] = { 1, field.size[0], field.size[0] * field.size[1] };
  f(centre);
  for (int d = 0; d < 3; ++d)
  {
    if (index[d] > 0)
      f(centre - stride[d]);
    if (index[d] + 1 < field.size[d])
      f(centre + stride[d]);
  }
}

Vec3
NeighbourhoodMean(const Volume<Vec3> & field, const Index3 & centre)
{
  Vec3        sum{ { 0.0, 0.0, 0.0 } };
  std::size_t n{ 0 };
  ForEachInCube(field, centre, 1, [&](std::size_t o) {
    for (int c = 0; c < 3; ++c)
      sum[c] += field.data[o][c];
    ++n;
  });
  return { { sum[0] / n, sum[1] / n, sum[2] / n } };
}

void
CheckField(const Volume<Vec3> & field)
{
  if (field.NumberOfVoxels() == 0 || field.data.size() != field.NumberOfVoxels())
    throw Error("voxel fold repair: the displacement field is empty or its buffer does not match its size");
  for (const double s : field.spacing)
    if (!(s > 0.0) || !std::isfinite(s))
      throw Error("voxel fold repair: the field's spacing must be positive");
}

double
DeterminantAt(const Volume<Vec3> & field, std::size_t offset)
{
  double jac[3][3];
  JacobianOf(field, StencilAt(field, offset), jac);
  return Determinant(jac);
}

/** What an active voxel (determinant below half the target) asks of the voxels
 *  its determinant reads: along axis d, +column[d] of u[stencil.hi[d]] and
 *  -column[d] of u[stencil.lo[d]] (column[d][c] = share * weight_d *
 *  cofactor[c][d], share making the linearised lift reach the target). */
struct Request
{
  Stencil stencil;
  double  column[3][3];
};

Request
RequestAt(const Volume<Vec3> & field, std::size_t voxel, double target)
{
  Request r{ StencilAt(field, voxel), {} };
  double  jac[3][3];
  double  cof[3][3];
  JacobianOf(field, r.stencil, jac);
  Cofactors(jac, cof);
  // |d det / d u|^2 summed over the stencil's voxels. On a face the voxel is
  // its own neighbour along that axis: its entries from the face axes merge
  // before squaring.
  Vec3   own{ { 0.0, 0.0, 0.0 } };
  double norm2{ 0.0 };
  for (int d = 0; d < 3; ++d)
    for (const auto & [p, w] : { std::make_pair(r.stencil.hi[d], r.stencil.weight[d]),
                                 std::make_pair(r.stencil.lo[d], -r.stencil.weight[d]) })
      for (int c = 0; c < 3; ++c)
      {
        if (p == voxel)
          own[c] += w * cof[c][d];
        else
          norm2 += w * w * cof[c][d] * cof[c][d];
      }
  norm2 += own[0] * own[0] + own[1] * own[1] + own[2] * own[2];
  if (!(norm2 > 1e-12))
    return r; // a determinant that no displacement moves (linearly): no request
  const double share = (target - Determinant(jac)) / norm2;
  for (int d = 0; d < 3; ++d)
    for (int c = 0; c < 3; ++c)
      r.column[d][c] = share * r.stencil.weight[d] * cof[c][d];
  return r;
}

/** The projection: every voxel whose determinant is below half the target
 *  asks for the smallest change of its stencil's displacements that lifts the
 *  determinant, linearised, to the target; the requests are summed and a
 *  step of the sum applied, in rounds, until no determinant is <= 0 or the
 *  rounds run out. Each voxel gathers the requests of the determinants that
 *  read it in a fixed order, so the result does not depend on the threads.
 *  `folded` counts the determinants <= 0 on entry; `determinant` holds every
 *  voxel's current determinant on entry and on return; `changed` marks the
 *  voxels moved. Returns the rounds. */
unsigned int
ProjectOntoPositiveDeterminants(Volume<Vec3> & field, const FieldFoldRepairOptions & options, std::size_t folded,
                                std::vector<double> & determinant, std::vector<std::uint8_t> & changed)
{
  const std::size_t        n = field.NumberOfVoxels();
  const double             target = options.projectionTarget;
  // A voxel asks while its determinant is below half the target: one that
  // has come close drops out rather than creeping up to the target for ever
  // (on the abdominal pair's fields a tenth of the time, the same changes).
  const double             threshold = 0.5 * target;
  constexpr std::uint32_t  none = 0xffffffffu;
  if (options.maximumProjectionRounds == 0)
    return 0;
  std::vector<std::size_t> active; // determinant below the threshold
  for (std::size_t o = 0; o < n; ++o)
    if (determinant[o] < threshold)
      active.push_back(o);
  if (active.size() >= none)
    throw Error("voxel fold repair: too many voxels near folds (" + std::to_string(active.size()) + ")");

  ThreadPool                 pool(options.threads);
  std::vector<std::uint32_t> activeIndex(n, none); // where an active voxel's request is
  std::vector<Request>       requests;
  std::vector<std::uint8_t> marked(n, 0);
  std::vector<std::size_t>  moved;   // voxels some active determinant reads
  std::vector<Vec3>         delta;   // ... and their summed requests
  std::vector<std::size_t>  touched; // determinants that read a moved voxel
  std::vector<double>       touchedDeterminant;
  auto collectReaders = [&](const std::vector<std::size_t> & of, std::vector<std::size_t> & into) {
    into.clear();
    for (const std::size_t o : of)
      ForEachReader(field, o, [&](std::size_t t) {
        if (!marked[t])
        {
          marked[t] = 1;
          into.push_back(t);
        }
      });
    for (const std::size_t t : into)
      marked[t] = 0;
  };

  unsigned int rounds{ 0 };
  while (folded > 0 && rounds < options.maximumProjectionRounds)
  {
    ++rounds;
    requests.resize(active.size());
    for (std::size_t a = 0; a < active.size(); ++a)
      activeIndex[active[a]] = static_cast<std::uint32_t>(a);
    pool.ParallelFor(active.size(), [&](std::size_t a) { requests[a] = RequestAt(field, active[a], target); });

    // The stencil relation is symmetric: a voxel is read by the determinants
    // of itself and its face neighbours.
    collectReaders(active, moved);
    delta.resize(moved.size());
    pool.ParallelFor(moved.size(), [&](std::size_t m) {
      const std::size_t p = moved[m];
      Vec3              sum{ { 0.0, 0.0, 0.0 } };
      ForEachReader(field, p, [&](std::size_t t) {
        if (activeIndex[t] == none)
          return;
        const Request & r = requests[activeIndex[t]];
        for (int d = 0; d < 3; ++d)
        {
          const double sign = (r.stencil.hi[d] == p ? 1.0 : 0.0) - (r.stencil.lo[d] == p ? 1.0 : 0.0);
          for (int c = 0; c < 3; ++c)
            sum[c] += sign * r.column[d][c];
        }
      });
      delta[m] = sum;
    });
    pool.ParallelFor(moved.size(), [&](std::size_t m) {
      if (delta[m][0] == 0.0 && delta[m][1] == 0.0 && delta[m][2] == 0.0)
        return; // read only by determinants that ask nothing of it
      for (int c = 0; c < 3; ++c)
        field.data[moved[m]][c] += options.projectionStep * delta[m][c];
      changed[moved[m]] = 1;
    });
    for (const std::size_t o : active)
      activeIndex[o] = none;

    collectReaders(moved, touched);
    touchedDeterminant.resize(touched.size());
    pool.ParallelFor(touched.size(), [&](std::size_t t) { touchedDeterminant[t] = DeterminantAt(field, touched[t]); });
    for (const std::size_t o : active)
      marked[o] = 1;
    for (std::size_t t = 0; t < touched.size(); ++t)
    {
      const std::size_t o = touched[t];
      const double      now = touchedDeterminant[t];
      folded = folded + (now <= 0.0) - (determinant[o] <= 0.0);
      determinant[o] = now;
      if (now < threshold && !marked[o])
      {
        marked[o] = 1;
        active.push_back(o);
      }
    }
    active.erase(std::remove_if(active.begin(), active.end(),
                                [&](std::size_t o) {
                                  marked[o] = 0;
                                  return !(determinant[o] < threshold);
                                }),
                 active.end());
  }
  return rounds;
}

/** The last resort: while some voxel is folded, each voxel within the
 *  current radius of a folded voxel takes the mean displacement of its 3x3x3
 *  neighbourhood (all updates of one round read the previous round's field).
 *  `folded` lists the folded voxels on entry and on return. Returns the rounds. */
unsigned int
SmoothAroundFolds(Volume<Vec3> & field, const FieldFoldRepairOptions & options, std::vector<std::size_t> & folded,
                  std::vector<std::uint8_t> & changed)
{
  const std::size_t         n = field.NumberOfVoxels();
  std::vector<std::uint8_t> marked(n, 0);  // to be smoothed this round
  std::vector<std::uint8_t> touched(n, 0); // determinant may have changed this round
  std::vector<std::size_t>  smoothList;
  std::vector<std::size_t>  touchedList;
  std::vector<Vec3>         smoothed;
  unsigned int              rounds{ 0 };
  while (!folded.empty() && rounds < options.maximumIterations)
  {
    const std::size_t radius = std::min<std::size_t>(
      options.initialRadius + rounds / std::max(1u, options.iterationsPerRadius), options.maximumRadius);
    ++rounds;

    smoothList.clear();
    for (const std::size_t f : folded)
      ForEachInCube(field, IndexOf(field, f), radius, [&](std::size_t o) {
        if (!marked[o])
        {
          marked[o] = 1;
          smoothList.push_back(o);
        }
      });
    smoothed.resize(smoothList.size());
    for (std::size_t s = 0; s < smoothList.size(); ++s)
      smoothed[s] = NeighbourhoodMean(field, IndexOf(field, smoothList[s]));

    touchedList.clear();
    for (std::size_t s = 0; s < smoothList.size(); ++s)
    {
      const std::size_t o = smoothList[s];
      field.data[o] = smoothed[s];
      marked[o] = 0;
      changed[o] = 1;
      ForEachReader(field, o, [&](std::size_t t) {
        if (!touched[t])
        {
          touched[t] = 1;
          touchedList.push_back(t);
        }
      });
    }

    // Folded voxels now: those of the touched region that are folded (every
    // previously folded voxel lies in it, being smoothed itself).
    folded.clear();
    for (const std::size_t t : touchedList)
    {
      touched[t] = 0;
      if (DeterminantAt(field, t) <= 0.0)
        folded.push_back(t);
    }
    std::sort(folded.begin(), folded.end()); // independent of the touched order
  }
  return rounds;
}
} // namespace

double
JacobianDeterminantAt(const Volume<Vec3> & field, std::size_t i, std::size_t j, std::size_t k)
{
  return DeterminantAt(field, field.Offset(i, j, k));
}

std::size_t
CountNonPositiveJacobians(const Volume<Vec3> & field)
{
  CheckField(field);
  std::size_t folded{ 0 };
  for (std::size_t o = 0; o < field.NumberOfVoxels(); ++o)
    folded += DeterminantAt(field, o) <= 0.0;
  return folded;
}

FieldFoldRepairReport
RemoveVoxelFolds(Volume<Vec3> & field, const FieldFoldRepairOptions & options,
                 const std::vector<std::uint8_t> * outsideMesh)
{
  CheckField(field);
  if (!(options.projectionTarget > 0.0) || !(options.projectionStep > 0.0) || !(options.projectionStep <= 1.0))
    throw Error("voxel fold repair: the projection's target must be positive and its step in (0, 1]");
  const std::size_t n = field.NumberOfVoxels();
  if (outsideMesh != nullptr && outsideMesh->size() != n)
    throw Error("voxel fold repair: the outside-the-mesh mask has " + std::to_string(outsideMesh->size()) +
                " entries for " + std::to_string(n) + " voxels");
  auto isOutside = [&](std::size_t o) { return outsideMesh != nullptr && (*outsideMesh)[o] != 0; };

  std::vector<double>      determinant(n);
  std::vector<std::size_t> folded;
  for (std::size_t o = 0; o < n; ++o)
  {
    determinant[o] = DeterminantAt(field, o);
    if (determinant[o] <= 0.0)
      folded.push_back(o);
  }

  FieldFoldRepairReport report;
  report.foldedBefore = folded.size();
  report.foldedBeforeOutsideMesh = static_cast<std::size_t>(std::count_if(folded.begin(), folded.end(), isOutside));
  if (folded.empty())
    return report;

  const std::vector<Vec3>   original = field.data;
  std::vector<std::uint8_t> changed(n, 0);
  report.projectionRounds = ProjectOntoPositiveDeterminants(field, options, folded.size(), determinant, changed);
  folded.clear();
  for (std::size_t o = 0; o < n; ++o)
    if (determinant[o] <= 0.0)
      folded.push_back(o);
  determinant = {};
  report.smoothingRounds = SmoothAroundFolds(field, options, folded, changed);
  report.foldedAfter = folded.size();

  for (std::size_t o = 0; o < n; ++o)
  {
    if (!changed[o])
      continue;
    ++report.voxelsChanged;
    double squared{ 0.0 };
    for (int c = 0; c < 3; ++c)
      squared += (field.data[o][c] - original[o][c]) * (field.data[o][c] - original[o][c]);
    const double distance = std::sqrt(squared);
    report.voxelsChangedOver1mm += distance > 1.0;
    report.maximumChange = std::max(report.maximumChange, distance);
    if (!isOutside(o))
      report.maximumChangeInsideMesh = std::max(report.maximumChangeInsideMesh, distance);
  }
  return report;
}
} // namespace morea_core
