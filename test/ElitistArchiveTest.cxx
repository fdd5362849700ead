// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of morea_core::ElitistArchive: non-domination, the capacity kept by
// discretising objective space, checkpoint restore and the stored payload.
// Core tests: no ITK.
#include "morea_core/ElitistArchive.h"
#include "morea_core/Error.h"
#include "morea_core/Random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

namespace
{
using morea_core::ElitistArchive;
using morea_core::Fitness;
using morea_core::ObjectiveVector;

Fitness
Feasible(double a, double b, double c)
{
  return Fitness{ { { a, b, c } }, true, 0.0 };
}

/** A payload that tells which solution it belongs to. */
morea_core::DualMesh
PayloadOf(std::uint64_t id)
{
  const double x = static_cast<double>(id);
  return morea_core::DualMesh{ { { { x, x + 0.25, -x } }, { { 1.0, 2.0, 3.0 } } }, { { { -x, x * 2.0, 0.5 } } } };
}

/** The archive's grid convention (ElitistArchive.cxx): cells centred on
 *  multiples of the width; a width of 0 leaves the objective out. */
std::array<double, 3>
CellOf(const ObjectiveVector & x, const ObjectiveVector & widths)
{
  std::array<double, 3> cell{};
  for (int j = 0; j < 3; ++j)
    cell[j] = widths[j] > 0.0 ? std::floor(x[j] / widths[j] + 0.5) : 0.0;
  return cell;
}

/** Squared distance from the cell's lower corner, in cell widths. */
double
DistanceToCellCorner(const ObjectiveVector & x, const ObjectiveVector & widths)
{
  const auto cell = CellOf(x, widths);
  double     d = 0.0;
  for (int j = 0; j < 3; ++j)
    if (widths[j] > 0.0)
      d += std::pow(x[j] / widths[j] + 0.5 - cell[j], 2);
  return d;
}

/** A random candidate at progress t in [0, 1). Mostly on the surface
 *  x * y * z = 1 (shifted by `shift`), whose points are all mutually
 *  non-dominated, over a patch that grows with t, so the archive keeps
 *  overflowing and being re-discretised; the rest a little behind the surface
 *  (mostly dominated); some infeasible. */
Fitness
RandomCandidate(morea_core::RandomGenerator & random, double t, double shift)
{
  const double radius = 0.1 + 1.4 * t; // in log space
  const double u = random.Uniform(-radius, radius);
  const double v = random.Uniform(-radius, radius);
  Fitness      f;
  f.objectives = { { std::exp(u) + shift, std::exp(v) + shift, std::exp(-u - v) + shift } };
  if (random.Uniform() < 0.3)
    for (double & x : f.objectives)
      x += random.Uniform(0.0, 0.3);
  if (random.Uniform() < 0.1)
  {
    f.feasible = false;
    f.constraint = random.Uniform();
  }
  return f;
}

void
ExpectMutuallyNonDominated(const ElitistArchive & archive)
{
  const auto & entries = archive.Entries();
  for (std::size_t i = 0; i < entries.size(); ++i)
  {
    ASSERT_TRUE(entries[i].fitness.feasible);
    for (std::size_t k = 0; k < entries.size(); ++k)
      if (i != k)
      {
        ASSERT_FALSE(morea_core::Dominates(entries[i].fitness.objectives, entries[k].fitness.objectives)) << i << " " << k;
        ASSERT_NE(entries[i].fitness.objectives, entries[k].fitness.objectives) << i << " " << k;
      }
  }
}

void
ExpectOnePerCell(const ElitistArchive & archive)
{
  if (!archive.IsDiscretised())
    return;
  std::set<std::array<double, 3>> cells;
  for (const auto & e : archive.Entries())
    ASSERT_TRUE(cells.insert(CellOf(e.fitness.objectives, archive.CellWidths())).second);
}

/** Inserts `count` random candidates, checking the archive's promises after
 *  each. Candidate i gets id i. */
void
InsertRandomly(ElitistArchive & archive, std::size_t count, std::uint64_t seed, double shift)
{
  morea_core::RandomGenerator random(seed);
  std::vector<Fitness>   candidates;
  for (std::uint64_t id = 0; id < count; ++id)
  {
    const Fitness f = RandomCandidate(random, static_cast<double>(id) / static_cast<double>(count), shift);
    candidates.push_back(f);
    const std::vector<morea_core::ArchiveEntry> before = archive.Entries();
    const std::vector<std::uint64_t>       witnessesBefore = archive.Witnesses();
    const bool                            accepted = archive.Accepts(f);
    const bool                            inserted = archive.Insert(f, PayloadOf(id), id);
    ASSERT_LE(archive.Size(), archive.Capacity());
    // Holds() tells exactly the entries here by their insertion numbers.
    const std::vector<std::uint64_t> witnesses = archive.Witnesses();
    for (std::uint64_t w : witnesses)
      ASSERT_TRUE(archive.Holds(w)) << id;
    for (std::uint64_t w : witnessesBefore)
      ASSERT_EQ(archive.Holds(w), std::find(witnesses.begin(), witnesses.end(), w) != witnesses.end()) << id;
    const auto & entries = archive.Entries();
    const auto   find = [&](std::uint64_t wanted) {
      return std::find_if(entries.begin(), entries.end(), [&](const auto & e) { return e.id == wanted; });
    };
    ASSERT_EQ(inserted, find(id) != entries.end()) << id;
    // An entry leaves only when the newcomer dominates it, or when thinned out
    // for a kept entry in its cell that lies no farther from the cell's corner.
    std::vector<ObjectiveVector> dropped;
    for (const auto & b : before)
      if (find(b.id) == entries.end() && !morea_core::Dominates(f.objectives, b.fitness.objectives))
        dropped.push_back(b.fitness.objectives);
    if (accepted && !inserted) // thinned out at once
      dropped.push_back(f.objectives);
    for (const ObjectiveVector & x : dropped)
    {
      ASSERT_TRUE(archive.IsDiscretised()) << id;
      const ObjectiveVector & widths = archive.CellWidths();
      const auto              keeper = std::find_if(entries.begin(), entries.end(), [&](const auto & e) {
        return CellOf(e.fitness.objectives, widths) == CellOf(x, widths);
      });
      ASSERT_NE(keeper, entries.end()) << id;
      if (!morea_core::Dominates(keeper->fitness.objectives, x))
      {
        ASSERT_LE(DistanceToCellCorner(keeper->fitness.objectives, widths), DistanceToCellCorner(x, widths)) << id;
      }
    }
    // Every entry is the candidate of its id, with its payload intact (entries
    // move around when the archive is thinned).
    for (const auto & e : entries)
    {
      ASSERT_LT(e.id, candidates.size());
      ASSERT_EQ(e.fitness.objectives, candidates[e.id].objectives) << id;
      ASSERT_EQ(e.solution.source, PayloadOf(e.id).source) << id;
      ASSERT_EQ(e.solution.target, PayloadOf(e.id).target) << id;
    }
    if (!f.feasible)
      ASSERT_FALSE(inserted) << id;
    else if (!inserted)
    {
      // Rejected (or thinned out at once): dominated by or equal to an entry,
      // or, when discretised, sharing a cell with one.
      const bool covered = std::any_of(entries.begin(), entries.end(), [&](const auto & e) {
        const ObjectiveVector & y = e.fitness.objectives;
        return y == f.objectives || morea_core::Dominates(y, f.objectives) ||
               (archive.IsDiscretised() &&
                CellOf(y, archive.CellWidths()) == CellOf(f.objectives, archive.CellWidths()));
      });
      ASSERT_TRUE(covered) << id;
      ASSERT_FALSE(archive.Accepts(f)) << id;
    }
    if (id % 250 == 0 || id + 1 == count)
    {
      ExpectMutuallyNonDominated(archive);
      ExpectOnePerCell(archive);
    }
  }
}
} // namespace

