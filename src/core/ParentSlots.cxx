// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/ParentSlots.h"

#include "morea_core/Error.h"

#include <algorithm>

namespace morea_core
{
ParentSlots::Assignment
ParentSlots::AssignFirst(const std::vector<std::uint64_t> & keys, std::size_t total)
{
  ++m_Batch;
  Assignment out;
  // Slots the batch needs: one per distinct nonzero key, one per key 0.
  // Counted on a sorted copy, without a hash set's allocation per key: this
  // runs as every batch starts, while the device waits.
  m_Scratch.assign(keys.begin(), keys.end());
  std::sort(m_Scratch.begin(), m_Scratch.end());
  const auto nonzero = std::upper_bound(m_Scratch.begin(), m_Scratch.end(), std::uint64_t{ 0 });
  const auto zeros = static_cast<std::size_t>(nonzero - m_Scratch.begin());
  const auto distinct = static_cast<std::size_t>(std::unique(nonzero, m_Scratch.end()) - nonzero);
  const std::size_t needed = std::max(zeros + distinct, total);
  if (needed > m_KeyOfSlot.size())
  {
    // A larger store starts empty (the device copy does not survive).
    const std::size_t capacity = std::max(needed, m_KeyOfSlot.size() + m_KeyOfSlot.size() / 4);
    m_SlotOfKey.clear();
    m_SlotOfKey.reserve(capacity); // never rehashed while the store keeps its size
    m_KeyOfSlot.assign(capacity, 0);
    m_BatchOfSlot.assign(capacity, 0);
    out.grown = true;
  }
  Place(keys, out);
  return out;
}

ParentSlots::Assignment
ParentSlots::AssignRest(const std::vector<std::uint64_t> & keys)
{
  if (m_Batch == 0)
    throw Error("parent slots: AssignRest needs an AssignFirst before it");
  Assignment out;
  Place(keys, out);
  return out;
}

void
ParentSlots::Place(const std::vector<std::uint64_t> & keys, Assignment & out)
{
  out.slot.assign(keys.size(), 0);
  out.capacity = m_KeyOfSlot.size();
  // Parents already held keep their slots; those are taken first.
  std::vector<bool> held(keys.size(), false);
  for (std::size_t i = 0; i < keys.size(); ++i)
  {
    if (keys[i] == 0)
      continue;
    const auto it = m_SlotOfKey.find(keys[i]);
    if (it == m_SlotOfKey.end())
      continue;
    out.slot[i] = it->second;
    m_BatchOfSlot[it->second] = m_Batch;
    held[i] = true;
  }
  // The others take slots this batch does not use, in ascending order.
  std::size_t next = 0;
  for (std::size_t i = 0; i < keys.size(); ++i)
  {
    if (held[i])
      continue;
    if (keys[i] != 0)
    {
      // A second parent with a key given a slot earlier in this batch.
      const auto it = m_SlotOfKey.find(keys[i]);
      if (it != m_SlotOfKey.end() && m_BatchOfSlot[it->second] == m_Batch)
      {
        out.slot[i] = it->second;
        continue;
      }
    }
    while (next < m_BatchOfSlot.size() && m_BatchOfSlot[next] == m_Batch)
      ++next;
    if (next == m_BatchOfSlot.size())
      throw Error("parent slots: the batch has more parents than its first part allowed for");
    const auto slot = static_cast<std::uint32_t>(next);
    if (m_KeyOfSlot[slot] != 0)
      m_SlotOfKey.erase(m_KeyOfSlot[slot]);
    m_KeyOfSlot[slot] = keys[i];
    if (keys[i] != 0)
      m_SlotOfKey[keys[i]] = slot;
    m_BatchOfSlot[slot] = m_Batch;
    out.slot[i] = slot;
    out.upload.push_back(i);
  }
}
} // namespace morea_core
