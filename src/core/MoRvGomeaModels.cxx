// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MO-RV-GOMEA's models: selection, clustering in objective space and the
// per-cluster, per-element normal distributions candidates are drawn from,
// with their adaptive multipliers.
#include "MoRvGomeaParts.h"

#include "morea_core/Error.h"
#include "morea_core/ThreadPool.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace morea_core
{
namespace
{
// Settings of AMaLGaM / RV-GOMEA that MO-RV-GOMEA inherits.
constexpr double      MultiplierDecrease = 0.9;
constexpr double      MultiplierIncrease = 1.0 / 0.9;
constexpr double      MultiplierMaximum = 10.0;
constexpr double      StandardDeviationRatioThreshold = 1.0;
constexpr double      AmsDelta = 2.0;
constexpr std::size_t KMeansIterations = 3;

// Random streams derived from a candidate's seed (the repair uses 0 and 1: the side).
constexpr std::uint64_t SamplingStream = 2;

double
Normalised(double v, double low, double high)
{
  return high > low ? (v - low) / (high - low) : 0.0;
}

/** Per-objective range of a set of solutions, mapping objectives to [0, 1]. */
struct ObjectiveRange
{
  ObjectiveVector low, high;

  ObjectiveRange(const std::vector<std::size_t> & members, const std::vector<Fitness> & fitness)
  {
    low.fill(std::numeric_limits<double>::infinity());
    high.fill(-std::numeric_limits<double>::infinity());
    for (std::size_t s : members)
      for (std::size_t m = 0; m < NumberOfObjectives; ++m)
      {
        low[m] = std::min(low[m], fitness[s].objectives[m]);
        high[m] = std::max(high[m], fitness[s].objectives[m]);
      }
  }
  ObjectiveVector
  Normalise(const Fitness & f) const
  {
    ObjectiveVector v;
    for (std::size_t m = 0; m < NumberOfObjectives; ++m)
      v[m] = Normalised(f.objectives[m], low[m], high[m]);
    return v;
  }
};

/** Lower Cholesky factor of the n x n matrix `a` (row-major), regularised
 *  on the diagonal until it exists (pinned coordinates have zero variance). */
std::vector<double>
RegularisedCholesky(std::vector<double> a, std::size_t n)
{
  double scale = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    scale = std::max(scale, a[i * n + i]);
  double jitter = std::max(scale, 1e-12) * 1e-10;
  for (int attempt = 0; attempt < 40; ++attempt)
  {
    std::vector<double> l(n * n, 0.0);
    bool                ok = true;
    for (std::size_t i = 0; i < n && ok; ++i)
      for (std::size_t j = 0; j <= i; ++j)
      {
        double s = a[i * n + j] + (i == j ? jitter : 0.0);
        for (std::size_t k = 0; k < j; ++k)
          s -= l[i * n + k] * l[j * n + k];
        if (i == j)
        {
          if (!(s > 0.0))
          {
            ok = false;
            break;
          }
          l[i * n + i] = std::sqrt(s);
        }
        else
          l[i * n + j] = s / l[j * n + j];
      }
    if (ok)
      return l;
    jitter *= 10.0;
  }
  throw Error("optimiser: a distribution's covariance has no Cholesky factor");
}

void
Gather(const DualMesh & solution, const FosElement & element, double * x)
{
  for (std::size_t k = 0; k < element.points.size(); ++k)
    for (int a = 0; a < 3; ++a)
    {
      x[6 * k + a] = solution.source[element.points[k]][a];
      x[6 * k + 3 + a] = solution.target[element.points[k]][a];
    }
}
} // namespace

std::vector<std::size_t>
MoRvGomea::Select(const std::vector<Fitness> & fitness, RandomGenerator & random) const
{
  const std::size_t n = fitness.size();
  const std::size_t wanted = std::min(
    n, std::max<std::size_t>(m_Options.numberOfClusters,
                             static_cast<std::size_t>(std::ceil(m_Options.selectionFraction * static_cast<double>(n)))));
  const std::vector<std::size_t> ranks = NonDominatedRanks(fitness);
  std::vector<std::size_t>       order(n);
  std::iota(order.begin(), order.end(), std::size_t{ 0 });
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return ranks[a] < ranks[b]; });
  std::vector<std::size_t> selection;
  std::size_t              i = 0;
  while (i < n && selection.size() + std::count(ranks.begin(), ranks.end(), ranks[order[i]]) <= wanted)
  {
    const std::size_t rank = ranks[order[i]];
    while (i < n && ranks[order[i]] == rank)
      selection.push_back(order[i++]);
  }
  if (selection.size() < wanted && i < n)
  {
    // The front that does not fit: a spread-out subset in normalised objective
    // space, greedily farthest from what is already selected.
    std::vector<std::size_t> front;
    for (std::size_t j = i; j < n && ranks[order[j]] == ranks[order[i]]; ++j)
      front.push_back(order[j]);
    // Normalised once: late in a run most of the population can be in this
    // front, and the loop below visits it once per solution it selects.
    const ObjectiveRange         range(front, fitness);
    std::vector<ObjectiveVector> points(front.size());
    for (std::size_t j = 0; j < front.size(); ++j)
      points[j] = range.Normalise(fitness[front[j]]);
    std::vector<double> nearest(front.size(), std::numeric_limits<double>::infinity());
    std::vector<bool>   taken(front.size(), false);
    std::size_t         pick = static_cast<std::size_t>(random.Uniform() * static_cast<double>(front.size()));
    while (selection.size() < wanted)
    {
      taken[pick] = true;
      selection.push_back(front[pick]);
      const ObjectiveVector p = points[pick];
      double                far = -1.0;
      for (std::size_t j = 0; j < front.size(); ++j)
        if (!taken[j])
        {
          nearest[j] = std::min(nearest[j], SquaredDistance(p, points[j]));
          if (nearest[j] > far)
          {
            far = nearest[j];
            pick = j;
          }
        }
      if (far < 0.0)
        break;
    }
  }
  return selection;
}

