// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The ITK layer's one way to report a user's error: an itk::ExceptionObject
// whose description is the message. Internal to src/itk (not installed).
#ifndef itkMOREAFail_h
#define itkMOREAFail_h

#include "itkMacro.h"

#include <string>

namespace itk
{
namespace morea
{
[[noreturn]] inline void
Fail(const std::string & message)
{
  itkGenericExceptionMacro(<< message);
}
} // namespace morea
} // namespace itk

#endif
