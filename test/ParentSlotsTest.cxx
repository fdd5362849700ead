// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The parent store's bookkeeping: held parents are not uploaded again, slots
// of parents a batch does not name are reused, equal keys share a slot.
#include "morea_core/ParentSlots.h"

#include "morea_core/Error.h"

#include <gtest/gtest.h>

#include <set>

namespace
{
using morea_core::ParentSlots;

TEST(ParentSlots, FirstBatchUploadsEveryParentIntoItsOwnSlot)
{
  ParentSlots           slots;
  const auto            a = slots.Assign({ 11, 12, 13 });
  EXPECT_TRUE(a.grown);
  EXPECT_EQ(a.capacity, 3u);
  EXPECT_EQ(a.upload, (std::vector<std::size_t>{ 0, 1, 2 }));
  EXPECT_EQ(std::set<std::uint32_t>(a.slot.begin(), a.slot.end()).size(), 3u);
}

TEST(ParentSlots, HeldParentsKeepTheirSlotsAndAreNotUploaded)
{
  ParentSlots slots;
  const auto  first = slots.Assign({ 11, 12, 13 });
  const auto  second = slots.Assign({ 13, 11, 12 });
  EXPECT_FALSE(second.grown);
  EXPECT_TRUE(second.upload.empty());
  EXPECT_EQ(second.slot[0], first.slot[2]);
  EXPECT_EQ(second.slot[1], first.slot[0]);
  EXPECT_EQ(second.slot[2], first.slot[1]);
}

TEST(ParentSlots, AChangedParentTakesTheSlotOfOneTheBatchDoesNotName)
{
  ParentSlots slots;
  const auto  first = slots.Assign({ 11, 12, 13 });
  // Solution 12 changed: its new key 14 needs a slot; 12's is the only free one.
  const auto  second = slots.Assign({ 11, 14, 13 });
  EXPECT_FALSE(second.grown);
  EXPECT_EQ(second.upload, (std::vector<std::size_t>{ 1 }));
  EXPECT_EQ(second.slot[1], first.slot[1]);
  EXPECT_EQ(second.slot[0], first.slot[0]);
  EXPECT_EQ(second.slot[2], first.slot[2]);
  // 12 was evicted: naming it again uploads it.
  const auto third = slots.Assign({ 12, 14, 13 });
  EXPECT_EQ(third.upload, (std::vector<std::size_t>{ 0 }));
  EXPECT_EQ(third.slot[0], first.slot[0]); // 11's slot, which this batch does not use
}

TEST(ParentSlots, EqualKeysShareOneSlotAndOneUpload)
{
  ParentSlots slots;
  const auto  a = slots.Assign({ 21, 22, 21 });
  EXPECT_EQ(a.slot[0], a.slot[2]);
  EXPECT_NE(a.slot[0], a.slot[1]);
  EXPECT_EQ(a.upload, (std::vector<std::size_t>{ 0, 1 }));
  EXPECT_EQ(a.capacity, 2u);
}

TEST(ParentSlots, KeyZeroIsAlwaysUploadedIntoAFreshSlot)
{
  ParentSlots slots;
  slots.Assign({ 0, 31 });
  const auto b = slots.Assign({ 0, 31, 0 });
  EXPECT_TRUE(b.grown); // three slots are needed now
  EXPECT_EQ(b.upload, (std::vector<std::size_t>{ 0, 1, 2 }));
  const auto c = slots.Assign({ 0, 31, 0 });
  EXPECT_FALSE(c.grown);
  EXPECT_EQ(c.upload, (std::vector<std::size_t>{ 0, 2 }));
  EXPECT_NE(c.slot[0], c.slot[2]);
  EXPECT_EQ(std::set<std::uint32_t>(c.slot.begin(), c.slot.end()).size(), 3u);
}

TEST(ParentSlots, GrowingLosesEverythingHeld)
{
  ParentSlots slots;
  slots.Assign({ 1, 2 });
  const auto b = slots.Assign({ 1, 2, 3, 4, 5 });
  EXPECT_TRUE(b.grown);
  EXPECT_GE(b.capacity, 5u);
  EXPECT_EQ(b.upload.size(), 5u);
  EXPECT_EQ(std::set<std::uint32_t>(b.slot.begin(), b.slot.end()).size(), 5u);
  for (std::uint32_t s : b.slot)
    EXPECT_LT(s, b.capacity);
  // A smaller batch afterwards fits: nothing grows, held parents stay.
  const auto c = slots.Assign({ 5, 6 });
  EXPECT_FALSE(c.grown);
  EXPECT_EQ(c.upload, (std::vector<std::size_t>{ 1 }));
  EXPECT_EQ(c.slot[0], b.slot[4]);
}
TEST(ParentSlots, ABatchAssignedInTwoCallsKeepsTheFirstCallsSlots)
{
  ParentSlots slots;
  slots.Assign({ 11, 12, 13, 14 });
  // Next batch: 11 and 15 now, room for 4 parents; 12 changed to 16 later.
  const auto first = slots.AssignFirst({ 11, 15 }, 4);
  EXPECT_FALSE(first.grown);
  EXPECT_EQ(first.upload, (std::vector<std::size_t>{ 1 }));
  const auto rest = slots.AssignRest({ 16, 13, 15 });
  EXPECT_FALSE(rest.grown);
  // 15 keeps the first call's slot (no second upload); 16 takes a slot
  // neither call named, not one of the first call's.
  EXPECT_EQ(rest.upload, (std::vector<std::size_t>{ 0 }));
  EXPECT_EQ(rest.slot[2], first.slot[1]);
  std::set<std::uint32_t> used{ first.slot[0], first.slot[1], rest.slot[0], rest.slot[1] };
  EXPECT_EQ(used.size(), 4u);
  // The first call makes room for the whole batch: growing later would lose
  // slots already uploaded.
  const auto grown = slots.AssignFirst({ 11 }, 6);
  EXPECT_TRUE(grown.grown);
  EXPECT_GE(grown.capacity, 6u);
  const auto more = slots.AssignRest({ 21, 22, 23, 24, 25 });
  EXPECT_EQ(more.upload.size(), 5u);
  EXPECT_THROW(slots.AssignRest({ 26 }), morea_core::Error);
  EXPECT_THROW(ParentSlots().AssignRest({ 1 }), morea_core::Error);
}
} // namespace