std::vector<MoRvGomea::ClusterModel>
MoRvGomea::BuildClusters(const std::vector<std::size_t> & selection, const std::vector<Fitness> & fitness,
                         RandomGenerator & random)
{
  // Normalised objective space of the selection.
  const ObjectiveRange range(selection, fitness);
  const ObjectiveVector & low = range.low;
  const ObjectiveVector & high = range.high;
  auto norm = [&](std::size_t s) { return range.Normalise(fitness[s]); };
  std::vector<ObjectiveVector> points;
  for (std::size_t s : selection)
    points.push_back(norm(s));

  const std::size_t k = std::min(m_Options.numberOfClusters, selection.size());
  const std::size_t clusterSize =
    std::min(selection.size(), std::max<std::size_t>(2, (2 * selection.size() + k - 1) / k));

  // k-leader-means: spread-out leaders, then a few k-means steps.
  std::vector<ObjectiveVector> means;
  std::vector<double>          nearest(points.size(), std::numeric_limits<double>::infinity());
  std::size_t leader = static_cast<std::size_t>(random.Uniform() * static_cast<double>(points.size()));
  while (means.size() < k)
  {
    means.push_back(points[leader]);
    double far = -1.0;
    for (std::size_t j = 0; j < points.size(); ++j)
    {
      nearest[j] = std::min(nearest[j], SquaredDistance(points[j], means.back()));
      if (nearest[j] > far)
      {
        far = nearest[j];
        leader = j;
      }
    }
  }
  for (std::size_t iteration = 0; iteration < KMeansIterations; ++iteration)
  {
    std::vector<ObjectiveVector> sums(k, ObjectiveVector{ { 0.0, 0.0, 0.0 } });
    std::vector<std::size_t>     counts(k, 0);
    for (const auto & p : points)
    {
      std::size_t best = 0;
      for (std::size_t c = 1; c < k; ++c)
        if (SquaredDistance(p, means[c]) < SquaredDistance(p, means[best]))
          best = c;
      for (std::size_t m = 0; m < NumberOfObjectives; ++m)
        sums[best][m] += p[m];
      ++counts[best];
    }
    for (std::size_t c = 0; c < k; ++c)
      if (counts[c])
        for (std::size_t m = 0; m < NumberOfObjectives; ++m)
          means[c][m] = sums[c][m] / static_cast<double>(counts[c]);
  }

  std::vector<ClusterModel> clusters(k + NumberOfObjectives);
  std::vector<std::size_t>  order(points.size());
  std::vector<double>       distance(points.size());
  for (std::size_t c = 0; c < k; ++c)
  {
    // The clusterSize selected solutions nearest the mean (clusters overlap).
    for (std::size_t j = 0; j < points.size(); ++j)
      distance[j] = SquaredDistance(points[j], means[c]);
    std::iota(order.begin(), order.end(), std::size_t{ 0 });
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return distance[a] < distance[b]; });
    clusters[c].mean = means[c];
    for (std::size_t j = 0; j < clusterSize; ++j)
      clusters[c].members.push_back(selection[order[j]]);
  }
  // Single-objective clusters: the best of the selection in one objective, to
  // push the extremes of the front outwards. Objectives without spread (e.g.
  // guidance when disabled) get none.
  for (std::size_t m = 0; m < NumberOfObjectives; ++m)
  {
    ClusterModel & cluster = clusters[k + m];
    cluster.singleObjective = static_cast<int>(m);
    if (!(high[m] > low[m]))
      continue;
    std::iota(order.begin(), order.end(), std::size_t{ 0 });
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      const Fitness & fa = fitness[selection[a]];
      const Fitness & fb = fitness[selection[b]];
      if (fa.feasible != fb.feasible)
        return fa.feasible;
      return fa.objectives[m] < fb.objectives[m];
    });
    const std::size_t size = std::min(clusterSize, std::max<std::size_t>(2, selection.size() / k));
    ObjectiveVector   mean{ { 0.0, 0.0, 0.0 } };
    for (std::size_t j = 0; j < size; ++j)
    {
      cluster.members.push_back(selection[order[j]]);
      for (std::size_t q = 0; q < NumberOfObjectives; ++q)
        mean[q] += points[order[j]][q] / static_cast<double>(size);
    }
    cluster.mean = mean;
  }

  // Carry the adaptive state over: regular clusters from the nearest previous
  // regular cluster, single-objective ones from their predecessor.
  const std::size_t previousRegular =
    m_ClusterMeans.size() >= NumberOfObjectives ? m_ClusterMeans.size() - NumberOfObjectives : 0;
  constexpr std::size_t    none = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> source(clusters.size(), none);
  for (std::size_t c = 0; c < clusters.size() && !m_Distributions.empty(); ++c)
  {
    std::size_t from = c;
    if (c < k)
    {
      if (previousRegular == 0)
        continue;
      from = 0;
      for (std::size_t p = 1; p < previousRegular; ++p)
        if (SquaredDistance(clusters[c].mean, m_ClusterMeans[p]) < SquaredDistance(clusters[c].mean, m_ClusterMeans[from]))
          from = p;
    }
    else
      from = previousRegular + (c - k);
    if (from < m_Distributions.size())
      source[c] = from;
  }
  // Each previous state moves to the last cluster that takes it and is
  // copied to the others (thousands of vectors a generation).
  std::vector<std::vector<DistributionState>> states(clusters.size());
  for (std::size_t c = 0; c < clusters.size(); ++c)
    if (source[c] == none)
      states[c].resize(m_Parallel.elements.size());
    else if (std::find(source.begin() + c + 1, source.end(), source[c]) == source.end())
      states[c] = std::move(m_Distributions[source[c]]);
    else
      states[c] = m_Distributions[source[c]];
  m_Distributions = std::move(states);
  m_ClusterMeans.clear();
  for (const auto & c : clusters)
    m_ClusterMeans.push_back(c.mean);

  // Every solution is varied with the model of the cluster whose mean is
  // nearest to it.
  for (std::size_t s = 0; s < m_Population.size(); ++s)
  {
    const ObjectiveVector p = norm(s);
    std::size_t           best = clusters.size();
    for (std::size_t c = 0; c < clusters.size(); ++c)
      if (!clusters[c].members.empty() &&
          (best == clusters.size() || SquaredDistance(p, clusters[c].mean) < SquaredDistance(p, clusters[best].mean)))
        best = c;
    clusters[best].population.push_back(s);
  }
  return clusters;
}