TEST(ElitistArchive, RejectsZeroCapacity)
{
  EXPECT_THROW(ElitistArchive(0), morea_core::Error);
}

TEST(ElitistArchive, InfeasibleNeverEnters)
{
  ElitistArchive archive(10);
  Fitness        f = Feasible(0, 0, 0);
  f.feasible = false;
  f.constraint = 0.0;
  EXPECT_FALSE(archive.Accepts(f));
  EXPECT_FALSE(archive.Insert(f, PayloadOf(1), 1));
  EXPECT_EQ(archive.Size(), 0u);
  EXPECT_TRUE(archive.Insert(Feasible(5, 5, 5), PayloadOf(2), 2));
  // An infeasible solution that would dominate the entry does not replace it.
  EXPECT_FALSE(archive.Insert(f, PayloadOf(3), 3));
  ASSERT_EQ(archive.Size(), 1u);
  EXPECT_EQ(archive.Entries()[0].id, 2u);
}

TEST(ElitistArchive, DominatingPointRemovesDominatedOnes)
{
  ElitistArchive archive(10);
  EXPECT_TRUE(archive.Insert(Feasible(2, 2, 2), PayloadOf(0), 0));
  EXPECT_TRUE(archive.Insert(Feasible(1, 3, 3), PayloadOf(1), 1));
  EXPECT_TRUE(archive.Insert(Feasible(3, 1, 3), PayloadOf(2), 2));
  EXPECT_TRUE(archive.Insert(Feasible(3, 3, 1), PayloadOf(3), 3));
  EXPECT_TRUE(archive.Insert(Feasible(0, 9, 9), PayloadOf(4), 4));
  EXPECT_EQ(archive.Size(), 5u);
  // Dominated and equal candidates are refused.
  EXPECT_FALSE(archive.Accepts(Feasible(2, 2, 3)));
  EXPECT_FALSE(archive.Insert(Feasible(2, 2, 2), PayloadOf(5), 5));
  EXPECT_FALSE(archive.Insert(Feasible(1, 9, 9), PayloadOf(6), 6));
  EXPECT_EQ(archive.Size(), 5u);
  // (1, 1, 1) dominates all but (0, 9, 9).
  EXPECT_TRUE(archive.Accepts(Feasible(1, 1, 1)));
  EXPECT_TRUE(archive.Insert(Feasible(1, 1, 1), PayloadOf(7), 7));
  ASSERT_EQ(archive.Size(), 2u);
  EXPECT_EQ(archive.Entries()[0].id, 4u);
  EXPECT_EQ(archive.Entries()[1].id, 7u);
  EXPECT_EQ(archive.Objectives(), (std::vector<ObjectiveVector>{ { { 0, 9, 9 } }, { { 1, 1, 1 } } }));
  EXPECT_FALSE(archive.IsDiscretised());
}

