#include "morea/RefusalBound.h"

#include "morea/Error.h"

#include <cmath>

namespace morea
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
RefusedWhateverItsSamples(const RefusalBound & bound, const TetrahedronValues & corners, const RefusalScreen & screen)
{
  if (!bound.screened)
    return false;
  const Fitness low = BoundFitness(bound, corners, screen);
  if (ConstraintDominates(low, bound.parent))
    return false;
  if (!low.feasible)
    return true;
  for (const ObjectiveVector & entry : screen.archive)
  {
    bool worse = false;
    for (std::size_t j = 0; j < entry.size(); ++j)
      worse |= entry[j] > low.objectives[j];
    if (!worse)
      return true;
  }
  return false;
}
} // namespace morea