void
MoRvGomea::EstimateDistributions(std::vector<ClusterModel> & clusters, const std::vector<std::uint32_t> & elements,
                                 ThreadPool & pool) const
{
  // Every (cluster, element) pair is independent: estimate them in parallel.
  std::vector<std::pair<std::size_t, std::size_t>> work;
  for (std::size_t c = 0; c < clusters.size(); ++c)
  {
    ClusterModel & cluster = clusters[c];
    if (cluster.members.empty() || cluster.population.empty())
      continue;
    if (cluster.means.size() != m_Parallel.elements.size()) // the first call sizes them
    {
      cluster.means.resize(m_Parallel.elements.size());
      cluster.cholesky.resize(m_Parallel.elements.size());
    }
    for (std::uint32_t e : elements)
      work.emplace_back(c, e);
  }
  pool.ParallelFor(work.size(), [&](std::size_t w) {
    ClusterModel &      cluster = clusters[work[w].first];
    const std::size_t   e = work[w].second;
    const double        count = static_cast<double>(cluster.members.size());
    const FosElement &  element = m_Parallel.elements[e];
    const std::size_t   n = 6 * element.points.size();
    std::vector<double> mean(n, 0.0), covariance(n * n, 0.0);
    std::vector<double> all(n * cluster.members.size());
    for (std::size_t j = 0; j < cluster.members.size(); ++j)
    {
      Gather(m_Population[cluster.members[j]], element, all.data() + j * n);
      for (std::size_t i = 0; i < n; ++i)
        mean[i] += all[j * n + i] / count;
    }
    for (std::size_t j = 0; j < cluster.members.size(); ++j)
    {
      const double * v = all.data() + j * n;
      for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = 0; b <= a; ++b)
          covariance[a * n + b] += (v[a] - mean[a]) * (v[b] - mean[b]) / count;
    }
    // Few members for many variables give a singular estimate that only
    // samples the members' span: shrink the off-diagonal part towards 0 by
    // the ratio of variables to members (the full estimate for large clusters).
    const double shrink = std::min(1.0, static_cast<double>(n) / count);
    for (std::size_t a = 0; a < n; ++a)
      for (std::size_t b = 0; b < a; ++b)
        covariance[b * n + a] = covariance[a * n + b] *= (1.0 - shrink);
    cluster.means[e] = std::move(mean);
    cluster.cholesky[e] = RegularisedCholesky(std::move(covariance), n);
  });
}

