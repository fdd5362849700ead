// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: where a backend keeps the parents of
// partial candidates between batches. Successive batches of a generation
// share most of their parents (a batch changes the few solutions whose
// candidates it accepts), so a backend that keeps each parent's points under
// its key (PartialCandidate::parentKey) uploads only the parents it does not
// hold. This is the bookkeeping, in plain C++: which slot of the store each
// parent of a batch takes, and which parents must be uploaded.
#ifndef morea_ParentSlots_h
#define morea_ParentSlots_h

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace morea_core
{
class ParentSlots
{
public:
  struct Assignment
  {
    /** Per parent of the batch: its slot. Parents with one nonzero key share it. */
    std::vector<std::uint32_t> slot;
    /** The parents whose points must be uploaded into their slots, ascending;
     *  one per slot. */
    std::vector<std::size_t> upload;
    /** The store must hold this many slots; when it grew, every slot's
     *  contents are lost and all parents are in `upload`. */
    std::size_t capacity{ 0 };
    bool        grown{ false };
  };

  /** Slots for the parents of one batch, given their keys (0: kept for this
   *  batch only). A slot whose parent the batch does not name is reused. */
  Assignment
  Assign(const std::vector<std::uint64_t> & keys)
  {
    return AssignFirst(keys, 0);
  }

  /** Assign in two calls, for a batch whose later parents are not final
   *  yet: the first parents now, with room for `total` parents in all (the
   *  store grows here if it must); the others with AssignRest, which takes
   *  none of the first call's slots and never grows the store (slots
   *  uploaded after the first call stay valid). Throws morea_core::Error when
   *  the batch has more parents than `total` allowed for. */
  Assignment
  AssignFirst(const std::vector<std::uint64_t> & keys, std::size_t total);
  Assignment
  AssignRest(const std::vector<std::uint64_t> & keys);

  std::size_t
  Capacity() const
  {
    return m_KeyOfSlot.size();
  }

private:
  void
  Place(const std::vector<std::uint64_t> & keys, Assignment & out);

  std::unordered_map<std::uint64_t, std::uint32_t> m_SlotOfKey;
  std::vector<std::uint64_t>                       m_KeyOfSlot;   ///< 0: nothing kept
  std::vector<std::uint64_t>                       m_BatchOfSlot; ///< the last batch that used it
  std::uint64_t                                    m_Batch{ 0 };
  std::vector<std::uint64_t>                       m_Scratch; ///< AssignFirst's sorted keys
};
} // namespace morea_core

#endif
