// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of dominance, non-dominated sorting, the hypervolume and the
// single-solution selections of morea/ParetoFront.h. Core tests: no ITK.
#include "morea_core/Error.h"
#include "morea_core/ParetoFront.h"
#include "morea_core/Random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <vector>

namespace
{
using morea_core::Fitness;
using morea_core::ObjectiveVector;

Fitness
Feasible(double a, double b, double c)
{
  return Fitness{ { { a, b, c } }, true, 0.0 };
}
Fitness
Infeasible(double constraint, double a = 0.0, double b = 0.0, double c = 0.0)
{
  return Fitness{ { { a, b, c } }, false, constraint };
}

/** Exact hypervolume by brute force: the distinct coordinates cut the box
 *  below the reference into cells, each wholly dominated or not. */
double
GridHypervolume(const std::vector<ObjectiveVector> & points, const ObjectiveVector & reference)
{
  std::array<std::vector<double>, 3> cuts;
  for (int j = 0; j < 3; ++j)
  {
    cuts[j].push_back(reference[j]);
    for (const auto & p : points)
      if (p[j] < reference[j])
        cuts[j].push_back(p[j]);
    std::sort(cuts[j].begin(), cuts[j].end());
    cuts[j].erase(std::unique(cuts[j].begin(), cuts[j].end()), cuts[j].end());
  }
  double volume = 0.0;
  for (std::size_t i = 0; i + 1 < cuts[0].size(); ++i)
    for (std::size_t k = 0; k + 1 < cuts[1].size(); ++k)
      for (std::size_t l = 0; l + 1 < cuts[2].size(); ++l)
      {
        const ObjectiveVector centre{ { (cuts[0][i] + cuts[0][i + 1]) / 2, (cuts[1][k] + cuts[1][k + 1]) / 2,
                                        (cuts[2][l] + cuts[2][l + 1]) / 2 } };
        const bool dominated = std::any_of(points.begin(), points.end(), [&](const ObjectiveVector & p) {
          return p[0] <= centre[0] && p[1] <= centre[1] && p[2] <= centre[2];
        });
        if (dominated)
          volume += (cuts[0][i + 1] - cuts[0][i]) * (cuts[1][k + 1] - cuts[1][k]) * (cuts[2][l + 1] - cuts[2][l]);
      }
  return volume;
}
} // namespace

TEST(ParetoFront, Dominance)
{
  using morea_core::Dominates;
  EXPECT_TRUE(Dominates({ { 1, 2, 3 } }, { { 1, 2, 4 } }));
  EXPECT_TRUE(Dominates({ { 0, 0, 0 } }, { { 1, 1, 1 } }));
  EXPECT_FALSE(Dominates({ { 1, 2, 3 } }, { { 1, 2, 3 } })); // equal: no strict improvement
  EXPECT_FALSE(Dominates({ { 1, 2, 3 } }, { { 2, 1, 3 } })); // trade-off
  EXPECT_FALSE(Dominates({ { 2, 1, 3 } }, { { 1, 2, 3 } }));
  EXPECT_FALSE(Dominates({ { 1, 2, 4 } }, { { 1, 2, 3 } }));
}

TEST(ParetoFront, ConstraintDomination)
{
  using morea_core::ConstraintDominates;
  // Feasible beats infeasible whatever the objectives.
  EXPECT_TRUE(ConstraintDominates(Feasible(9, 9, 9), Infeasible(0.1, 0, 0, 0)));
  EXPECT_FALSE(ConstraintDominates(Infeasible(0.1, 0, 0, 0), Feasible(9, 9, 9)));
  // Two infeasible: the smaller violation wins, objectives do not matter.
  EXPECT_TRUE(ConstraintDominates(Infeasible(1.0, 9, 9, 9), Infeasible(2.0, 0, 0, 0)));
  EXPECT_FALSE(ConstraintDominates(Infeasible(2.0, 0, 0, 0), Infeasible(1.0, 9, 9, 9)));
  EXPECT_FALSE(ConstraintDominates(Infeasible(1.0, 0, 0, 0), Infeasible(1.0, 9, 9, 9)));
  // Two feasible: Pareto dominance.
  EXPECT_TRUE(ConstraintDominates(Feasible(1, 1, 1), Feasible(1, 2, 1)));
  EXPECT_FALSE(ConstraintDominates(Feasible(1, 2, 1), Feasible(2, 1, 1)));
  EXPECT_FALSE(ConstraintDominates(Feasible(1, 1, 1), Feasible(1, 1, 1)));
}