TEST(ElitistArchive, StoresThePayloadIntact)
{
  ElitistArchive        archive(10);
  const morea_core::DualMesh solution{ { { { 1.5, -2.0, 3.25 } }, { { 4, 5, 6 } }, { { 7, 8, 9 } } },
                                  { { { 0.1, 0.2, 0.3 } }, { { -4, -5, -6 } }, { { 1e9, -1e-9, 0 } } } };
  const Fitness         f = Feasible(1, 2, 3);
  ASSERT_TRUE(archive.Insert(f, solution, 123456789012345ULL));
  // More entries around it, so the vector reallocates and entries move.
  for (std::uint64_t id = 0; id < 8; ++id)
    archive.Insert(Feasible(2.0 + static_cast<double>(id), 1.0 - 0.1 * static_cast<double>(id), 3.0), PayloadOf(id), id);
  const auto & entries = archive.Entries();
  const auto   it = std::find_if(entries.begin(), entries.end(), [](const auto & e) { return e.id == 123456789012345ULL; });
  ASSERT_NE(it, entries.end());
  EXPECT_EQ(it->solution.source, solution.source);
  EXPECT_EQ(it->solution.target, solution.target);
  EXPECT_EQ(it->fitness.objectives, f.objectives);
  EXPECT_TRUE(it->fitness.feasible);
}

TEST(ElitistArchive, RandomInsertionsKeepTheArchiveSound)
{
  ElitistArchive archive(200);
  InsertRandomly(archive, 5000, 42, 0.0);
  // The run must have exercised the discretised mode, and thinning must not
  // have gutted the archive.
  EXPECT_TRUE(archive.IsDiscretised());
  EXPECT_GT(archive.Size(), archive.Capacity() / 2);
}

TEST(ElitistArchive, SmallCapacitiesWithNegativeObjectivesFit)
{
  // Objective values of both signs: cells must merge them.
  for (std::size_t capacity : { 1, 2, 3, 7 })
  {
    ElitistArchive archive(capacity);
    InsertRandomly(archive, 600, 100 + capacity, -1.5);
    EXPECT_TRUE(archive.IsDiscretised()) << capacity;
    EXPECT_GE(archive.Size(), 1u);
  }
}

