// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/FieldFoldRepair.h"

#include "morea_core/Error.h"

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
} // namespace

double
JacobianDeterminantAt(const Volume<Vec3> & field, std::size_t i, std::size_t j, std::size_t k)
{
  const Index3 index{ { i, j, k } };
  const std::size_t stride[3] = { 1, field.size[0], field.size[0] * field.size[1] };
  const std::size_t centre = field.Offset(i, j, k);
  double            jac[3][3]; // jac[c][d] = d(x + u)_c / d x_d
  for (int d = 0; d < 3; ++d)
  {
    const bool        hasLower = index[d] > 0;
    const bool        hasUpper = index[d] + 1 < field.size[d];
    const std::size_t lo = hasLower ? centre - stride[d] : centre;
    const std::size_t hi = hasUpper ? centre + stride[d] : centre;
    const double      steps = static_cast<double>(hasLower) + static_cast<double>(hasUpper);
    for (int c = 0; c < 3; ++c)
    {
      const double g = steps > 0.0 ? (field.data[hi][c] - field.data[lo][c]) / (steps * field.spacing[d]) : 0.0;
      jac[c][d] = g + (c == d ? 1.0 : 0.0);
    }
  }
  return jac[0][0] * (jac[1][1] * jac[2][2] - jac[1][2] * jac[2][1]) -
         jac[0][1] * (jac[1][0] * jac[2][2] - jac[1][2] * jac[2][0]) +
         jac[0][2] * (jac[1][0] * jac[2][1] - jac[1][1] * jac[2][0]);
}

std::size_t
CountNonPositiveJacobians(const Volume<Vec3> & field)
{
  CheckField(field);
  std::size_t folded{ 0 };
  for (std::size_t k = 0; k < field.size[2]; ++k)
    for (std::size_t j = 0; j < field.size[1]; ++j)
      for (std::size_t i = 0; i < field.size[0]; ++i)
        folded += JacobianDeterminantAt(field, i, j, k) <= 0.0;
  return folded;
}

FieldFoldRepairReport
RemoveVoxelFolds(Volume<Vec3> & field, const FieldFoldRepairOptions & options,
                 const std::vector<std::uint8_t> * outsideMesh)
{
  CheckField(field);
  const std::size_t n = field.NumberOfVoxels();
  if (outsideMesh != nullptr && outsideMesh->size() != n)
    throw Error("voxel fold repair: the outside-the-mesh mask has " + std::to_string(outsideMesh->size()) +
                " entries for " + std::to_string(n) + " voxels");
  auto isOutside = [&](std::size_t o) { return outsideMesh != nullptr && (*outsideMesh)[o] != 0; };

  auto isFolded = [&](std::size_t o) {
    const Index3 x = IndexOf(field, o);
    return JacobianDeterminantAt(field, x[0], x[1], x[2]) <= 0.0;
  };

  std::vector<std::size_t> folded;
  for (std::size_t o = 0; o < n; ++o)
    if (isFolded(o))
      folded.push_back(o);

  FieldFoldRepairReport report;
  report.foldedBefore = folded.size();
  report.foldedBeforeOutsideMesh = static_cast<std::size_t>(std::count_if(folded.begin(), folded.end(), isOutside));
  if (folded.empty())
    return report;

  const std::vector<Vec3>   original = field.data;
  std::vector<std::uint8_t> marked(n, 0);  // to be smoothed this round
  std::vector<std::uint8_t> touched(n, 0); // determinant may have changed this round
  std::vector<std::uint8_t> changed(n, 0); // smoothed in some round
  std::vector<std::size_t>  smoothList;
  std::vector<std::size_t>  touchedList;
  std::vector<Vec3>         smoothed;

  while (!folded.empty() && report.iterations < options.maximumIterations)
  {
    const std::size_t radius = std::min<std::size_t>(
      options.initialRadius + report.iterations / std::max(1u, options.iterationsPerRadius), options.maximumRadius);
    ++report.iterations;

    smoothList.clear();
    for (const std::size_t f : folded)
      ForEachInCube(field, IndexOf(field, f), radius, [&](std::size_t o) {
        if (!marked[o])
        {
          marked[o] = 1;
          smoothList.push_back(o);
        }
      });
    // Jacobi update: every mean reads the previous round's field.
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
      // A determinant reads its 6-neighbours, so those may change too.
      ForEachInCube(field, IndexOf(field, o), 1, [&](std::size_t t) {
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
      if (isFolded(t))
        folded.push_back(t);
    }
    std::sort(folded.begin(), folded.end()); // independent of the touched order
  }

  report.foldedAfter = folded.size();
  for (std::size_t o = 0; o < n; ++o)
  {
    if (!changed[o])
      continue;
    ++report.voxelsChanged;
    double squared{ 0.0 };
    for (int c = 0; c < 3; ++c)
      squared += (field.data[o][c] - original[o][c]) * (field.data[o][c] - original[o][c]);
    report.maximumChange = std::max(report.maximumChange, std::sqrt(squared));
    if (!isOutside(o))
      report.maximumChangeInsideMesh = std::max(report.maximumChangeInsideMesh, std::sqrt(squared));
  }
  return report;
}
} // namespace morea_core