TEST(ParetoFront, RanksUnderConstraintDomination)
{
  const std::vector<Fitness> population{
    Feasible(1, 1, 1),         // 0: first front
    Feasible(2, 2, 2),         // 1: dominated by 0
    Feasible(0, 5, 0),         // 2: trade-off with 0 -> first front
    Feasible(3, 3, 3),         // 3: dominated by 1
    Infeasible(1.0, 0, 0, 0),  // 4: behind every feasible one
    Infeasible(2.0, 0, 0, 0),  // 5: behind 4 (larger violation)
    Infeasible(1.0, 9, 9, 9),  // 6: same violation as 4 -> same rank
    Feasible(1, 1, 1),         // 7: duplicate of 0 -> same rank
    Feasible(2.5, 2.5, 0.5),   // 8: dominated by none of 0, 2 -> first front
  };
  EXPECT_EQ(morea_core::NonDominatedRanks(population), (std::vector<std::size_t>{ 0, 1, 0, 2, 3, 4, 3, 0, 0 }));
  EXPECT_TRUE(morea_core::NonDominatedRanks({}).empty());
  EXPECT_EQ(morea_core::NonDominatedRanks({ Infeasible(3.0) }), (std::vector<std::size_t>{ 0 }));
}

TEST(ParetoFront, RanksAgreeWithDefinitionOnRandomPopulation)
{
  // Rank r: dominated only by solutions of rank < r, and by one of rank r - 1.
  // Every other solution on a coarse grid: equal objectives and ties in some.
  morea_core::RandomGenerator random(7);
  std::vector<Fitness>   population;
  for (int i = 0; i < 300; ++i)
  {
    Fitness f = i % 2 ? Feasible(std::floor(random.Uniform(0.0, 4.0)), std::floor(random.Uniform(0.0, 4.0)),
                                 std::floor(random.Uniform(0.0, 4.0)))
                      : Feasible(random.Uniform(), random.Uniform(), random.Uniform());
    if (random.Uniform() < 0.2)
    {
      f.feasible = false;
      f.constraint = std::floor(random.Uniform(0.0, 5.0));
    }
    population.push_back(f);
  }
  const auto ranks = morea_core::NonDominatedRanks(population);
  for (std::size_t i = 0; i < population.size(); ++i)
  {
    bool dominatedByPreviousRank = false;
    for (std::size_t k = 0; k < population.size(); ++k)
      if (morea_core::ConstraintDominates(population[k], population[i]))
      {
        ASSERT_LT(ranks[k], ranks[i]);
        dominatedByPreviousRank = dominatedByPreviousRank || ranks[k] + 1 == ranks[i];
      }
    EXPECT_TRUE(ranks[i] == 0 || dominatedByPreviousRank) << i;
  }
}

namespace
{
/** Deb's ranks by their definition: peel off the solutions no remaining
 *  one dominates, front by front (all pairs, every round). */
std::vector<std::size_t>
RanksByPeeling(const std::vector<Fitness> & population)
{
  const std::size_t        n = population.size();
  std::vector<std::size_t> ranks(n, n);
  for (std::size_t rank = 0, left = n; left > 0; ++rank)
  {
    std::vector<std::size_t> front;
    for (std::size_t i = 0; i < n; ++i)
    {
      if (ranks[i] != n)
        continue;
      bool dominated = false;
      for (std::size_t k = 0; k < n && !dominated; ++k)
        dominated = ranks[k] == n && morea_core::ConstraintDominates(population[k], population[i]);
      if (!dominated)
        front.push_back(i);
    }
    for (std::size_t i : front)
      ranks[i] = rank;
    left -= front.size();
  }
  return ranks;
}
} // namespace

