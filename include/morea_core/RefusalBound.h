// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: a bound that refuses a partial candidate
// before its samples are drawn.
//
// Every sample adds a non-negative term to a tetrahedron's intensity and
// guidance sums, and its magnitude, sample counts and folds follow from its
// corners alone. So a candidate's totals with the new tetrahedra's intensity
// and guidance at 0 bound its objectives from below, objective by objective,
// and its constraint value too. If that bound is refused (an archive entry
// equals or dominates it, or it is infeasible) and does not constraint-
// dominate the parent, the candidate is refused whatever its samples hold:
// a backend need not draw them. The optimiser checks every such candidate
// again, exactly, on the totals and archive of its turn, and has the backend
// sample those the check does not refuse (EvaluationBackend::SampleSkipped),
// so that no decision changes.
#ifndef morea_RefusalBound_h
#define morea_RefusalBound_h

#include "morea_core/ParetoFront.h"
#include "morea_core/TetrahedronObjectives.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace morea_core
{
/** Added to an infeasible solution's fold value so that any folded solution
 *  ranks below any solution that only exceeds the guidance limit. */
constexpr double FoldConstraintOffset = 1.0e12;

/** Adaptive steering (SPEC 5): a feasible fitness whose guidance exceeds
 *  `guidanceLimit` (infinity: none) becomes infeasible by the excess; a
 *  folded one keeps its fold value, offset below every steered one. */
Fitness
SteeredFitness(const Fitness & raw, double guidanceLimit);

/** What a backend needs of one candidate to bound it (PartialCandidate::bound). */
struct RefusalBound
{
  /** In: whether the bound may skip the candidate (false for acceptance
   *  rules other than the archive's). */
  bool screened{ false };
  /** In: the parent's totals less its values of the element's dependent
   *  tetrahedra. */
  TetrahedronValues rest;
  /** In: the parent's (steered) fitness. */
  Fitness parent;
  /** Out: not sampled. Its values then hold magnitude, fold value, folds and
   *  sample counts, with intensity and guidance 0. */
  bool skipped{ false };
  /** Out, when skipped: the archive entry that refused the bound (from
   *  RefusalScreen::witnesses; 0: none, the bound is infeasible), the first
   *  to try when the optimiser judges it. */
  std::uint64_t witness{ 0 };
};

/** What bounds all candidates of a batch: the archive's objective vectors
 *  when the batch began and how totals become a fitness. */
struct RefusalScreen
{
  std::vector<ObjectiveVector> archive;
  std::vector<std::uint64_t>   witnesses; ///< per entry, its name for ElitistArchive::Judge
  std::size_t                  tetrahedra{ 0 };
  double                       guidanceLimit{ 0.0 };
  /** Fills the bound of candidate i of the EvaluatePartials call from its
   *  parent's state. Called by the backend for each candidate with a bound,
   *  from several threads at once, before screening it: where the backend
   *  has other work under way (a GPU checking folds), this host work
   *  overlaps it. */
  std::function<void(std::size_t)> fill;
};

/** Whether a run lets its backend skip candidates by their bound. */
enum class RefusalBoundChoice
{
  Auto, ///< where the backend gains from it (EvaluationBackend::GainsFromRefusalBounds)
  On,
  Off
};

/** "auto", "on" or "off"; anything else is an error. */
RefusalBoundChoice
ParseRefusalBoundChoice(const std::string & name);

/** The lower bound's fitness: `rest` plus `corners`, the new tetrahedra's
 *  values without their intensity and guidance. */
Fitness
BoundFitness(const RefusalBound & bound, const TetrahedronValues & corners, const RefusalScreen & screen);

/** Whether the bound shows the candidate refused against the screen's
 *  archive: the rule both backends apply (the CUDA kernel mirrors it).
 *  `entry` (if set) gets the refusing entry's index, or the archive's size
 *  when the bound is refused as infeasible. */
bool
RefusedWhateverItsSamples(const RefusalBound & bound, const TetrahedronValues & corners, const RefusalScreen & screen,
                          std::size_t * entry = nullptr);
} // namespace morea_core

#endif
