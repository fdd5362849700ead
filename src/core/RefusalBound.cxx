// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/RefusalBound.h"

#include "morea_core/Error.h"

#include <cmath>

namespace morea_core
{
RefusalBoundChoice
ParseRefusalBoundChoice(const std::string & name)
{
  if (name == "auto")
    return RefusalBoundChoice::Auto;
  if (name == "on")
    return RefusalBoundChoice::On;
  if (name == "off")
    return RefusalBoundChoice::Off;
  throw Error("refusal bound: '" + name + "' is none of auto, on, off");
}

Fitness
SteeredFitness(const Fitness & raw, double guidanceLimit)
{
  Fitness f = raw;
  if (!raw.feasible)
    f.constraint = FoldConstraintOffset + raw.constraint;
  else if (Value(raw.objectives, Objective::Guidance) > guidanceLimit)
  {
    f.feasible = false;
    f.constraint = Value(raw.objectives, Objective::Guidance) - guidanceLimit;
  }
  return f;
}

Fitness
BoundFitness(const RefusalBound & bound, const TetrahedronValues & corners, const RefusalScreen & screen)
{
  ObjectiveTotals totals;
  totals.sum = bound.rest;
  totals.Add(corners);
  return SteeredFitness(totals.ToFitness(screen.tetrahedra), screen.guidanceLimit);
}

bool
RefusedWhateverItsSamples(const RefusalBound & bound, const TetrahedronValues & corners, const RefusalScreen & screen,
                          std::size_t * entry)
{
  if (!bound.screened)
    return false;
  const Fitness low = BoundFitness(bound, corners, screen);
  if (ConstraintDominates(low, bound.parent))
    return false;
  std::size_t e = 0;
  if (low.feasible)
  {
    for (; e < screen.archive.size(); ++e)
    {
      bool worse = false;
      for (std::size_t j = 0; j < NumberOfObjectives; ++j)
        worse |= screen.archive[e][j] > low.objectives[j];
      if (!worse)
        break;
    }
    if (e == screen.archive.size())
      return false;
  }
  else
    e = screen.archive.size();
  if (entry)
    *entry = e;
  return true;
}
} // namespace morea_core
