#include "morea/MeshRepair.h"

#include "morea/RepairNoise.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace morea
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

/** The violation of tetrahedra [first, last) (FoldConstraint::Partial's sum,
 *  in its order), or false as soon as the running value exceeds `bound`:
 *  violations are non-negative, so such a trial cannot be Better. */
bool
BoundedViolation(const FoldConstraint & constraint, const std::vector<Vec3> & points, const std::uint32_t * first,
                 const std::uint32_t * last, double bound, FoldViolation & out)
{
  out = FoldViolation{};
  for (const std::uint32_t * t = first; t != last; ++t)
  {
    bool folded = false;
    out.value += constraint.TetrahedronViolation(*t, points, folded);
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

    bool moved = false;
    for (std::uint32_t p : candidates)
    {
      const BoundaryPin & pin = base.pins[p];
      if (pin[0] != 0 && pin[1] != 0 && pin[2] != 0)
        continue; // corners never move
      const std::uint32_t * localBegin = topology.TetrahedraOfPointBegin(p);
      const std::uint32_t * localEnd = topology.TetrahedraOfPointEnd(p);
      FoldViolation         current;
      BoundedViolation(constraint, points, localBegin, localEnd, std::numeric_limits<double>::infinity(), current);
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
        const Vec3 trial{ { original[0] + scale * move[0], original[1] + scale * move[1],
                            original[2] + scale * move[2] } };
        points[p] = ProjectToDomain(trial, pin, base.domain);
        FoldViolation v;
        if (BoundedViolation(constraint, points, localBegin, localEnd, best.value, v) && Better(v, best))
        {
          best = v;
          bestPosition = points[p];
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
} // namespace morea
