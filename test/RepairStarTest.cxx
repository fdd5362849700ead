// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The fold repair's star terms (RepairStar.h): six times a tetrahedron's
// oriented volume as an affine function of one corner, for each place of the
// corner and either orientation of the base volume, and violations that fold
// exactly where the constraint does.
#include "morea_core/RepairStar.h"
#include "morea_core/TetrahedralMesh.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

using namespace morea_core;

namespace
{
/** The term of corner `slot` of tetrahedron c, base volume `reference`. */
StarTerm
TermOf(const std::array<Vec3, 4> & c, int slot, double reference, double fraction)
{
  const double * other[3];
  int            m = 0;
  for (int j = 0; j < 4; ++j)
    if (j != slot)
      other[m++] = c[j].data();
  StarTerm t;
  MakeStarTerm(other, slot, reference, fraction, t);
  return t;
}
} // namespace

TEST(RepairStar, TermIsSixTimesTheOrientedVolume)
{
  std::mt19937_64                        random(7);
  std::uniform_real_distribution<double> coordinate(-40.0, 40.0);
  int                                    checked = 0;
  for (int n = 0; n < 2000; ++n)
  {
    std::array<Vec3, 4> c;
    for (Vec3 & p : c)
      p = { { coordinate(random), coordinate(random), coordinate(random) } };
    const double volume = SignedVolume(c[0], c[1], c[2], c[3]);
    if (std::abs(volume) < 1.0)
      continue; // nearly flat: the two formulas round apart
    for (int slot = 0; slot < 4; ++slot)
      for (double reference : { 2.5, -2.5 })
      {
        const StarTerm t = TermOf(c, slot, reference, 0.0);
        const double   oriented = reference > 0.0 ? volume : -volume;
        EXPECT_NEAR(StarTermVolume(t, c[slot].data()), 6.0 * oriented, 1e-9 * std::abs(6.0 * volume))
          << "slot " << slot << ", reference " << reference;
        // Affine: moving the corner by d changes it by normal . d.
        const double d[3] = { 0.25, -1.5, 3.0 };
        const double moved[3] = { c[slot][0] + d[0], c[slot][1] + d[1], c[slot][2] + d[2] };
        std::array<Vec3, 4> m = c;
        m[slot] = { { moved[0], moved[1], moved[2] } };
        const double movedVolume = SignedVolume(m[0], m[1], m[2], m[3]);
        EXPECT_NEAR(StarTermVolume(t, moved), 6.0 * (reference > 0.0 ? movedVolume : -movedVolume),
                    1e-9 * (std::abs(6.0 * movedVolume) + std::abs(6.0 * volume)));
        ++checked;
      }
  }
  EXPECT_GT(checked, 4000);
}

TEST(RepairStar, ViolationFoldsWhereTheConstraintDoes)
{
  // A right tetrahedron of volume 1/6 (base), its apex moved along z.
  const double reference = 1.0 / 6.0;
  for (double fraction : { 0.0, 0.5 })
    for (double z : { 1.0, 0.6, 0.4, 0.0, -0.5, 1.9, 2.5 })
    {
      const std::array<Vec3, 4> c{ { { { 0, 0, 0 } }, { { 1, 0, 0 } }, { { 0, 1, 0 } }, { { 0, 0, z } } } };
      const StarTerm            t = TermOf(c, 3, reference, fraction);
      bool                      folded = false;
      const double              violation = StarTermViolation(t, c[3].data(), folded);
      // Oriented volume z / 6 against [f, 1/f] x 1/6: sixfold, z against [f, 1/f].
      const double lower = fraction, upper = fraction > 0.0 ? 1.0 / fraction : INFINITY;
      const bool   expected = !(z > lower) || z > upper;
      EXPECT_EQ(folded, expected) << "fraction " << fraction << ", z " << z;
      const double expectedValue = z <= lower ? lower - z : (z > upper ? z - upper : 0.0);
      EXPECT_NEAR(violation, expectedValue, 1e-12) << "fraction " << fraction << ", z " << z;
    }
  // The same apex as corner 0 of a reordered tetrahedron with a negative
  // base volume: the term says unfolded while z > 0 all the same.
  const std::array<Vec3, 4> r{ { { { 0, 0, 0.5 } }, { { 0, 0, 0 } }, { { 1, 0, 0 } }, { { 0, 1, 0 } } } };
  ASSERT_LT(SignedVolume(r[0], r[1], r[2], r[3]), 0.0);
  bool folded = true;
  EXPECT_EQ(StarTermViolation(TermOf(r, 0, -reference, 0.0), r[0].data(), folded), 0.0);
  EXPECT_FALSE(folded);
  const double below[3] = { 0.0, 0.0, -0.25 };
  EXPECT_NEAR(StarTermViolation(TermOf(r, 0, -reference, 0.0), below, folded), 0.25, 1e-15);
  EXPECT_TRUE(folded);
}
