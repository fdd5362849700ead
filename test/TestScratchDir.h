// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// A fresh, empty scratch folder for the running test, under the build's
// test output folder: <MOREA_TEST_OUTPUT_DIR>/<suite>/<test name>, so that
// tests run in parallel (ctest -j) never see each other's files.
#ifndef morea_TestScratchDir_h
#define morea_TestScratchDir_h

#include <gtest/gtest.h>

#include <filesystem>
#include <system_error>

namespace morea_test
{
inline std::filesystem::path
TestScratchDir(const char * suite)
{
  const auto *          info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::filesystem::path dir = std::filesystem::path(MOREA_TEST_OUTPUT_DIR) / suite / info->name();
  std::error_code       ec;
  std::filesystem::remove_all(dir, ec);
  std::filesystem::create_directories(dir);
  return dir;
}
} // namespace morea_test

#endif
