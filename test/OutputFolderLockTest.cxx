// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/Error.h"
#include "morea_core/OutputFolderLock.h"

#include <gtest/gtest.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

namespace
{
std::filesystem::path
FreshFolder(const std::string & name)
{
  const auto folder = std::filesystem::temp_directory_path() / ("morea-lock-test-" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(folder);
  return folder;
}

/** The message of the Error that claiming `folder` throws, or "" when it succeeds. */
std::string
RefusalOf(const std::filesystem::path & folder)
{
  try
  {
    const morea_core::OutputFolderLock lock(folder.string());
  }
  catch (const morea_core::Error & e)
  {
    return e.what();
  }
  return {};
}
} // namespace

TEST(OutputFolderLock, CreatesTheFolderAndExcludesASecondOwnerUntilReleased)
{
  const auto folder = FreshFolder("nested/run");
  {
    std::optional<morea_core::OutputFolderLock> first(std::in_place, folder.string());
    EXPECT_TRUE(std::filesystem::is_directory(folder));
    const std::string refusal = RefusalOf(folder);
    EXPECT_NE(refusal.find("is in use by another run (process " + std::to_string(::getpid()) + ")"), std::string::npos)
      << refusal;
    EXPECT_NE(refusal.find(folder.string()), std::string::npos) << refusal;
    first.reset();
    EXPECT_EQ(RefusalOf(folder), "");
  }
}

TEST(OutputFolderLock, AnotherProcessHoldingItRefusesAndItsEndFreesTheFolder)
{
  const auto folder = FreshFolder("other-process");
  int        ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0)
  {
    // Holds the folder until the parent kills it: it never releases the lock itself.
    ::close(ready[0]);
    const morea_core::OutputFolderLock lock(folder.string());
    char                          byte = 1;
    (void)!::write(ready[1], &byte, 1);
    ::close(ready[1]);
    for (;;)
      ::pause();
  }
  ::close(ready[1]);
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  const std::string refusal = RefusalOf(folder);
  EXPECT_NE(refusal.find("(process " + std::to_string(child) + ")"), std::string::npos) << refusal;
  ::kill(child, SIGKILL); // a killed run: its lock goes with it
  int status = 0;
  ::waitpid(child, &status, 0);
  ::close(ready[0]);
  EXPECT_EQ(RefusalOf(folder), "");
}

TEST(OutputFolderLock, AFolderThatCannotBeMadeIsAnError)
{
  const auto folder = FreshFolder("blocked");
  std::filesystem::create_directories(folder.parent_path());
  std::FILE * inTheWay = std::fopen(folder.c_str(), "w"); // a file where the folder should go
  ASSERT_NE(inTheWay, nullptr);
  std::fclose(inTheWay);
  const std::string refusal = RefusalOf(folder / "run");
  EXPECT_NE(refusal.find("cannot create the output folder"), std::string::npos) << refusal;
}