TEST(ElitistArchive, OverflowSetsWidthsFromTheRange)
{
  // Five points on a line in objectives 0 and 1, objective 2 constant:
  // widths start at range / sqrt(4) = 0.8 / 2 and only grow by factors of 1.1.
  ElitistArchive archive(4);
  for (std::uint64_t i = 0; i < 5; ++i)
  {
    const double x = 0.1 + 0.2 * static_cast<double>(i);
    EXPECT_TRUE(archive.Insert(Feasible(x, 1.0 - x, 7.0), PayloadOf(i), i) || i == 4);
  }
  ASSERT_TRUE(archive.IsDiscretised());
  EXPECT_LE(archive.Size(), 4u);
  const ObjectiveVector widths = archive.CellWidths();
  EXPECT_EQ(widths[2], 0.0);
  EXPECT_NEAR(widths[0], widths[1], 1e-12);
  const double steps = std::log(widths[0] / 0.4) / std::log(1.1);
  EXPECT_GE(steps, -1e-9);
  EXPECT_NEAR(steps, std::round(steps), 1e-6);
  ExpectMutuallyNonDominated(archive);
  ExpectOnePerCell(archive);
}

TEST(ElitistArchive, DiscretisedCellAdmitsOnlyADominatingNewcomer)
{
  // Widths so wide that all these points share one cell.
  ElitistArchive archive(10);
  archive.Restore({ morea_core::ArchiveEntry{ Feasible(0.2, 0.6, 0.5), PayloadOf(1), 1 } }, true, { { 1000, 1000, 1000 } });
  // Non-dominated but in the occupied cell without dominating its entry: refused.
  EXPECT_FALSE(archive.Accepts(Feasible(0.3, 0.5, 0.5)));
  EXPECT_FALSE(archive.Insert(Feasible(0.3, 0.5, 0.5), PayloadOf(2), 2));
  // Dominating the entry: it replaces it.
  EXPECT_TRUE(archive.Insert(Feasible(0.1, 0.5, 0.5), PayloadOf(3), 3));
  ASSERT_EQ(archive.Size(), 1u);
  EXPECT_EQ(archive.Entries()[0].id, 3u);
  // A point in another cell enters freely.
  EXPECT_TRUE(archive.Insert(Feasible(-2000, 5000, 0.5), PayloadOf(4), 4));
  EXPECT_EQ(archive.Size(), 2u);
}

TEST(ElitistArchive, RestoreRoundTrip)
{
  ElitistArchive original(150);
  InsertRandomly(original, 3000, 9, 0.0);
  ASSERT_TRUE(original.IsDiscretised());

  ElitistArchive restored(150);
  restored.Restore(original.Entries(), original.IsDiscretised(), original.CellWidths());
  EXPECT_EQ(restored.IsDiscretised(), original.IsDiscretised());
  EXPECT_EQ(restored.CellWidths(), original.CellWidths());
  ASSERT_EQ(restored.Size(), original.Size());
  for (std::size_t i = 0; i < original.Size(); ++i)
  {
    EXPECT_EQ(restored.Entries()[i].id, original.Entries()[i].id);
    EXPECT_EQ(restored.Entries()[i].fitness.objectives, original.Entries()[i].fitness.objectives);
    EXPECT_EQ(restored.Entries()[i].solution.source, original.Entries()[i].solution.source);
    EXPECT_EQ(restored.Entries()[i].solution.target, original.Entries()[i].solution.target);
  }
  // Both answer and evolve alike.
  morea_core::RandomGenerator random(77);
  std::size_t            accepted = 0;
  for (std::uint64_t id = 0; id < 2000; ++id)
  {
    const Fitness f = RandomCandidate(random, 1.0 + static_cast<double>(id) / 4000.0, 0.0);
    ASSERT_EQ(restored.Accepts(f), original.Accepts(f)) << id;
    accepted += original.Accepts(f);
    ASSERT_EQ(restored.Insert(f, PayloadOf(id), id), original.Insert(f, PayloadOf(id), id)) << id;
  }
  EXPECT_GT(accepted, 0u);
  EXPECT_EQ(restored.Objectives(), original.Objectives());
  EXPECT_EQ(restored.CellWidths(), original.CellWidths());

  ElitistArchive tooSmall(original.Size() - 1);
  EXPECT_THROW(tooSmall.Restore(original.Entries(), true, original.CellWidths()), morea_core::Error);
}

TEST(ElitistArchive, RemoveIf)
{
  ElitistArchive archive(10);
  for (std::uint64_t i = 0; i < 5; ++i)
    archive.Insert(Feasible(static_cast<double>(i), 4.0 - static_cast<double>(i), 0.0), PayloadOf(i), i);
  archive.RemoveIf([](const morea_core::ArchiveEntry & e) { return e.fitness.objectives[0] >= 2.5; });
  ASSERT_EQ(archive.Size(), 3u);
  for (std::uint64_t i = 0; i < 3; ++i)
  {
    EXPECT_EQ(archive.Entries()[i].id, i);
    EXPECT_EQ(archive.Entries()[i].solution.source, PayloadOf(i).source);
  }
  // A removed point may come back.
  EXPECT_TRUE(archive.Insert(Feasible(3.0, 1.0, 0.0), PayloadOf(3), 3));
}

