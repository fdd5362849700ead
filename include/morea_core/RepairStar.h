// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the fold repair's view of one point's
// tetrahedra (its star). While the repair tries positions x for one point,
// the other corners stay put, so six times each tetrahedron's oriented volume
// is affine in x: s (x - a) . ((b - a) x (c - a)), with a, b, c the other
// corners in order and s = +-1 from the point's place among the corners and
// the base volume's sign. A trial then costs 3 subtractions, 3 products and
// 2 sums per tetrahedron instead of a whole triple product. The repair ranks
// its trials by these sixfold violations; the constraint itself (checks,
// objectives) keeps the triple product. Plain inline code for both compilers
// (the CPU and the GPU repair round every operation alike, RepairNoise.h).
#ifndef morea_RepairStar_h
#define morea_RepairStar_h

#include "morea_core/RepairNoise.h"

namespace morea_core
{
/** One tetrahedron of a point's star, as a function of the point's position. */
struct StarTerm
{
  double corner[3]; ///< a: the first other corner
  double normal[3]; ///< s (b - a) x (c - a): positive dot product while unfolded
  double lower;     ///< 6 f |base volume| (f: the volume fraction)
  double upper;     ///< 6 |base volume| / f; infinite for f = 0
};

/** The term of a tetrahedron whose other corners are `other` (in order), the
 *  point being corner `slot` (0..3), `reference` its base signed volume. */
MOREA_HOST_DEVICE inline void
MakeStarTerm(const double * const other[3], int slot, double reference, double fraction, StarTerm & t)
{
  using namespace repair_noise;
  double u[3], w[3];
  for (int a = 0; a < 3; ++a)
  {
    t.corner[a] = other[0][a];
    u[a] = Sub(other[1][a], other[0][a]);
    w[a] = Sub(other[2][a], other[0][a]);
  }
  const double n[3] = { Sub(Mul(u[1], w[2]), Mul(u[2], w[1])), Sub(Mul(u[2], w[0]), Mul(u[0], w[2])),
                        Sub(Mul(u[0], w[1]), Mul(u[1], w[0])) };
  // Moving the point from `slot` to the end takes 3 - slot swaps: the
  // volume's sign flips for slots 0 and 2. A negative base volume flips it
  // again, so that "unfolded" is positive (negation is exact).
  const bool flip = (slot % 2 == 0) != !(reference > 0.0);
  for (int a = 0; a < 3; ++a)
    t.normal[a] = flip ? -n[a] : n[a];
  const double size = reference < 0.0 ? -reference : reference;
  t.lower = Mul(6.0, Mul(fraction, size));
  t.upper = fraction > 0.0 ? Div(Mul(6.0, size), fraction) : INFINITY;
}

/** Six times the oriented volume with the point at x. */
MOREA_HOST_DEVICE inline double
StarTermVolume(const StarTerm & t, const double * x)
{
  using namespace repair_noise;
  return Add(Add(Mul(t.normal[0], Sub(x[0], t.corner[0])), Mul(t.normal[1], Sub(x[1], t.corner[1]))),
             Mul(t.normal[2], Sub(x[2], t.corner[2])));
}

/** How far that volume lies outside [lower, upper] (sixfold units), and
 *  whether it does: the constraint's violation, ranked alike. */
MOREA_HOST_DEVICE inline double
StarTermViolation(const StarTerm & t, const double * x, bool & folded)
{
  using namespace repair_noise;
  const double v = StarTermVolume(t, x);
  if (!(v > t.lower))
  {
    folded = true;
    return Sub(t.lower, v);
  }
  if (v > t.upper)
  {
    folded = true;
    return Sub(v, t.upper);
  }
  folded = false;
  return 0.0;
}
} // namespace morea_core

#endif