TEST(ParetoFront, RanksAreThoseOfPeelingFrontsOffOnPopulationsOfEveryShape)
{
  // Shapes the optimiser meets: scattered (many fronts), near one surface
  // (a large first front, as late in a run), exactly on it (one front),
  // coarse grids (ties and identical solutions) and infeasible ones.
  morea_core::RandomGenerator random(11);
  for (int shape = 0; shape < 5; ++shape)
    for (int round = 0; round < 4; ++round)
    {
      std::vector<Fitness> population;
      for (int i = 0; i < 400; ++i)
      {
        const double a = random.Uniform(), b = random.Uniform() * (1.0 - a), c = 1.0 - a - b;
        const double noise = shape == 1 ? 0.01 : 0.0;
        Fitness      f = Feasible(a, b, c);
        if (shape == 0)
          f = Feasible(random.Uniform(), random.Uniform(), random.Uniform());
        else if (shape == 3)
          f = Feasible(std::floor(random.Uniform(0.0, 6.0)), std::floor(random.Uniform(0.0, 6.0)),
                       std::floor(random.Uniform(0.0, 6.0)));
        else if (shape == 4)
          f = Feasible(std::floor(random.Uniform(0.0, 3.0)), std::floor(random.Uniform(0.0, 3.0)),
                       std::floor(random.Uniform(0.0, 3.0)));
        for (double & o : f.objectives)
          o += noise * random.Uniform();
        if (random.Uniform() < (round == 0 ? 0.0 : 0.1 * round))
        {
          f.feasible = false;
          f.constraint = std::floor(random.Uniform(0.0, 5.0));
        }
        population.push_back(f);
      }
      const auto ranks = morea_core::NonDominatedRanks(population);
      ASSERT_EQ(ranks, RanksByPeeling(population)) << "shape " << shape << ", round " << round;
      if (shape == 2 && round == 0)
        EXPECT_EQ(*std::max_element(ranks.begin(), ranks.end()), 0u) << "all on one surface: one front";
      if (shape == 0 || shape == 3)
        EXPECT_GT(*std::max_element(ranks.begin(), ranks.end()), 3u) << "several fronts";
    }
}

TEST(ParetoFront, RanksCountANotANumberAsTheWorst)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // NaN in any objective: worse than the same solution with a number there.
  const std::vector<Fitness> population{ Feasible(nan, 1.0, 1.0), Feasible(1.0, 1.0, 1.0), Feasible(0.0, nan, 0.0),
                                         Feasible(0.0, 2.0, 0.0) };
  EXPECT_EQ(morea_core::NonDominatedRanks(population), (std::vector<std::size_t>{ 1, 0, 1, 0 }));
}

TEST(ParetoFront, HypervolumeOfHandComputedSets)
{
  const ObjectiveVector reference{ { 4, 4, 4 } };
  EXPECT_EQ(morea_core::Hypervolume({}, reference), 0.0);
  // One box: 3 * 2 * 1.
  EXPECT_DOUBLE_EQ(morea_core::Hypervolume({ { { 1, 2, 3 } } }, reference), 6.0);
  // Two overlapping boxes: 6 + 6 - overlap [2,4]x[2,4]x[3,4] = 4 -> 8.
  EXPECT_DOUBLE_EQ(morea_core::Hypervolume({ { { 1, 2, 3 } }, { { 2, 1, 3 } } }, reference), 8.0);
  // A third box [3,4]x[3,4]x[1,4] = 3, of which [3,4]^3 = 1 is covered -> 10.
  const std::vector<ObjectiveVector> three{ { { 1, 2, 3 } }, { { 2, 1, 3 } }, { { 3, 3, 1 } } };
  EXPECT_DOUBLE_EQ(morea_core::Hypervolume(three, reference), 10.0);
  // Order does not matter; dominated points and duplicates add nothing.
  std::vector<ObjectiveVector> more{ three[2], { { 3, 3, 3 } }, three[0], three[1], three[0] };
  EXPECT_DOUBLE_EQ(morea_core::Hypervolume(more, reference), 10.0);
  // Points not strictly better than the reference in every objective are ignored,
  // even where they would otherwise dominate the others.
  more.push_back({ { 5, 0, 0 } });
  more.push_back({ { 0, 4, 0 } });
  more.push_back({ { 0, 0, 4 } });
  EXPECT_DOUBLE_EQ(morea_core::Hypervolume(more, reference), 10.0);
  // Negative coordinates and a shifted reference.
  EXPECT_DOUBLE_EQ(morea_core::Hypervolume({ { { -1, -2, -3 } } }, { { 0, 0, 0 } }), 6.0);
}

