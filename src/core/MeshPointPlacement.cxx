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
} // namespace

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