void
MoRvGomea::SampleCandidates(CandidateBatch & batch, const std::vector<ClusterModel> & clusters,
                            ThreadPool & pool) const
{
  batch.Layout(m_Parallel);
  pool.ParallelFor(batch.candidates.size(), [&](std::size_t i) {
    Candidate &                 cand = batch.candidates[i];
    const ClusterModel &        cluster = clusters[cand.cluster];
    const FosElement &          element = m_Parallel.elements[cand.element];
    const std::size_t           dim = 6 * element.points.size();
    const std::vector<double> & mean = cluster.means[cand.element];
    const std::vector<double> & l = cluster.cholesky[cand.element];
    const DistributionState &   state = m_Distributions[cand.cluster][cand.element];
    RandomGenerator             random(HashCombine(cand.seed, SamplingStream));
    thread_local std::vector<double> z;
    z.resize(dim);
    double *                    x = batch.Sample(cand);
    for (auto & v : z)
      v = random.Normal();
    const double scale = std::sqrt(state.multiplier);
    for (std::size_t a = 0; a < dim; ++a)
    {
      double v = 0.0;
      for (std::size_t b = 0; b <= a; ++b)
        v += l[a * dim + b] * z[b];
      x[a] = mean[a] + scale * v;
    }
    if (cand.anticipate && state.previousMean.size() == dim)
      for (std::size_t a = 0; a < dim; ++a)
        x[a] += AmsDelta * state.multiplier * (mean[a] - state.previousMean[a]);
    Vec3 *                      source = batch.Source(cand);
    Vec3 *                      target = batch.Target(cand);
    for (std::size_t k = 0; k < element.points.size(); ++k)
    {
      const std::uint32_t p = element.points[k];
      source[k] = ProjectToDomain({ { x[6 * k], x[6 * k + 1], x[6 * k + 2] } }, m_Base.pins[p], m_Base.domain);
      target[k] =
        ProjectToDomain({ { x[6 * k + 3], x[6 * k + 4], x[6 * k + 5] } }, m_Base.pins[p], m_Base.domain);
    }
  });
}

