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
