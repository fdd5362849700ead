#include "morea/ParetoFront.h"

#include "morea/Error.h"
#include "morea/ThreadPool.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <numeric>

namespace morea
{
namespace
{
constexpr std::size_t M = NumberOfObjectives;

void
RequireNonEmpty(const std::vector<ObjectiveVector> & front, const char * what)
{
  if (front.empty())
    throw Error(std::string(what) + ": the front is empty");
}

/** The front mapped to [0,1] per objective by its own range (zero range -> 0).
 *  Keeps the minima and ranges so outside points can be mapped the same way. */
struct Normalisation
{
  ObjectiveVector lower{};
  ObjectiveVector range{};

  explicit Normalisation(const std::vector<ObjectiveVector> & front)
  {
    ObjectiveVector upper{};
    lower = upper = front.front();
    for (const ObjectiveVector & v : front)
      for (std::size_t j = 0; j < M; ++j)
      {
        lower[j] = std::min(lower[j], v[j]);
        upper[j] = std::max(upper[j], v[j]);
      }
    for (std::size_t j = 0; j < M; ++j)
      range[j] = upper[j] - lower[j];
  }

  ObjectiveVector
  operator()(const ObjectiveVector & v) const
  {
    ObjectiveVector n{};
    for (std::size_t j = 0; j < M; ++j)
      n[j] = range[j] > 0.0 ? (v[j] - lower[j]) / range[j] : 0.0;
    return n;
  }
};

std::vector<ObjectiveVector>
Normalised(const std::vector<ObjectiveVector> & front)
{
  const Normalisation normalise(front);
  std::vector<ObjectiveVector> n;
  n.reserve(front.size());
  for (const ObjectiveVector & v : front)
    n.push_back(normalise(v));
  return n;
}

double
Sum(const ObjectiveVector & v)
{
  return std::accumulate(v.begin(), v.end(), 0.0);
}

double
SquaredDistance(const ObjectiveVector & a, const ObjectiveVector & b)
{
  double d = 0.0;
  for (std::size_t j = 0; j < M; ++j)
    d += (a[j] - b[j]) * (a[j] - b[j]);
  return d;
}

/** Index of the smallest score; the first one on ties. */
template <typename Score>
std::size_t
ArgMin(std::size_t n, Score score)
{
  std::size_t best = 0;
  double      bestScore = score(0);
  for (std::size_t i = 1; i < n; ++i)
  {
    const double s = score(i);
    if (s < bestScore)
    {
      best = i;
      bestScore = s;
    }
  }
  return best;
}

/** The 2D region dominated by a set of points within a reference corner, kept
 *  as a staircase (x ascending, y strictly descending) with its area, so one
 *  insertion costs O(log n + removed points). */
class Staircase2D
{
public:
  Staircase2D(double referenceX, double referenceY)
    : m_ReferenceX(referenceX)
    , m_ReferenceY(referenceY)
  {}

  void
  Insert(double x, double y)
  {
    auto next = m_Steps.lower_bound(x); // first step with step.x >= x
    // Dominated by the step to the left (or one at the same x): nothing new.
    if (next != m_Steps.begin() && std::prev(next)->second <= y)
      return;
    if (next != m_Steps.end() && next->first == x && next->second <= y)
      return;
    // Walk right adding the strip between y and the staircase's current level,
    // and drop the steps the new point dominates (those with step.y >= y).
    double level = next == m_Steps.begin() ? m_ReferenceY : std::prev(next)->second;
    double left = x;
    while (next != m_Steps.end() && next->second >= y)
    {
      m_Area += (next->first - left) * (level - y);
      left = next->first;
      level = next->second;
      next = m_Steps.erase(next);
    }
    const double right = next == m_Steps.end() ? m_ReferenceX : next->first;
    m_Area += (right - left) * (level - y);
    m_Steps.emplace(x, y);
  }

