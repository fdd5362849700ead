// MultiObjectiveRegistration core: the elitist archive of MO-RV-GOMEA (SPEC 5):
// every feasible non-dominated solution found so far, up to a capacity kept by
// discretising objective space (Luong & Bosman 2012).
#ifndef morea_ElitistArchive_h
#define morea_ElitistArchive_h

#include "morea/ParetoFront.h"
#include "morea/TetrahedralMesh.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace morea
{
struct ArchiveEntry
{
  Fitness       fitness;  ///< always feasible
  DualMesh      solution;
  std::uint64_t id{ 0 };  ///< the optimiser's solution id, for the output files
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

  /** Inserts when Accepts(); removes the entries the new one dominates. When
   *  the size would exceed the capacity, objective space is discretised (cell
   *  widths from the entries' ranges) and entries sharing a cell are thinned,
   *  widening the cells until the size fits. Returns whether it was inserted. */
  bool
  Insert(const Fitness & f, const DualMesh & solution, std::uint64_t id);

  /** Removes the entries for which `remove` returns true (adaptive steering). */
  void
  RemoveIf(const std::function<bool(const ArchiveEntry &)> & remove);

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
  /** Restores a saved archive as it was (no checks beyond the capacity). */
  void
  Restore(std::vector<ArchiveEntry> entries, bool discretised, const ObjectiveVector & cellWidths);

private:
  std::size_t               m_Capacity;
  std::vector<ArchiveEntry> m_Entries;
  bool                      m_Discretised{ false };
  ObjectiveVector           m_CellWidths{ { 0.0, 0.0, 0.0 } };
  /** Index of the entry that last rejected a candidate; tried first (a
   *  speed-up only: any index gives the same answers). Not thread-safe. */
  mutable std::size_t m_RejectorHint{ 0 };
};
} // namespace morea

#endif