namespace
{
/** What a verdict of kind Rejected claims: `f` is infeasible or non-finite, or
 *  an entry equals or dominates it. */
bool
RejectedByDominance(const ElitistArchive & archive, const Fitness & f)
{
  if (!f.feasible || !std::all_of(f.objectives.begin(), f.objectives.end(), [](double x) { return std::isfinite(x); }))
    return true;
  return std::any_of(archive.Entries().begin(), archive.Entries().end(), [&](const morea_core::ArchiveEntry & e) {
    return e.fitness.objectives == f.objectives || morea_core::Dominates(e.fitness.objectives, f.objectives);
  });
}

/** Probes for verdicts: random candidates (some equal to an entry, some
 *  non-finite). */
Fitness
RandomProbe(morea_core::RandomGenerator & random, const ElitistArchive & archive)
{
  const double u = random.Uniform();
  if (u < 0.05 && archive.Size() > 0)
    return archive.Entries()[static_cast<std::size_t>(random.Uniform() * static_cast<double>(archive.Size()))].fitness;
  Fitness f = RandomCandidate(random, random.Uniform(), 0.0);
  if (u > 0.99)
    f.objectives[1] = u > 0.995 ? std::nan("") : std::numeric_limits<double>::infinity();
  return f;
}

ElitistArchive
FilledArchive(std::size_t capacity, std::size_t insertions, std::uint64_t seed)
{
  ElitistArchive         archive(capacity);
  morea_core::RandomGenerator random(seed);
  for (std::uint64_t id = 0; id < insertions; ++id)
    archive.Insert(RandomCandidate(random, static_cast<double>(id) / static_cast<double>(insertions), 0.0),
                   PayloadOf(id), id);
  return archive;
}
} // namespace

TEST(ElitistArchive, JudgeAgreesWithAFullScan)
{
  // Never thinned, and discretised.
  for (std::size_t capacity : { 100000, 60 })
  {
    const ElitistArchive archive = FilledArchive(capacity, 1500, 5 + capacity);
    ASSERT_EQ(archive.IsDiscretised(), capacity == 60);
    morea_core::RandomGenerator random(11);
    std::size_t            kinds[4] = {};
    morea_core::ArchiveVerdict  previous;
    for (int i = 0; i < 4000; ++i)
    {
      const Fitness               f = RandomProbe(random, archive);
      const morea_core::ArchiveVerdict verdict = archive.Judge(f);
      const bool                  accepts = archive.Accepts(f);
      ++kinds[static_cast<int>(verdict.kind)];
      EXPECT_EQ(verdict.kind == morea_core::ArchiveVerdict::Kind::Accepted, accepts) << i;
      EXPECT_EQ(verdict.kind == morea_core::ArchiveVerdict::Kind::Rejected, RejectedByDominance(archive, f)) << i;
      EXPECT_NE(verdict.kind, morea_core::ArchiveVerdict::Kind::Unknown) << i;
      if (verdict.kind == morea_core::ArchiveVerdict::Kind::Crowded)
      {
        // Refused by the cell of an entry here, which it does not dominate.
        EXPECT_TRUE(archive.IsDiscretised()) << i;
        ASSERT_TRUE(archive.Holds(verdict.witness)) << i;
        const auto witnesses = archive.Witnesses();
        const auto & holder = archive.Entries()[static_cast<std::size_t>(
          std::find(witnesses.begin(), witnesses.end(), verdict.witness) - witnesses.begin())];
        EXPECT_EQ(CellOf(holder.fitness.objectives, archive.CellWidths()), CellOf(f.objectives, archive.CellWidths()))
          << i;
        EXPECT_FALSE(morea_core::Dominates(f.objectives, holder.fitness.objectives)) << i;
        morea_core::ArchiveVerdict copy = verdict;
        EXPECT_FALSE(archive.Accepts(f, copy)) << i;
      }
      EXPECT_EQ(verdict.revision, archive.ThinningRevision());
      // A witness is only a hint: any one, or none, gives the same verdict.
      EXPECT_EQ(archive.Judge(f, previous.witness).kind, verdict.kind) << i;
      EXPECT_EQ(archive.Judge(f, random.NextU64() % 2000).kind, verdict.kind) << i;
      // So does Accepts() from a verdict that knows nothing, or only a witness.
      morea_core::ArchiveVerdict blank;
      EXPECT_EQ(archive.Accepts(f, blank), accepts) << i;
      morea_core::ArchiveVerdict hinted = previous;
      hinted.kind = morea_core::ArchiveVerdict::Kind::Unknown;
      EXPECT_EQ(archive.Accepts(f, hinted), accepts) << i;
      previous = verdict;
    }
    // All kinds came up (Crowded only with a grid).
    EXPECT_GT(kinds[static_cast<int>(morea_core::ArchiveVerdict::Kind::Rejected)], 100u) << capacity;
    EXPECT_GT(kinds[static_cast<int>(morea_core::ArchiveVerdict::Kind::Accepted)], 100u) << capacity;
    EXPECT_EQ(kinds[static_cast<int>(morea_core::ArchiveVerdict::Kind::Crowded)] > 0, archive.IsDiscretised()) << capacity;
  }
}