  double
  Area() const
  {
    return m_Area;
  }

private:
  double                   m_ReferenceX;
  double                   m_ReferenceY;
  std::map<double, double> m_Steps;
  double                   m_Area{ 0.0 };
};
} // namespace

bool
ConstraintDominates(const Fitness & a, const Fitness & b)
{
  if (a.feasible != b.feasible)
    return a.feasible;
  if (!a.feasible)
    return a.constraint < b.constraint;
  return Dominates(a.objectives, b.objectives);
}

namespace
{
/** ConstraintDominates both ways in one pass: 1 where a dominates b, -1
 *  where b dominates a, 0 where neither does. */
int
ConstraintOrder(const Fitness & a, const Fitness & b)
{
  if (a.feasible != b.feasible)
    return a.feasible ? 1 : -1;
  if (!a.feasible)
    return a.constraint < b.constraint ? 1 : (b.constraint < a.constraint ? -1 : 0);
  bool worse = false, better = false;
  for (std::size_t j = 0; j < a.objectives.size(); ++j)
  {
    worse |= a.objectives[j] > b.objectives[j];
    better |= a.objectives[j] < b.objectives[j];
  }
  if (better != worse)
    return better ? 1 : -1;
  return 0;
}
} // namespace

std::vector<std::size_t>
NonDominatedRanks(const std::vector<Fitness> & population, ThreadPool * pool)
{
  // Deb's fast non-dominated sort: count who dominates each solution, then peel
  // fronts off by releasing the solutions each front dominates. Each solution
  // is compared with all others on its own (each pair twice, in one pass
  // for both directions, but rows side by side on the pool: a paper-scale
  // population's sort took about 4 ms of every generation on one thread).
  const std::size_t                       n = population.size();
  std::vector<std::vector<std::uint32_t>> dominatedBy(n); // i -> solutions i dominates
  std::vector<std::size_t>                dominatorCount(n, 0);
  const auto                              row = [&](std::size_t i) {
    for (std::size_t k = 0; k < n; ++k)
    {
      if (k == i)
        continue;
      const int order = ConstraintOrder(population[i], population[k]);
      if (order > 0)
        dominatedBy[i].push_back(static_cast<std::uint32_t>(k));
      else if (order < 0)
        ++dominatorCount[i];
    }
  };
  if (pool)
    pool->ParallelFor(n, row);
  else
    for (std::size_t i = 0; i < n; ++i)
      row(i);

  std::vector<std::size_t> ranks(n, 0);
  std::vector<std::size_t> front;
  for (std::size_t i = 0; i < n; ++i)
    if (dominatorCount[i] == 0)
      front.push_back(i);
  for (std::size_t rank = 0; !front.empty(); ++rank)
  {
    std::vector<std::size_t> nextFront;
    for (std::size_t i : front)
    {
      ranks[i] = rank;
      for (std::uint32_t k : dominatedBy[i])
        if (--dominatorCount[k] == 0)
          nextFront.push_back(k);
    }
    front.swap(nextFront);
  }
  return ranks;
}

double
BoundedHypervolume(const std::vector<ObjectiveVector> & points, const ObjectiveVector & scales)
{
  for (double s : scales)
    if (!(s > 0.0) || !std::isfinite(s))
      throw Error("hypervolume: the scales must be positive and finite");
  std::vector<ObjectiveVector> mapped;
  mapped.reserve(points.size());
  for (const ObjectiveVector & p : points)
  {
    ObjectiveVector q;
    for (std::size_t m = 0; m < q.size(); ++m)
    {
      const double f = std::max(0.0, p[m]);
      q[m] = std::isfinite(f) ? f / (f + scales[m]) : 1.0;
    }
    mapped.push_back(q);
  }
  return Hypervolume(mapped, { { 1.0, 1.0, 1.0 } });
}

double
Hypervolume(const std::vector<ObjectiveVector> & points, const ObjectiveVector & reference)
{
  // Sweep along the third objective: between consecutive z values the
  // dominated cross-section is the 2D staircase of the points seen so far.
  std::vector<ObjectiveVector> inside;
  inside.reserve(points.size());
  for (const ObjectiveVector & p : points)
    if (p[0] < reference[0] && p[1] < reference[1] && p[2] < reference[2])
      inside.push_back(p);
  std::sort(inside.begin(), inside.end(),
            [](const ObjectiveVector & a, const ObjectiveVector & b) { return a[2] < b[2]; });

  Staircase2D section(reference[0], reference[1]);
  double      volume = 0.0;
  for (std::size_t i = 0; i < inside.size(); ++i)
  {
    section.Insert(inside[i][0], inside[i][1]);
    const double nextZ = i + 1 < inside.size() ? inside[i + 1][2] : reference[2];
    volume += section.Area() * (nextZ - inside[i][2]);
  }
  return volume;
}

std::size_t
SelectBestGuidance(const std::vector<ObjectiveVector> & front)
{
  RequireNonEmpty(front, "best-guidance selection");
  const auto        normalised = Normalised(front);
  const std::size_t g = static_cast<std::size_t>(Objective::Guidance);
  std::size_t       best = 0;
  for (std::size_t i = 1; i < front.size(); ++i)
    if (front[i][g] < front[best][g] || (front[i][g] == front[best][g] && Sum(normalised[i]) < Sum(normalised[best])))
      best = i;
  return best;
}

std::size_t
SelectKnee(const std::vector<ObjectiveVector> & front)
{
  RequireNonEmpty(front, "knee selection");
  const auto normalised = Normalised(front);
  // The ideal point is the origin of the normalised objectives.
  const auto nearestIdeal = [&] {
    return ArgMin(front.size(), [&](std::size_t i) { return SquaredDistance(normalised[i], ObjectiveVector{}); });
  };

  // The extreme solution of objective j is the one nearest that objective's
  // axis: smallest worst value in the other objectives, then smallest in j
  // (NSGA-III's achievement scalarising with weight e_j). Unlike "best in j",
  // this stays distinct per objective when one solution is best in two. An
  // objective without range has no extreme: the front is flat in it.
  std::array<std::size_t, M> extremes{};
  for (std::size_t j = 0; j < M; ++j)
  {
    if (std::all_of(normalised.begin(), normalised.end(), [j](const ObjectiveVector & n) { return n[j] == 0.0; }))
      return nearestIdeal();
    const auto offAxis = [j](const ObjectiveVector & n) {
      double worst = 0.0;
      for (std::size_t k = 0; k < M; ++k)
        if (k != j)
          worst = std::max(worst, n[k]);
      return worst;
    };
    for (std::size_t i = 1; i < front.size(); ++i)
    {
      const ObjectiveVector & holder = normalised[extremes[j]];
      const ObjectiveVector & challenger = normalised[i];
      if (offAxis(challenger) < offAxis(holder) || (offAxis(challenger) == offAxis(holder) && challenger[j] < holder[j]))
        extremes[j] = i;
    }
  }
  const ObjectiveVector & a = normalised[extremes[0]];
  const ObjectiveVector & b = normalised[extremes[1]];
  const ObjectiveVector & c = normalised[extremes[2]];
  if (a == b || b == c || a == c)
    return nearestIdeal();

  // Unit plane normal, oriented towards the worse side (along (1,1,1)) so that
  // "below" means towards the ideal point. Collinear extremes (no plane) or a
  // plane containing the (1,1,1) direction (no below) fall back as above.
  const ObjectiveVector u{ { b[0] - a[0], b[1] - a[1], b[2] - a[2] } };
  const ObjectiveVector v{ { c[0] - a[0], c[1] - a[1], c[2] - a[2] } };
  ObjectiveVector normal{ { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] } };
  const double    length = std::sqrt(SquaredDistance(normal, ObjectiveVector{}));
  if (!(length > 1e-12) || !(std::abs(Sum(normal)) > 1e-12 * length))
    return nearestIdeal();
  const double orientation = Sum(normal) < 0.0 ? -1.0 : 1.0;
  for (double & n : normal)
    n *= orientation / length;

