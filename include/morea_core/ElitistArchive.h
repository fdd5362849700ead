// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the elitist archive of MO-RV-GOMEA (SPEC 5):
// every feasible non-dominated solution found so far, up to a capacity kept by
// discretising objective space (Luong & Bosman 2012).
#ifndef morea_ElitistArchive_h
#define morea_ElitistArchive_h

#include "morea_core/ParetoFront.h"
#include "morea_core/TetrahedralMesh.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace morea_core
{
struct ArchiveEntry
{
  Fitness       fitness;  ///< always feasible
  DualMesh      solution;
  std::uint64_t id{ 0 };  ///< the optimiser's solution id, for the output files
};

/** What ElitistArchive::Judge() found about a fitness, for answering Accepts()
 *  on it later without a full scan. A default verdict knows nothing. */
struct ArchiveVerdict
{
  enum class Kind : std::uint8_t
  {
    Unknown,  ///< nothing known
    Rejected, ///< infeasible, non-finite, or an entry dominates or equals it
    Accepted, ///< Accepts() was true
    /** Refused only for sharing the grid cell of the witness, which it does
     *  not dominate: that holds while the witness stays and the grid is
     *  unchanged, and no longer (the witness can leave for a newcomer that
     *  does not dominate `f`). */
    Crowded
  };
  Kind          kind{ Kind::Unknown };
  std::uint64_t revision{ 0 };   ///< the archive's ThinningRevision() then
  std::uint64_t insertions{ 0 }; ///< entries inserted into the archive before then
  /** The entry that refused it (its insertion number), tried first when the
   *  verdict must be taken afresh: a hint, so it may also be left from a
   *  verdict on a similar fitness (with the kind set to Unknown). */
  std::uint64_t witness{ 0 };
};

class ElitistArchive
{
public:
  explicit ElitistArchive(std::size_t capacity);

  /** Whether `f` would enter: feasible, dominated by no entry and not equal in
   *  all objectives to one, and (when discretised) not in the grid cell of an
   *  entry it does not dominate. Not for concurrent calls (see m_RejectorHint). */
  bool
  Accepts(const Fitness & f) const;

  /** A verdict on `f` against the archive as it is now: Rejected exactly when
   *  `f` is infeasible or non-finite or an entry equals or dominates it,
   *  Accepted exactly when Accepts(f), else Crowded. Tries the entry `witness`
   *  (an earlier verdict's) first, a hint that does not change the verdict.
   *  Safe to call from several threads at once (while nothing changes the
   *  archive). */
  ArchiveVerdict
  Judge(const Fitness & f, std::uint64_t witness = 0) const;

  /** Accepts(f), answered from a verdict on the same `f` taken earlier (by
   *  Judge() or by this call), which it brings up to date. While the archive has
   *  since only gained entries and lost dominated ones (ThinningRevision()
   *  unchanged), a rejection still holds (a dominated entry leaves only for a
   *  newcomer that dominates it, and so `f` too), a crowding holds while its
   *  witness is here, and an acceptance needs a look at the newer entries
   *  only; otherwise this scans as Accepts(f) does.
   *  Not for concurrent calls. */
  bool
  Accepts(const Fitness & f, ArchiveVerdict & verdict) const;

  /** Inserts when Accepts(); removes the entries the new one dominates. When
   *  the size would exceed the capacity, objective space is discretised (cell
   *  widths from the entries' ranges) and entries sharing a cell are thinned,
   *  widening the cells until the size fits. Returns whether it was inserted. */
  bool
  Insert(const Fitness & f, const DualMesh & solution, std::uint64_t id);
  /** The same, deciding whether it enters by Accepts(f, verdict). */
  bool
  Insert(const Fitness & f, const DualMesh & solution, std::uint64_t id, ArchiveVerdict & verdict);

  /** Removes the entries for which `remove` returns true (adaptive steering). */
  void
  RemoveIf(const std::function<bool(const ArchiveEntry &)> & remove);

  /** Counts the changes after which a verdict must be taken afresh: thinning
   *  (with the grid's widths set anew), RemoveIf() and Restore(). Entries
   *  entering, and leaving for a newcomer that dominates them, do not count. */
  std::uint64_t
  ThinningRevision() const
  {
    return m_Revision;
  }

  const std::vector<ArchiveEntry> &
  Entries() const
  {
    return m_Entries;
  }
  std::size_t
  Size() const
  {
    return m_Entries.size();
  }
  std::size_t
  Capacity() const
  {
    return m_Capacity;
  }
  /** Objective vectors of all entries, in entry order. */
  std::vector<ObjectiveVector>
  Objectives() const;
  /** Insertion numbers of all entries, in entry order: each names its entry
   *  as a witness for Judge(). */
  std::vector<std::uint64_t>
  Witnesses() const;

  /** Discretisation state, so a checkpoint restores the archive exactly. */
  bool
  IsDiscretised() const
  {
    return m_Discretised;
  }
  const ObjectiveVector &
  CellWidths() const
  {
    return m_CellWidths;
  }
  /** Whether the entry with insertion number `serial` is still here. */
  bool
  Holds(std::uint64_t serial) const
  {
    return serial < m_Present.size() && m_Present[serial];
  }

  /** Restores a saved archive as it was (no checks beyond the capacity). */
  void
  Restore(std::vector<ArchiveEntry> entries, bool discretised, const ObjectiveVector & cellWidths);

private:
  class EntryTest;
  struct Refuser;
  struct Flagged;

  /** The first entry that `refuses`, trying entries `first` and `second`
   *  (hints; out of range for none) before all in order. */
  Refuser
  FindRefuser(const EntryTest & refuses, std::size_t first, std::size_t second) const;
  /** The first entry from `begin` on that `refuses`, as FindRefuser's scan. */
  Refuser
  FirstRefuserFrom(const EntryTest & refuses, std::size_t begin) const;
  /** The first entries from `begin` on that `refuses` rejects by dominance
   *  and that it refuses for their cell alone (Size() where none), scanning
   *  the columns block by block; with `stopAtRefuser`, only as far as the
   *  first refuser of either kind. */
  Flagged
  ScanColumns(const EntryTest & refuses, std::size_t begin, bool stopAtRefuser) const;
  /** The first entry from `begin` on that `f` dominates, or Size(). */
  std::size_t
  FirstDominatedBy(const ObjectiveVector & f, std::size_t begin) const;
  /** Appends an entry's objectives and cell to the columns. */
  void
  AppendColumns(const ObjectiveVector & objectives, const ObjectiveVector & cell);
  /** Records in `verdict` what a scan found. */
  void
  Settle(ArchiveVerdict & verdict, const Refuser & refuser) const;
  /** Index of the entry with insertion number `serial`, or Size(). */
  std::size_t
  IndexOf(std::uint64_t serial) const;
  /** Inserts `f`, known to be accepted now. */
  bool
  InsertAccepted(const Fitness & f, const DualMesh & solution, std::uint64_t id);
  /** Removes the entries for which keep[i] is false, in order; keep[i] is
   *  true for all i before `first`. Their meshes' buffers are kept for reuse. */
  void
  Compact(const std::vector<bool> & keep, std::size_t first = 0);
  /** Appends an entry and its key (the key's cell for the current grid). */
  void
  Append(const Fitness & f, const DualMesh & solution, std::uint64_t id);
  /** Sets every key's cell for the current grid. */
  void
  RefreshCells();

  std::size_t               m_Capacity;
  std::vector<ArchiveEntry> m_Entries;
  /** Per entry, in entry order, the entries inserted before it: ascending,
   *  so the entries newer than a verdict are a suffix. */
  std::vector<std::uint64_t> m_Serials;
  /** What the scans read of the entries, column by column in entry order and
   *  apart from the payloads: their objectives and grid cells (when
   *  discretised; kept so a scan need not divide). A scan tests blocks of
   *  entries without branches, in vector instructions. */
  std::array<std::vector<double>, NumberOfObjectives> m_ObjectiveColumns, m_CellColumns;
  std::vector<bool>         m_Present; ///< per insertion number: whether that entry is here
  /** Meshes of removed entries, whose buffers a newcomer's copy reuses: most
   *  newcomers soon leave for a better one, and a copy into buffers of the
   *  right size needs no allocation. */
  std::vector<DualMesh> m_SpareMeshes;
  std::uint64_t             m_Insertions{ 0 };
  std::uint64_t             m_Revision{ 0 };
  bool                      m_Discretised{ false };
  ObjectiveVector           m_CellWidths{ { 0.0, 0.0, 0.0 } };
  /** Index of the entry that last rejected a candidate; tried first (a
   *  speed-up only: any index gives the same answers). Not thread-safe. */
  mutable std::size_t m_RejectorHint{ 0 };
};
} // namespace morea_core

#endif
