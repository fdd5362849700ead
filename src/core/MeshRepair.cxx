// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/MeshRepair.h"

#include "morea_core/RepairNoise.h"
#include "morea_core/RepairStar.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace morea_core
{
namespace
{
/** Mean distance of `point` to the planes of the faces opposite it in its tetrahedra. */
double
DistanceToSurroundingPolyhedron(std::uint32_t point, const std::vector<Vec3> & points, const MeshTopology & topology)
{
  double      sum = 0.0;
  std::size_t n = 0;
  const Vec3 & p = points[point];
  for (const std::uint32_t * t = topology.TetrahedraOfPointBegin(point); t != topology.TetrahedraOfPointEnd(point); ++t)
  {
    const Tetrahedron & tet = topology.Tetrahedra()[*t];
    Vec3                f[3];
    int                 m = 0;
    for (std::uint32_t v : tet)
      if (v != point)
        f[m++] = points[v];
    const Vec3   u{ { f[1][0] - f[0][0], f[1][1] - f[0][1], f[1][2] - f[0][2] } };
    const Vec3   w{ { f[2][0] - f[0][0], f[2][1] - f[0][1], f[2][2] - f[0][2] } };
    const Vec3   normal{ { u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0] } };
    const double area2 = std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
    if (area2 == 0.0)
      continue;
    sum += std::abs(normal[0] * (p[0] - f[0][0]) + normal[1] * (p[1] - f[0][1]) + normal[2] * (p[2] - f[0][2])) / area2;
    ++n;
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}

bool
Better(const FoldViolation & a, const FoldViolation & b)
{
  return a.value < b.value || (a.value <= b.value && a.folded < b.folded);
}

/** The star of point p (RepairStar.h): its tetrahedra in ascending order. */
void
GatherStar(std::uint32_t p, const std::vector<Vec3> & points, const FoldConstraint & constraint,
           std::vector<StarTerm> & star)
{
  const MeshTopology & topology = constraint.Topology();
  star.clear();
  for (const std::uint32_t * t = topology.TetrahedraOfPointBegin(p); t != topology.TetrahedraOfPointEnd(p); ++t)
  {
    const Tetrahedron & tet = topology.Tetrahedra()[*t];
    const double *      other[3];
    int                 m = 0, slot = 0;
    for (int j = 0; j < 4; ++j)
      if (tet[j] == p)
        slot = j;
      else if (m < 3)
        other[m++] = points[tet[j]].data();
    star.emplace_back();
    MakeStarTerm(other, slot, constraint.ReferenceVolumes()[*t], constraint.VolumeFraction(), star.back());
  }
}

/** The star's violation with the point at x (sixfold units), or false as
 *  soon as the running value exceeds `bound`: the terms are non-negative, so
 *  such a trial cannot be Better. */
bool
BoundedViolation(const std::vector<StarTerm> & star, const double * x, double bound, FoldViolation & out)
{
  out = FoldViolation{};
  for (const StarTerm & term : star)
  {
    bool folded = false;
    out.value += StarTermViolation(term, x, folded);
    out.folded += folded;
    if (out.value > bound)
      return false;
  }
  return true;
}
} // namespace

RepairResult
RepairFolds(std::vector<Vec3> & points, const TetrahedralMesh & base, const FoldConstraint & constraint,
            RandomGenerator & random, const RepairOptions & options)
{
  return RepairPoints(points, nullptr, nullptr, base, constraint, random.NextU64(), options);
}

RepairResult
RepairPoints(std::vector<Vec3> & points, const std::vector<std::uint32_t> * movable,
             const std::vector<std::uint32_t> * scope, const TetrahedralMesh & base, const FoldConstraint & constraint,
             std::uint64_t seed, const RepairOptions & options)
{
  const MeshTopology & topology = constraint.Topology();
  auto evaluate = [&] { return scope ? constraint.Partial(points, *scope) : constraint.Evaluate(points); };
  auto foldedTetrahedra = [&] {
    if (!scope)
      return constraint.FoldedTetrahedra(points);
    std::vector<std::uint32_t> folded;
    for (std::uint32_t t : *scope)
    {
      bool f = false;
      constraint.TetrahedronViolation(t, points, f);
      if (f)
        folded.push_back(t);
    }
    return folded;
  };
  RepairResult result;
  result.before = evaluate();
  result.after = result.before;
  for (std::size_t round = 0; round < options.maxRounds && !result.after.Feasible(); ++round)
  {
    std::vector<std::uint32_t> candidates;
    for (std::uint32_t t : foldedTetrahedra())
      for (std::uint32_t v : topology.Tetrahedra()[t])
        candidates.push_back(v);
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    if (movable)
      candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                      [&](std::uint32_t p) {
                                        return std::find(movable->begin(), movable->end(), p) == movable->end();
                                      }),
                       candidates.end());

    bool                  moved = false;
    std::vector<StarTerm> star;
    for (std::uint32_t p : candidates)
    {
      const BoundaryPin & pin = base.pins[p];
      if (pin[0] != 0 && pin[1] != 0 && pin[2] != 0)
        continue; // corners never move
      GatherStar(p, points, constraint, star);
      FoldViolation current;
      BoundedViolation(star, points[p].data(), std::numeric_limits<double>::infinity(), current);
      if (current.Feasible())
        continue; // fixed by an earlier move in this pass
      const double scale = DistanceToSurroundingPolyhedron(p, points, topology);
      if (!(scale > 0.0))
        continue;
      const Vec3    original = points[p];
      Vec3          bestPosition = original;
      FoldViolation best = current;
      for (std::size_t s = 0; s < options.samplesPerPoint; ++s)
      {
        double move[3];
        RepairTrialNormals(seed, static_cast<std::uint32_t>(round), p, static_cast<std::uint32_t>(s), move);
        const Vec3 trial = ProjectToDomain(Vec3{ { original[0] + scale * move[0], original[1] + scale * move[1],
                                                   original[2] + scale * move[2] } },
                                           pin, base.domain);
        FoldViolation v;
        if (BoundedViolation(star, trial.data(), best.value, v) && Better(v, best))
        {
          best = v;
          bestPosition = trial;
        }
      }
      points[p] = bestPosition;
      if (bestPosition != original)
      {
        moved = true;
        ++result.movedPoints;
      }
    }
    result.after = evaluate();
    if (!moved)
      break;
  }
  return result;
}

RepairResult
RepairFolds(DualMesh & solution, const TetrahedralMesh & base, const FoldConstraint & constraint,
            RandomGenerator & random, const RepairOptions & options)
{
  RepairResult source = RepairFolds(solution.source, base, constraint, random, options);
  RepairResult target = RepairFolds(solution.target, base, constraint, random, options);
  source.before += target.before;
  source.after += target.after;
  source.movedPoints += target.movedPoints;
  return source;
}
} // namespace morea_core