void
MoRvGomea::UpdateDistributionStates(const std::vector<ClusterModel> &                         clusters,
                                    const std::vector<std::vector<std::vector<double>>> & acceptedSum,
                                    const std::vector<std::vector<std::size_t>> &         acceptedCount)
{
  // Adaptive variance scaling: the standard-deviation-ratio test and the
  // no-improvement stretch.
  const std::size_t elements = m_Parallel.elements.size();
  for (std::size_t c = 0; c < clusters.size(); ++c)
  {
    if (clusters[c].means.empty() || clusters[c].population.empty())
      continue;
    for (std::size_t e = 0; e < elements; ++e)
    {
      DistributionState & state = m_Distributions[c][e];
      const std::size_t   dim = clusters[c].means[e].size();
      const std::size_t   maxStretch = NoImprovementStretchBase + dim;
      if (acceptedCount[c][e] > 0)
      {
        // SDR: the accepted samples' mean in standard deviations of the model.
        std::vector<double> d(dim), y(dim);
        for (std::size_t a = 0; a < dim; ++a)
          d[a] = acceptedSum[c][e][a] / static_cast<double>(acceptedCount[c][e]) - clusters[c].means[e][a];
        const auto & l = clusters[c].cholesky[e];
        double       ratio = 0.0;
        for (std::size_t a = 0; a < dim; ++a)
        {
          double v = d[a];
          for (std::size_t b = 0; b < a; ++b)
            v -= l[a * dim + b] * y[b];
          y[a] = v / l[a * dim + a];
          ratio = std::max(ratio, std::abs(y[a]));
        }
        state.noImprovementStretch = 0;
        if (state.multiplier < 1.0)
          state.multiplier = 1.0;
        if (ratio > StandardDeviationRatioThreshold)
          state.multiplier = std::min(MultiplierMaximum, state.multiplier * MultiplierIncrease);
      }
      else
      {
        if (state.multiplier <= 1.0)
          ++state.noImprovementStretch;
        if (state.multiplier > 1.0 || state.noImprovementStretch >= maxStretch)
          state.multiplier *= MultiplierDecrease;
        if (state.multiplier < 1.0 && state.noImprovementStretch < maxStretch)
          state.multiplier = 1.0;
      }
      state.previousMean = clusters[c].means[e];
    }
  }
}
} // namespace morea_core