TEST(ElitistArchive, JudgeNamesTheFirstRefusingEntry)
{
  // The scans test entries in blocks; the witness must still be the first
  // entry, in entry order, that refuses: by dominance anywhere, else (with a
  // grid) the first that crowds. Every archive size leaves another tail.
  for (std::size_t capacity : { 100000, 60 })
    for (std::size_t insertions : { 7, 300, 1500 })
    {
      const ElitistArchive archive = FilledArchive(capacity, insertions, 3 + capacity + insertions);
      const auto           witnesses = archive.Witnesses();
      const auto &         entries = archive.Entries();
      morea_core::RandomGenerator random(insertions);
      std::size_t            checked = 0;
      for (int i = 0; i < 2000; ++i)
      {
        const Fitness f = RandomProbe(random, archive);
        if (!f.feasible ||
            !std::all_of(f.objectives.begin(), f.objectives.end(), [](double x) { return std::isfinite(x); }))
          continue;
        std::size_t dominance = entries.size(), crowding = entries.size();
        for (std::size_t e = 0; e < entries.size() && dominance == entries.size(); ++e)
        {
          const ObjectiveVector & y = entries[e].fitness.objectives;
          if (y == f.objectives || morea_core::Dominates(y, f.objectives))
            dominance = e;
          else if (crowding == entries.size() && archive.IsDiscretised() &&
                   CellOf(y, archive.CellWidths()) == CellOf(f.objectives, archive.CellWidths()) &&
                   !morea_core::Dominates(f.objectives, y))
            crowding = e;
        }
        // A witness no entry has: no hint.
        const morea_core::ArchiveVerdict verdict = archive.Judge(f, std::numeric_limits<std::uint64_t>::max());
        if (dominance < entries.size())
        {
          ASSERT_EQ(verdict.kind, morea_core::ArchiveVerdict::Kind::Rejected) << i;
          ASSERT_EQ(verdict.witness, witnesses[dominance]) << i;
        }
        else if (crowding < entries.size())
        {
          ASSERT_EQ(verdict.kind, morea_core::ArchiveVerdict::Kind::Crowded) << i;
          ASSERT_EQ(verdict.witness, witnesses[crowding]) << i;
        }
        else
          ASSERT_EQ(verdict.kind, morea_core::ArchiveVerdict::Kind::Accepted) << i;
        ++checked;
      }
      EXPECT_GT(checked, 1500u);
    }
}

TEST(ElitistArchive, RestoreRefusesNonFiniteObjectives)
{
  ElitistArchive original(100);
  InsertRandomly(original, 50, 2, 0.0);
  std::vector<morea_core::ArchiveEntry> entries = original.Entries();
  ASSERT_FALSE(entries.empty());
  entries.back().fitness.objectives[2] = std::numeric_limits<double>::quiet_NaN();
  ElitistArchive restored(100);
  EXPECT_THROW(restored.Restore(entries, false, ObjectiveVector{ 0.0, 0.0, 0.0 }), morea_core::Error);
  EXPECT_EQ(restored.Size(), 0u); // nothing half-restored
}