TEST(ParetoFront, BoundedHypervolumeCountsFrontsBeyondItsScales)
{
  const ObjectiveVector scales{ { 2, 4, 8 } };
  EXPECT_EQ(morea_core::BoundedHypervolume({}, scales), 0.0);
  // f = s maps to 1/2 in every objective: (1 - 1/2)^3.
  EXPECT_DOUBLE_EQ(morea_core::BoundedHypervolume({ { { 2, 4, 8 } } }, scales), 0.125);
  // The origin dominates the whole unit cube.
  EXPECT_DOUBLE_EQ(morea_core::BoundedHypervolume({ { { 0, 0, 0 } } }, scales), 1.0);
  // f = 3 s maps to 3/4: a point far beyond the scales still counts, where a
  // box at the scales would have left it out.
  EXPECT_DOUBLE_EQ(morea_core::BoundedHypervolume({ { { 6, 4, 8 } } }, scales), 0.25 * 0.5 * 0.5);
  EXPECT_EQ(morea_core::Hypervolume({ { { 6, 4, 8 } } }, scales), 0.0);
  // Dominance is kept: a dominated point adds nothing, a better one adds.
  const std::vector<ObjectiveVector> two{ { { 2, 4, 8 } }, { { 6, 1, 8 } } };
  const double                       volume = morea_core::BoundedHypervolume(two, scales);
  EXPECT_DOUBLE_EQ(volume, 0.125 + 0.25 * (0.8 - 0.5) * 0.5);
  EXPECT_DOUBLE_EQ(morea_core::BoundedHypervolume({ two[0], two[1], { { 6, 4, 8 } } }, scales), volume);
  EXPECT_GT(morea_core::BoundedHypervolume({ two[0], two[1], { { 1, 4, 8 } } }, scales), volume);
  // Infinite objectives count for nothing; bad scales are an error.
  EXPECT_EQ(morea_core::BoundedHypervolume({ { { 2, INFINITY, 8 } } }, scales), 0.0);
  EXPECT_THROW(morea_core::BoundedHypervolume({}, { { 1, 0, 1 } }), morea_core::Error);
  EXPECT_THROW(morea_core::BoundedHypervolume({}, { { 1, NAN, 1 } }), morea_core::Error);
}

TEST(ParetoFront, HypervolumeMatchesBruteForceOnRandomSets)
{
  morea_core::RandomGenerator random(11);
  const ObjectiveVector  reference{ { 1.0, 1.2, 0.9 } };
  for (int trial = 0; trial < 40; ++trial)
  {
    const int                    n = 1 + trial;
    std::vector<ObjectiveVector> points;
    for (int i = 0; i < n; ++i)
    {
      // Half near the front x + y + z = 1 (many mutually non-dominated), half
      // anywhere (some dominated, some beyond the reference); some repeated
      // coordinates to exercise ties.
      ObjectiveVector p{ { random.Uniform(), random.Uniform(), random.Uniform() } };
      if (i % 2 == 0)
      {
        const double s = p[0] + p[1] + p[2];
        for (double & x : p)
          x = x / s + random.Uniform(-0.02, 0.02);
      }
      else
        for (double & x : p)
          x *= 1.3;
      if (i % 5 == 4)
        p[random.NextU64() % 3] = points.front()[random.NextU64() % 3];
      points.push_back(p);
    }
    const double exact = GridHypervolume(points, reference);
    EXPECT_NEAR(morea_core::Hypervolume(points, reference), exact, 1e-12 * std::max(1.0, exact)) << "trial " << trial;
  }
}

