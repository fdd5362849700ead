// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The checksum of checkpoints and fingerprints: XXH64's reference values, and
// fingerprints that name the first key that differs.
#include "morea_core/Hash.h"
#include "morea_core/ParameterSet.h"
#include "morea_core/RunFingerprint.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace
{
TEST(Hash64, MatchesTheReferenceXXH64)
{
  // Values of xxhash 0.8 (XXH64) for these inputs.
  EXPECT_EQ(morea_core::Hash64(std::string()), 0xef46db3751d8e999ULL);
  EXPECT_EQ(morea_core::Hash64(std::string("a")), 0xd24ec4f1a98c6e5bULL);
  EXPECT_EQ(morea_core::Hash64(std::string("abc")), 0x44bc2cf5ad770999ULL);
  EXPECT_EQ(morea_core::Hash64(std::string("xxhash"), 20141025), 0xb559b98d844e0635ULL);
  EXPECT_EQ(morea_core::Hash64(std::string("Nobody inspects the spammish repetition")), 0xfbcea83c8a378bf1ULL);
  std::string bytes;
  for (int i = 0; i < 1000; ++i)
    bytes.push_back(static_cast<char>(i * 7 + 3));
  EXPECT_EQ(morea_core::Hash64(bytes, 12345), 0x365c39a0c5a4c88eULL); // stripes, 8-, 4- and 1-byte tails
  EXPECT_EQ(morea_core::HashText(0x00ab0000000000cdULL), "00ab0000000000cd");
}

TEST(RunFingerprint, NamesTheFirstDifferenceAndLeavesOutWhatDoesNotChangeTheFront)
{
  morea_core::ParameterSet parameters;
  morea_core::RunFingerprint a;
  a.AddParameters(parameters);
  morea_core::RunFingerprint b = a;
  EXPECT_EQ(a.FirstDifference(b), "");
  // Running longer, elsewhere, under another name does not change the front.
  for (const char * key : { "ea_num_generations", "cuda_gpu_id", "problem_id", "num_runs", "zip" })
  {
    EXPECT_FALSE(morea_core::ParameterChangesTheFront(key)) << key;
    for (const auto & [k, v] : a.Entries())
      EXPECT_NE(k, key);
  }
  parameters.SetFromString("morea_sampling_rate", "0.5");
  parameters.SetFromString("seed", "3");
  morea_core::RunFingerprint c;
  c.AddParameters(parameters);
  // The first in the saved fingerprint's order (the parameter table's).
  EXPECT_EQ(a.FirstDifference(c), "seed: 0 in the checkpoint, 3 in this run");
  parameters.SetFromString("seed", "0");
  morea_core::RunFingerprint d;
  d.AddParameters(parameters);
  EXPECT_EQ(a.FirstDifference(d), "morea_sampling_rate: 1 in the checkpoint, 0.5 in this run");
  d.Add("extra", "1");
  a.Add("morea_sampling_rate", "0.5");
  EXPECT_EQ(a.FirstDifference(d), "extra: not in the checkpoint, 1 in this run");
  EXPECT_EQ(d.FirstDifference(a), "extra: 1 in the checkpoint, not given in this run");
  morea_core::RunFingerprint e;
  e.Add("k", std::string(200, 'x'));
  morea_core::RunFingerprint f;
  f.Add("k", "y");
  EXPECT_EQ(e.FirstDifference(f), "k: " + std::string(77, 'x') + "... in the checkpoint, y in this run");
}
} // namespace
