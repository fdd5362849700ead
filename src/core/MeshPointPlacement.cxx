// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/MeshPointPlacement.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace morea_core
{
namespace
{
double
SquaredDistance(const Vec3 & a, const Vec3 & b)
{
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

double
SquaredDistanceToSet(const Vec3 & p, const std::vector<Vec3> & set)
{
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3 & q : set)
    best = std::min(best, SquaredDistance(p, q));
  return best;
}

/** One line of the squared distance transform: f holds squared distances (or
 *  infinity) at samples `step` mm apart; on return, the lower envelope of the
 *  parabolas (x - q)^2 + f(q). */
void
SquaredDistanceLine(std::vector<double> & f, double step, std::vector<double> & out, std::vector<std::size_t> & v,
                    std::vector<double> & z)
{
  const std::size_t n = f.size();
  const double      inf = std::numeric_limits<double>::infinity();
  out.assign(n, inf);
  v.assign(n, 0);
  z.assign(n + 1, 0.0);
  std::size_t k = 0;
  bool        any = false;
  for (std::size_t q = 0; q < n; ++q)
  {
    if (!std::isfinite(f[q]))
      continue;
    if (!any)
    {
      any = true;
      v[0] = q;
      z[0] = -inf;
      z[1] = inf;
      continue;
    }
    const double xq = step * static_cast<double>(q);
    double s = 0.0;
    for (;;) // z[0] is -infinity, so k never drops below 0
    {
      const double xv = step * static_cast<double>(v[k]);
      s = ((f[q] + xq * xq) - (f[v[k]] + xv * xv)) / (2.0 * (xq - xv));
      if (s > z[k])
        break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = inf;
  }
  if (!any)
    return;
  k = 0;
  for (std::size_t q = 0; q < n; ++q)
  {
    const double x = step * static_cast<double>(q);
    while (z[k + 1] < x)
      ++k;
    const double d = x - step * static_cast<double>(v[k]);
    out[q] = d * d + f[v[k]];
  }
}
} // namespace

Volume<float>
DistanceToMask(const Volume<std::uint8_t> & mask)
{
  const auto &        n = mask.size;
  const double        inf = std::numeric_limits<double>::infinity();
  std::vector<double> squared(mask.NumberOfVoxels());
  for (std::size_t i = 0; i < squared.size(); ++i)
    squared[i] = mask.data[i] != 0 ? 0.0 : inf;
  std::vector<double>      line, out, z;
  std::vector<std::size_t> v;
  const std::size_t        stride[3] = { 1, n[0], n[0] * n[1] };
  for (int axis = 0; axis < 3; ++axis)
  {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    line.resize(n[axis]);
    for (std::size_t j = 0; j < n[b]; ++j)
      for (std::size_t i = 0; i < n[a]; ++i)
      {
        const std::size_t base = i * stride[a] + j * stride[b];
        for (std::size_t q = 0; q < n[axis]; ++q)
          line[q] = squared[base + q * stride[axis]];
        SquaredDistanceLine(line, mask.spacing[axis], out, v, z);
        for (std::size_t q = 0; q < n[axis]; ++q)
          squared[base + q * stride[axis]] = out[q];
      }
  }
  Volume<float> distance = mask.template Like<float>(0.0f);
  for (std::size_t i = 0; i < squared.size(); ++i)
    distance.data[i] = static_cast<float>(std::sqrt(squared[i]));
  return distance;
}

std::vector<Vec3>
ShellPoints(const Volume<float> & distance, double offset)
{
  const double      half = 0.5 * std::max({ distance.spacing[0], distance.spacing[1], distance.spacing[2] });
  std::vector<Vec3> points;
  const auto &      n = distance.size;
  for (std::size_t k = 0; k < n[2]; ++k)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t i = 0; i < n[0]; ++i)
      {
        const double d = distance(i, j, k);
        if (d > 0.0 && std::abs(d - offset) <= half)
          points.push_back(distance.PointAt(i, j, k));
      }
  return points;
}

std::vector<Vec3>
SpreadOutSubset(const std::vector<Vec3> & candidates, std::size_t count, const std::vector<Vec3> & existing,
                double minimumDistance)
{
  std::vector<Vec3> chosen;
  if (candidates.empty() || count == 0)
    return chosen;

  std::vector<double> nearest(candidates.size(), std::numeric_limits<double>::infinity());
  if (existing.empty())
  {
    Vec3 centroid{ { 0.0, 0.0, 0.0 } };
    for (const Vec3 & c : candidates)
      for (int a = 0; a < 3; ++a)
        centroid[a] += c[a] / static_cast<double>(candidates.size());
    for (std::size_t i = 0; i < candidates.size(); ++i)
      nearest[i] = -SquaredDistance(candidates[i], centroid); // farthest from "minus centroid distance"
  }
  else
  {
    for (std::size_t i = 0; i < candidates.size(); ++i)
      nearest[i] = SquaredDistanceToSet(candidates[i], existing);
  }

  const double minimumSquared = minimumDistance * minimumDistance;
  bool         first = existing.empty();
  while (chosen.size() < count)
  {
    const auto   it = std::max_element(nearest.begin(), nearest.end());
    const double best = *it;
    if (!first && best < minimumSquared)
      break;
    first = false;
    const Vec3 pick = candidates[static_cast<std::size_t>(it - nearest.begin())];
    chosen.push_back(pick);
    for (std::size_t i = 0; i < candidates.size(); ++i)
    {
      const double d = SquaredDistance(candidates[i], pick);
      nearest[i] = (nearest[i] < 0.0) ? d : std::min(nearest[i], d);
    }
  }
  return chosen;
}

std::vector<Vec3>
BestCandidateRandomPoints(std::size_t count, const std::function<Vec3(RandomGenerator &)> & draw,
                          const std::vector<Vec3> & existing, RandomGenerator & random, std::size_t candidatesPerPoint)
{
  std::vector<Vec3> all = existing;
  std::vector<Vec3> drawn;
  for (std::size_t n = 0; n < count; ++n)
  {
    Vec3   best{};
    double bestDistance = -1.0;
    for (std::size_t c = 0; c < std::max<std::size_t>(1, candidatesPerPoint); ++c)
    {
      const Vec3   p = draw(random);
      const double d = SquaredDistanceToSet(p, all);
      if (d > bestDistance)
      {
        bestDistance = d;
        best = p;
      }
    }
    all.push_back(best);
    drawn.push_back(best);
  }
  return drawn;
}

std::vector<Vec3>
MaskBoundaryPoints(const Volume<std::uint8_t> & mask)
{
  std::vector<Vec3> points;
  const auto &      n = mask.size;
  for (std::size_t k = 0; k < n[2]; ++k)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t i = 0; i < n[0]; ++i)
      {
        if (mask(i, j, k) == 0)
          continue;
        const bool border = i == 0 || j == 0 || k == 0 || i + 1 == n[0] || j + 1 == n[1] || k + 1 == n[2];
        if (border || mask(i - 1, j, k) == 0 || mask(i + 1, j, k) == 0 || mask(i, j - 1, k) == 0 ||
            mask(i, j + 1, k) == 0 || mask(i, j, k - 1) == 0 || mask(i, j, k + 1) == 0)
          points.push_back(mask.PointAt(i, j, k));
      }
  return points;
}

std::vector<Vec3>
DomainCorners(const MeshDomain & domain)
{
  std::vector<Vec3> corners;
  for (int c = 0; c < 8; ++c)
  {
    corners.push_back({ (c & 1) ? domain.upper[0] : domain.lower[0], (c & 2) ? domain.upper[1] : domain.lower[1],
                        (c & 4) ? domain.upper[2] : domain.lower[2] });
  }
  return corners;
}
} // namespace morea_core