TEST(ParetoFront, HypervolumeOf2000PointsIsFast)
{
  // 2000 points on the unit sphere's positive octant, all non-dominated. Their
  // boxes lie outside the ball, so the volume is below 1 - pi/6 and near it.
  morea_core::RandomGenerator       random(3);
  std::vector<ObjectiveVector> points;
  while (points.size() < 2000)
  {
    ObjectiveVector p{ { std::abs(random.Normal()), std::abs(random.Normal()), std::abs(random.Normal()) } };
    const double    norm = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    if (norm == 0.0)
      continue;
    for (double & x : p)
      x /= norm;
    points.push_back(p);
  }
  const auto   start = std::chrono::steady_clock::now();
  const double volume = morea_core::Hypervolume(points, { { 1, 1, 1 } });
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("Hypervolume of %zu points: %.3f ms\n", points.size(), ms);
  EXPECT_LT(ms, 50.0);
  const double bound = 1.0 - std::acos(-1.0) / 6.0;
  EXPECT_LT(volume, bound);
  EXPECT_GT(volume, 0.9 * bound);
}

TEST(ParetoFront, SelectBestGuidance)
{
  // Guidance 2 twice: index 1 has the smaller normalised sum (1/3 + 1/5 + 0
  // against 0 + 1 + 0).
  const std::vector<ObjectiveVector> front{ { { 0, 0, 5 } }, { { 1, 1, 2 } }, { { 0, 5, 2 } }, { { 3, 3, 9 } } };
  EXPECT_EQ(morea_core::SelectBestGuidance(front), 1u);
  EXPECT_EQ(morea_core::SelectBestGuidance({ { { 7, 7, 7 } } }), 0u);
  EXPECT_THROW(morea_core::SelectBestGuidance({}), morea_core::Error);
}

TEST(ParetoFront, SelectKnee)
{
  // Extremes on the plane x + y + z = 1; (0.2, 0.2, 0.2) lies farthest below it.
  std::vector<ObjectiveVector> front{ { { 1, 0, 0 } },       { { 0.3, 0.3, 0.1 } }, { { 0, 1, 0 } },
                                      { { 0.2, 0.2, 0.2 } }, { { 0, 0, 1 } },       { { 0.1, 0.1, 0.9 } } };
  EXPECT_EQ(morea_core::SelectKnee(front), 3u);
  // Normalisation: rescaling and shifting objectives changes nothing.
  for (auto & p : front)
    p = { { 100.0 * p[0] + 5.0, p[1] - 2.0, 0.01 * p[2] } };
  EXPECT_EQ(morea_core::SelectKnee(front), 3u);

  // A front flat in one objective has two extremes: the one nearest the ideal
  // point is (0.25, 0.25) normalised.
  EXPECT_EQ(morea_core::SelectKnee({ { { 0, 4, 1 } }, { { 4, 0, 1 } }, { { 1, 1, 1 } }, { { 3, 0.5, 1 } } }), 2u);
  EXPECT_EQ(morea_core::SelectKnee({ { { 1, 2, 3 } } }), 0u);
  EXPECT_THROW(morea_core::SelectKnee({}), morea_core::Error);
}

TEST(ParetoFront, SelectWeighted)
{
  const std::vector<ObjectiveVector> front{ { { 0, 10, 10 } }, { { 10, 0, 10 } }, { { 10, 10, 0 } }, { { 4, 4, 4 } } };
  EXPECT_EQ(morea_core::SelectWeighted(front, { { 1, 0, 0 } }), 0u);
  EXPECT_EQ(morea_core::SelectWeighted(front, { { 0, 0, 2 } }), 2u);
  EXPECT_EQ(morea_core::SelectWeighted(front, { { 1, 1, 1 } }), 3u); // 1.2 against 2
  EXPECT_EQ(morea_core::SelectWeighted(front, { { 0, 3, 1 } }), 1u); // 1 against 1.6
  // Weights act on normalised objectives: objective 0 in large units does not
  // swamp the others.
  const std::vector<ObjectiveVector> scaled{ { { 0, 1, 1 } }, { { 1000, 0, 0.6 } } };
  EXPECT_EQ(morea_core::SelectWeighted(scaled, { { 1, 1, 1 } }), 1u); // 1 against 2

  EXPECT_THROW(morea_core::SelectWeighted(front, { { 0, 0, 0 } }), morea_core::Error);
  EXPECT_THROW(morea_core::SelectWeighted(front, { { 1, -1, 1 } }), morea_core::Error);
  EXPECT_THROW(morea_core::SelectWeighted(front, { { 1, std::numeric_limits<double>::quiet_NaN(), 1 } }), morea_core::Error);
  EXPECT_THROW(morea_core::SelectWeighted(front, { { 1, std::numeric_limits<double>::infinity(), 1 } }), morea_core::Error);
  EXPECT_THROW(morea_core::SelectWeighted({}, { { 1, 1, 1 } }), morea_core::Error);
}

