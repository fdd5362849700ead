// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Test helpers for messages: what an itk::ExceptionObject says, and a
// substring expectation that prints the whole message when it fails.
#ifndef morea_test_ItkErrorSupport_h
#define morea_test_ItkErrorSupport_h

#include "itkMacro.h"

#include <gtest/gtest.h>

#include <exception>
#include <string>

namespace morea_test
{
/** The description of the itk::ExceptionObject `f` throws; the test fails
 *  (and "" comes back) when it throws something else or nothing. */
template <typename F>
std::string
ItkError(F && f)
{
  try
  {
    f();
  }
  catch (const itk::ExceptionObject & e)
  {
    return e.GetDescription();
  }
  catch (const std::exception & e)
  {
    ADD_FAILURE() << "expected itk::ExceptionObject, got: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected itk::ExceptionObject, nothing was thrown";
  return "";
}

inline ::testing::AssertionResult
Contains(const std::string & haystack, const std::string & needle)
{
  if (haystack.find(needle) != std::string::npos)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "message '" << haystack << "' does not contain '" << needle << "'";
}
} // namespace morea_test

#define EXPECT_CONTAINS(haystack, needle) EXPECT_TRUE(::morea_test::Contains((haystack), (needle)))

#endif