  return ArgMin(front.size(), [&](std::size_t i) {
    const ObjectiveVector & p = normalised[i];
    // Signed height above the plane; the knee has the most negative one.
    return normal[0] * (p[0] - a[0]) + normal[1] * (p[1] - a[1]) + normal[2] * (p[2] - a[2]);
  });
}

std::size_t
SelectWeighted(const std::vector<ObjectiveVector> & front, const ObjectiveVector & weights)
{
  RequireNonEmpty(front, "weighted selection");
  for (double w : weights)
    if (!(w >= 0.0) || !std::isfinite(w))
      throw Error("weighted selection: weights must be finite and >= 0");
  if (Sum(weights) <= 0.0)
    throw Error("weighted selection: at least one weight must be > 0");
  const auto normalised = Normalised(front);
  return ArgMin(front.size(), [&](std::size_t i) {
    double s = 0.0;
    for (std::size_t j = 0; j < M; ++j)
      s += weights[j] * normalised[i][j];
    return s;
  });
}

std::size_t
SelectNearest(const std::vector<ObjectiveVector> & front, const ObjectiveVector & point)
{
  RequireNonEmpty(front, "nearest selection");
  const Normalisation   normalise(front);
  const ObjectiveVector target = normalise(point);
  return ArgMin(front.size(), [&](std::size_t i) { return SquaredDistance(normalise(front[i]), target); });
}
} // namespace morea
