// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of checkpoint files written behind the optimiser.
#include "morea_core/CheckpointWriter.h"

#include "morea_core/Error.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

namespace
{
using namespace morea_core;

std::string
ReadAll(const std::filesystem::path & path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST(CheckpointWriter, WritesReplaceTheFileWhole)
{
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "morea-checkpoint-writer-test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / "state.ckpt";
  std::string                 first(3'000'000, 'a'), second(1'000, 'b');
  first[12345] = 'z';
  CheckpointWriter writer;
  writer.Write(first, path.string());
  writer.Write(second, path.string()); // waits for the first
  writer.Wait();
  EXPECT_EQ(ReadAll(path), second);
  writer.Write(first, path.string());
  // The buffer comes back empty with its room, once written.
  std::string buffer = writer.TakeBuffer();
  EXPECT_TRUE(buffer.empty());
  EXPECT_GE(buffer.capacity(), first.size());
  EXPECT_EQ(ReadAll(path), first);
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".partial"));
  EXPECT_EQ(writer.TakeBuffer().capacity(), std::string().capacity()); // handed back once
  writer.Wait(); // nothing in progress
  std::filesystem::remove_all(dir);
}

TEST(CheckpointWriter, ErrorsReachTheCallerOnce)
{
  const std::filesystem::path missing = std::filesystem::temp_directory_path() / "morea-no-such-folder" / "x.ckpt";
  std::filesystem::remove_all(missing.parent_path());
  CheckpointWriter writer;
  writer.Write("bytes", missing.string());
  try
  {
    writer.Wait();
    ADD_FAILURE() << "expected an error";
  }
  catch (const Error & e)
  {
    EXPECT_NE(std::string(e.what()).find("x.ckpt"), std::string::npos) << e.what();
  }
  writer.Wait(); // reported once
  // The next write finds the previous one's error first.
  writer.Write("bytes", missing.string());
  EXPECT_THROW(writer.Write("more", missing.string()), Error);
  EXPECT_THROW(WriteFileAtomically(missing.string(), "bytes"), Error);
  EXPECT_FALSE(std::filesystem::exists(missing.parent_path()));
}
} // namespace

TEST(CheckpointSchedule, ReadsGenerationsAndDurations)
{
  EXPECT_EQ(CheckpointSchedule::Parse("10").generations, 10u);
  EXPECT_EQ(CheckpointSchedule::Parse("10").seconds, 0.0);
  EXPECT_EQ(CheckpointSchedule::Parse("30s").seconds, 30.0);
  EXPECT_EQ(CheckpointSchedule::Parse("30s").generations, 0u);
  EXPECT_EQ(CheckpointSchedule::Parse("2.5min").seconds, 150.0);
  EXPECT_EQ(CheckpointSchedule::Parse("0.5s").seconds, 0.5);
  const CheckpointSchedule end = CheckpointSchedule::Parse("0");
  EXPECT_EQ(end.generations, 0u);
  EXPECT_EQ(end.seconds, 0.0);
  for (const char * bad : { "", "s", "-1", "1.5", "10 s", "10h", "nan", "inf", "1e3s", "ten", "+5", " 5" })
    EXPECT_THROW(CheckpointSchedule::Parse(bad), Error) << "'" << bad << "'";
}

TEST(CheckpointSchedule, IsDueEveryCountOfGenerationsOrOnceTheDurationHasPassed)
{
  const CheckpointSchedule byCount{ 10, 0.0 };
  EXPECT_TRUE(byCount.Due(20, 0.0));
  EXPECT_FALSE(byCount.Due(21, 1e6)); // time does not matter to a count
  const CheckpointSchedule byTime{ 0, 30.0 };
  EXPECT_FALSE(byTime.Due(20, 29.9)); // nor the generation to a duration
  EXPECT_TRUE(byTime.Due(21, 30.0));
  const CheckpointSchedule never{ 0, 0.0 };
  EXPECT_FALSE(never.Due(10, 1e6));
  const CheckpointSchedule both{ 10, 30.0 };
  EXPECT_TRUE(both.Due(10, 0.0));
  EXPECT_TRUE(both.Due(11, 31.0));
  EXPECT_FALSE(both.Due(11, 1.0));
}