TEST(ElitistArchive, RejectionsByDominanceOutlastInsertionsWithoutThinning)
{
  // Capacity never reached: entries leave only for a newcomer that dominates
  // them, which then dominates what they dominated.
  ElitistArchive                     archive = FilledArchive(100000, 300, 3);
  const std::uint64_t                revision = archive.ThinningRevision();
  morea_core::RandomGenerator             random(4);
  std::vector<Fitness>               probes;
  std::vector<morea_core::ArchiveVerdict> verdicts;
  for (int i = 0; i < 1500; ++i)
  {
    probes.push_back(RandomProbe(random, archive));
    verdicts.push_back(archive.Judge(probes.back()));
  }
  // For the rejected probes: the entries that then equalled or dominated them.
  std::vector<std::vector<std::uint64_t>> coveredBy(probes.size());
  for (std::size_t i = 0; i < probes.size(); ++i)
    if (verdicts[i].kind == morea_core::ArchiveVerdict::Kind::Rejected)
      for (const auto & e : archive.Entries())
        if (e.fitness.objectives == probes[i].objectives || morea_core::Dominates(e.fitness.objectives, probes[i].objectives))
          coveredBy[i].push_back(e.id);

  std::vector<morea_core::ArchiveVerdict> live = verdicts; // brought up to date on every call
  std::size_t                        removed = 0;
  for (std::uint64_t id = 1000; id < 2500; ++id)
  {
    // Candidates that move the front on, so entries keep being dominated away.
    Fitness f = RandomCandidate(random, 0.3 + 0.7 * static_cast<double>(id - 1000) / 1500.0, 0.0);
    for (double & x : f.objectives)
      x *= 1.0 - 0.05 * static_cast<double>(id - 1000) / 1500.0;
    const std::size_t before = archive.Size();
    const bool        inserted = archive.Insert(f, PayloadOf(id), id);
    removed += before + (inserted ? 1 : 0) - archive.Size();
    ASSERT_EQ(archive.ThinningRevision(), revision);
    for (int k = 0; k < 25; ++k)
    {
      const std::size_t i = static_cast<std::size_t>(random.Uniform() * static_cast<double>(probes.size()));
      const bool        accepts = archive.Accepts(probes[i]);
      if (verdicts[i].kind == morea_core::ArchiveVerdict::Kind::Rejected)
        ASSERT_FALSE(accepts) << id << " " << i;
      morea_core::ArchiveVerdict snapshot = verdicts[i];
      ASSERT_EQ(archive.Accepts(probes[i], snapshot), accepts) << id << " " << i;
      ASSERT_EQ(archive.Accepts(probes[i], live[i]), accepts) << id << " " << i;
    }
  }
  ASSERT_FALSE(archive.IsDiscretised());
  EXPECT_GT(removed, 100u);
  // Rejections that outlived every entry that made them: the newcomers
  // dominating those entries carried them.
  std::size_t outlived = 0;
  for (std::size_t i = 0; i < probes.size(); ++i)
    if (!coveredBy[i].empty() && std::none_of(coveredBy[i].begin(), coveredBy[i].end(), [&](std::uint64_t id) {
          return std::any_of(archive.Entries().begin(), archive.Entries().end(),
                             [&](const morea_core::ArchiveEntry & e) { return e.id == id; });
        }))
    {
      ++outlived;
      EXPECT_FALSE(archive.Accepts(probes[i])) << i;
      EXPECT_TRUE(RejectedByDominance(archive, probes[i])) << i;
    }
  EXPECT_GT(outlived, 10u);
}

TEST(ElitistArchive, ThinningRevisionCountsThinningRemovalAndRestore)
{
  ElitistArchive         archive(20);
  morea_core::RandomGenerator random(8);
  std::size_t            thinnings = 0, quiet = 0;
  for (std::uint64_t id = 0; id < 1500; ++id)
  {
    const Fitness       f = RandomCandidate(random, static_cast<double>(id) / 1500.0, 0.0);
    const std::uint64_t revision = archive.ThinningRevision();
    const auto          before = archive.Entries();
    const bool          accepts = archive.Accepts(f);
    std::size_t         dominated = 0;
    for (const auto & e : before)
      dominated += accepts && morea_core::Dominates(f.objectives, e.fitness.objectives);
    archive.Insert(f, PayloadOf(id), id);
    // Thinned exactly when the newcomer would overfill the archive.
    const bool overfull = accepts && before.size() - dominated + 1 > archive.Capacity();
    EXPECT_EQ(archive.ThinningRevision(), revision + (overfull ? 1 : 0)) << id;
    if (overfull)
    {
      ++thinnings;
      EXPECT_TRUE(archive.IsDiscretised()) << id;
    }
    else
    {
      // Nothing thinned: the entries are the old ones less the dominated, plus the newcomer.
      ++quiet;
      std::vector<ObjectiveVector> expected;
      for (const auto & e : before)
        if (!accepts || !morea_core::Dominates(f.objectives, e.fitness.objectives))
          expected.push_back(e.fitness.objectives);
      if (accepts)
        expected.push_back(f.objectives);
      ASSERT_EQ(archive.Objectives(), expected) << id;
    }
  }
  EXPECT_GT(thinnings, 10u);
  EXPECT_GT(quiet, 100u);

  std::uint64_t revision = archive.ThinningRevision();
  archive.RemoveIf([](const morea_core::ArchiveEntry & e) { return e.id % 2 == 0; });
  EXPECT_EQ(archive.ThinningRevision(), ++revision);
  archive.Restore(archive.Entries(), archive.IsDiscretised(), archive.CellWidths());
  EXPECT_EQ(archive.ThinningRevision(), ++revision);
}

