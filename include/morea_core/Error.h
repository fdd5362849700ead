// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the exception type the core throws, and the
// one kind of it a caller may want to tell apart.
#ifndef morea_Error_h
#define morea_Error_h

#include <stdexcept>
#include <string>

namespace morea_core
{
/** Raised for bad input or an impossible request; the message is meant for the user. */
class Error : public std::runtime_error
{
public:
  explicit Error(const std::string & message)
    : std::runtime_error(message)
  {}
};
/** A device ran out of memory during a run (the CUDA backend's allocations):
 *  the caller adds what the run was and what to change. */
class OutOfDeviceMemory : public Error
{
public:
  using Error::Error;
};
} // namespace morea_core

#endif
