// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: objective vectors, constraint domination,
// non-dominated sorting, hypervolume and the helpers that pick one solution of
// an approximation set (SPEC 5 and 7).
#ifndef morea_ParetoFront_h
#define morea_ParetoFront_h

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace morea_core
{
/** All objectives are minimised. */
enum class Objective : std::size_t
{
  Magnitude = 0, ///< deformation magnitude
  Intensity = 1, ///< image dissimilarity
  Guidance = 2   ///< contour distance
};
constexpr std::size_t NumberOfObjectives = 3;
using ObjectiveVector = std::array<double, NumberOfObjectives>;

inline double
Value(const ObjectiveVector & v, Objective o)
{
  return v[static_cast<std::size_t>(o)];
}

/** A solution's standing: its objectives and, when infeasible, how badly. */
struct Fitness
{
  ObjectiveVector objectives{ { 0.0, 0.0, 0.0 } };
  bool            feasible{ true };
  double          constraint{ 0.0 }; ///< > = 0; compared only between infeasible solutions
};

/** Pareto dominance of objective vectors: no worse in all, better in one.
 *  Inline and branch-free: the archive's scans call it millions of times. */
inline bool
Dominates(const ObjectiveVector & a, const ObjectiveVector & b)
{
  bool worse = false, better = false;
  for (std::size_t j = 0; j < a.size(); ++j)
  {
    worse |= a[j] > b[j];
    better |= a[j] < b[j];
  }
  return !worse && better;
}

/** Squared Euclidean distance of two objective vectors. */
inline double
SquaredDistance(const ObjectiveVector & a, const ObjectiveVector & b)
{
  double d = 0.0;
  for (std::size_t j = 0; j < a.size(); ++j)
    d += (a[j] - b[j]) * (a[j] - b[j]);
  return d;
}

/** Constraint domination (Deb): feasible beats infeasible; of two infeasible
 *  solutions the smaller constraint value wins; two feasible ones compare by
 *  Pareto dominance. */
bool
ConstraintDominates(const Fitness & a, const Fitness & b);

/** Non-domination rank under constraint domination: 0 for the first front
 *  (O(n log^2 n) for 3 objectives; a NaN objective or constraint counts as
 *  +infinity). */
std::vector<std::size_t>
NonDominatedRanks(const std::vector<Fitness> & population);

/** Hypervolume dominated by `points` and bounded by `reference` (3 objectives,
 *  exact). Points not strictly better than the reference in every objective
 *  contribute nothing. */
double
Hypervolume(const std::vector<ObjectiveVector> & points, const ObjectiveVector & reference);

/** Hypervolume of `points` with each objective f mapped to f / (f + s), s
 *  the objective's entry of `scales` (positive), against the reference
 *  (1, 1, 1). The mapping keeps the order of every objective, hence
 *  dominance, and takes [0, inf) into [0, 1): every front of nonnegative
 *  objectives counts, however far it moves from where the scales were
 *  taken, and fronts of one run compare as long as the scales stay. */
double
BoundedHypervolume(const std::vector<ObjectiveVector> & points, const ObjectiveVector & scales);

/** Choosing one solution of a front (indices into `front`; all throw
 *  morea_core::Error on an empty front). Objectives are first normalised to [0,1]
 *  by the front's range (an objective with zero range counts as 0). */
/** Smallest guidance value; ties broken by the smaller normalised sum. */
std::size_t
SelectBestGuidance(const std::vector<ObjectiveVector> & front);
/** Knee point: the solution farthest below the plane through the front's
 *  extreme solutions (for fewer than 3 distinct extremes, the one nearest the
 *  ideal point). */
std::size_t
SelectKnee(const std::vector<ObjectiveVector> & front);
/** Smallest weighted sum of normalised objectives (weights >= 0, not all 0). */
std::size_t
SelectWeighted(const std::vector<ObjectiveVector> & front, const ObjectiveVector & weights);
/** Nearest to `point` (raw objective units, normalised like the front). */
std::size_t
SelectNearest(const std::vector<ObjectiveVector> & front, const ObjectiveVector & point);
/** Up to `count` distinct solutions spread over the front, in the order
 *  chosen: the best-guidance solution first, then each time the one farthest
 *  (normalised) from all chosen so far, the first on ties; so every prefix is
 *  spread too. Fewer when the front holds fewer; count 0 throws. */
std::vector<std::size_t>
SelectSpread(const std::vector<ObjectiveVector> & front, std::size_t count);
} // namespace morea_core

#endif