TEST(ParetoFront, SelectNearest)
{
  const std::vector<ObjectiveVector> front{ { { 0, 10, 10 } }, { { 10, 0, 10 } }, { { 10, 10, 0 } }, { { 4, 4, 4 } } };
  EXPECT_EQ(morea_core::SelectNearest(front, { { 10, 0, 10 } }), 1u);
  EXPECT_EQ(morea_core::SelectNearest(front, { { 5, 5, 5 } }), 3u);
  EXPECT_EQ(morea_core::SelectNearest(front, { { 9, 8, -3 } }), 2u);
  // Distances are taken after normalising: (60, 1, 0) is (0.6, 1, 0), nearer
  // (0, 1, 0) than (1, 0, 0), though in raw units it is nearer (100, 0, 0).
  const std::vector<ObjectiveVector> scaled{ { { 0, 1, 0 } }, { { 100, 0, 0 } } };
  EXPECT_EQ(morea_core::SelectNearest(scaled, { { 60, 1, 0 } }), 0u);
  EXPECT_EQ(morea_core::SelectNearest(scaled, { { 80, 0.2, 0 } }), 1u);
  EXPECT_THROW(morea_core::SelectNearest({}, { { 0, 0, 0 } }), morea_core::Error);
}

TEST(ParetoFront, SelectSpread)
{
  // Normalised, the front spans the unit cube's corners and one middle point.
  const std::vector<ObjectiveVector> front{ { { 0.5, 0.5, 0.5 } }, { { 1, 0, 0 } }, { { 0, 1, 0 } },
                                            { { 0, 0, 1 } },       { { 0.9, 0.1, 0.0 } } };
  // Best guidance first, then each time the farthest from those chosen:
  // corners 1, 2, 3, the middle, and last the near-copy of corner 1.
  const auto four = morea_core::SelectSpread(front, 4);
  ASSERT_EQ(four, (std::vector<std::size_t>{ 1, 2, 3, 0 }));
  EXPECT_EQ(four[0], morea_core::SelectBestGuidance(front));
  // Distinct, and every prefix is what a smaller count gives.
  EXPECT_EQ(std::set<std::size_t>(four.begin(), four.end()).size(), 4u);
  for (std::size_t n = 1; n <= 4; ++n)
    EXPECT_EQ(morea_core::SelectSpread(front, n), std::vector<std::size_t>(four.begin(), four.begin() + n)) << n;
  // The second is the member farthest from the first.
  const auto distance = [&](std::size_t a, std::size_t b) {
    double d = 0.0;
    for (std::size_t j = 0; j < 3; ++j)
      d += (front[a][j] - front[b][j]) * (front[a][j] - front[b][j]);
    return d;
  };
  for (std::size_t i = 0; i < front.size(); ++i)
    EXPECT_LE(distance(i, four[0]), distance(four[1], four[0]));
  // The near-duplicate of a chosen corner (index 4) comes last.
  const auto all = morea_core::SelectSpread(front, 10);
  ASSERT_EQ(all.size(), front.size());
  EXPECT_EQ(all.back(), 4u);
  // Equal solutions are not chosen twice.
  EXPECT_EQ(morea_core::SelectSpread({ { { 1, 2, 3 } }, { { 1, 2, 3 } } }, 5), std::vector<std::size_t>{ 0 });
  EXPECT_THROW(morea_core::SelectSpread(front, 0), morea_core::Error);
  EXPECT_THROW(morea_core::SelectSpread({}, 3), morea_core::Error);
}