TEST(ElitistArchive, VerdictsGiveTheAnswersOfFullScans)
{
  // Two archives fed alike, one asked by full scans, the other through
  // verdicts taken at the start of each batch (as the optimiser does): the
  // same answers and the same contents throughout, with and without thinning,
  // steering removals and restores.
  for (std::size_t capacity : { 100000, 40 })
  {
    ElitistArchive         plain(capacity), judged(capacity);
    morea_core::RandomGenerator random(21 + capacity);
    std::uint64_t          id = 0;
    std::size_t            viaVerdicts = 0;
    for (int batch = 0; batch < 40; ++batch)
    {
      std::vector<Fitness> batchFitness;
      for (int k = 0; k < 150; ++k)
        batchFitness.push_back(RandomCandidate(random, static_cast<double>(batch) / 40.0, 0.0));
      std::vector<morea_core::ArchiveVerdict> verdicts;
      std::uint64_t                      witness = 0;
      for (const Fitness & f : batchFitness)
      {
        verdicts.push_back(judged.Judge(f, witness));
        witness = verdicts.back().witness;
      }
      const std::uint64_t revision = judged.ThinningRevision();
      for (std::size_t b = 0; b < batchFitness.size(); ++b)
      {
        // Steering's removals, and restores, in mid-batch: the verdicts before
        // them go stale.
        if (b == batchFitness.size() / 2 && batch % 5 == 4)
        {
          const double limit = 1.2 + random.Uniform();
          auto         steer = [limit](const morea_core::ArchiveEntry & e) { return e.fitness.objectives[2] > limit; };
          plain.RemoveIf(steer);
          judged.RemoveIf(steer);
        }
        if (b == batchFitness.size() / 2 && batch % 5 == 2)
          judged.Restore(judged.Entries(), judged.IsDiscretised(), judged.CellWidths());
        Fitness f = batchFitness[b];
        if (random.Uniform() < 0.2)
        {
          // Its solution changed since: the verdict is on another fitness.
          f.objectives[0] *= 0.999;
          verdicts[b].kind = morea_core::ArchiveVerdict::Kind::Unknown;
        }
        viaVerdicts += verdicts[b].kind != morea_core::ArchiveVerdict::Kind::Unknown && judged.ThinningRevision() == revision;
        const bool accepts = plain.Accepts(f);
        ASSERT_EQ(judged.Accepts(f, verdicts[b]), accepts) << capacity << " " << batch << " " << b;
        // Inserted when accepted, or (like a candidate that dominates its
        // parent) regardless, for Insert to decide.
        if (accepts || random.Uniform() < 0.3)
        {
          ASSERT_EQ(judged.Insert(f, PayloadOf(id), id, verdicts[b]), plain.Insert(f, PayloadOf(id), id))
            << capacity << " " << batch << " " << b;
          ++id;
        }
      }
      ASSERT_EQ(judged.Objectives(), plain.Objectives()) << capacity << " " << batch;
      ASSERT_EQ(judged.IsDiscretised(), plain.IsDiscretised()) << capacity << " " << batch;
      ASSERT_EQ(judged.CellWidths(), plain.CellWidths()) << capacity << " " << batch;
      for (std::size_t i = 0; i < plain.Size(); ++i)
        ASSERT_EQ(judged.Entries()[i].id, plain.Entries()[i].id) << capacity << " " << batch;
    }
    EXPECT_EQ(plain.IsDiscretised(), capacity == 40);
    // Thinning makes the verdicts of the rest of a batch stale.
    EXPECT_GT(viaVerdicts, capacity == 40 ? 200u : 3000u) << capacity;
  }
}
