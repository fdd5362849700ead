// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: a one-off parallel loop on threads of its
// own, for the few long loops that run outside the optimiser's pool (and may
// run beside other such loops, where the shared pool would serialise them).
#ifndef morea_ParallelForThreads_h
#define morea_ParallelForThreads_h

#include "morea_core/ThreadPool.h"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <system_error>
#include <thread>
#include <vector>

namespace morea_core
{
/** Runs body(item) for items [0, count) on up to HostThreads() threads (the
 *  caller's among them), handing out items one by one; returns when all are
 *  done. `body` must not throw. */
template <typename TBody>
void
ParallelForOnNewThreads(std::size_t count, TBody body)
{
  const std::size_t threads =
    std::max<std::size_t>(1, std::min<std::size_t>(count, HostThreads()));
  std::atomic<std::size_t> next{ 0 };
  auto                     worker = [&] {
    for (std::size_t item = next++; item < count; item = next++)
      body(item);
  };
  std::vector<std::thread> helpers;
  helpers.reserve(threads - 1);
  for (std::size_t t = 1; t < threads; ++t)
  {
    try
    {
      helpers.emplace_back(worker);
    }
    catch (const std::system_error &)
    {
      break; // the system has no thread to spare now: the same items on fewer threads
    }
  }
  worker();
  for (auto & h : helpers)
    h.join();
}
} // namespace morea_core

#endif
