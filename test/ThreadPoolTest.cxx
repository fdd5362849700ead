// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The thread pool: every index runs exactly once whatever the count and the
// number of threads, an exception reaches the caller and stops the work, and
// the pool stays usable for the next call.
#include "morea_core/ParallelForThreads.h"
#include "morea_core/ThreadPool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

using morea_core::ThreadPool;

TEST(ThreadPool, RunsEveryIndexExactlyOnce)
{
  for (std::size_t threads : { 1, 2, 5, 16 })
  {
    ThreadPool pool(threads);
    EXPECT_EQ(pool.NumberOfThreads(), threads);
    for (std::size_t count : { 0, 1, 7, 129, 1000, 100003 })
    {
      std::vector<std::atomic<int>> hits(count);
      pool.ParallelFor(count, [&](std::size_t i) { hits[i].fetch_add(1); });
      std::size_t wrong = 0;
      for (const auto & h : hits)
        wrong += h.load() != 1;
      EXPECT_EQ(wrong, 0u) << threads << " threads, " << count << " items";
    }
  }
}

TEST(ThreadPool, UnevenItemsAllFinishBeforeTheCallReturns)
{
  ThreadPool       pool(4);
  std::atomic<int> done{ 0 };
  pool.ParallelFor(64, [&](std::size_t i) {
    volatile double x = 0.0;
    for (std::size_t k = 0; k < (i % 8 == 0 ? 200000 : 10); ++k)
      x = x + 1.0;
    done.fetch_add(1);
  });
  EXPECT_EQ(done.load(), 64);
}

TEST(ThreadPool, AnExceptionReachesTheCallerAndThePoolStaysUsable)
{
  ThreadPool       pool(4);
  std::atomic<int> ran{ 0 };
  EXPECT_THROW(pool.ParallelFor(100000,
                                [&](std::size_t i) {
                                  ran.fetch_add(1);
                                  if (i == 10)
                                    throw std::runtime_error("item 10");
                                }),
               std::runtime_error);
  EXPECT_LT(ran.load(), 100000) << "work stops being handed out after an error";
  std::atomic<int> after{ 0 };
  pool.ParallelFor(1000, [&](std::size_t) { after.fetch_add(1); });
  EXPECT_EQ(after.load(), 1000);
}

// Calls back to back (workers still spinning from the one before, some still
// inside it) and calls after a pause (workers asleep): each runs its own
// work, every index once, never the work of the call before.
TEST(ThreadPool, CallsBackToBackAndAfterAPauseEachRunTheirOwnWork)
{
  ThreadPool pool(4);
  for (int call = 0; call < 20000; ++call)
  {
    const std::size_t             count = 2 + static_cast<std::size_t>(call % 37);
    std::vector<std::atomic<int>> hits(count);
    std::atomic<int>              foreign{ 0 };
    pool.ParallelFor(count, [&, call](std::size_t i) {
      if (i >= count)
        foreign.fetch_add(1);
      else
        hits[i].fetch_add(call + 1);
    });
    ASSERT_EQ(foreign.load(), 0) << "call " << call;
    for (std::size_t i = 0; i < count; ++i)
      ASSERT_EQ(hits[i].load(), call + 1) << "call " << call << ", index " << i;
    if (call % 2000 == 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(5)); // past the workers' spinning
  }
}

// One pool per thread count while someone holds it; a call from within a
// call (or from another thread during one) runs on its caller alone and
// still covers every index.
TEST(ThreadPool, SharedPoolsAndCallsWithinCalls)
{
  auto a = ThreadPool::Shared(3);
  auto b = ThreadPool::Shared(3);
  auto c = ThreadPool::Shared(2);
  EXPECT_EQ(a.get(), b.get());
  EXPECT_NE(a.get(), c.get());
  EXPECT_EQ(a->NumberOfThreads(), 3u);
  std::vector<std::atomic<int>> hits(40 * 50);
  a->ParallelFor(40, [&](std::size_t i) {
    b->ParallelFor(50, [&](std::size_t k) { hits[i * 50 + k].fetch_add(1); });
  });
  std::size_t wrong = 0;
  for (const auto & h : hits)
    wrong += h.load() != 1;
  EXPECT_EQ(wrong, 0u);
  // Still usable in parallel afterwards.
  std::atomic<int> after{ 0 };
  a->ParallelFor(1000, [&](std::size_t) { after.fetch_add(1); });
  EXPECT_EQ(after.load(), 1000);
}

// The background worker runs each job on its own thread, beside the caller,
// one at a time; Wait returns once the job has ended, with its exception.
TEST(BackgroundWorker, RunsJobsBesideTheCallerInTurnAndPassesOnTheirErrors)
{
  morea_core::BackgroundWorker worker;
  worker.Wait(); // none started: returns at once
  const std::thread::id caller = std::this_thread::get_id();
  std::thread::id       ran;
  std::atomic<bool>     release{ false };
  int                   value = 0;
  worker.Start([&] {
    ran = std::this_thread::get_id();
    while (!release.load())
      std::this_thread::yield();
    value = 1;
  });
  // Under way: a second job is refused, and the first has not finished.
  EXPECT_THROW(worker.Start([] {}), std::exception);
  EXPECT_EQ(value, 0);
  release.store(true);
  worker.Wait();
  EXPECT_EQ(value, 1) << "Wait returns after the job has ended";
  EXPECT_NE(ran, caller);
  // Jobs in turn, each seeing what the one before wrote.
  for (int k = 2; k <= 50; ++k)
  {
    worker.Start([&value, k] { value = value == k - 1 ? k : -1; });
    worker.Wait();
  }
  EXPECT_EQ(value, 50);
  // An error reaches Wait once; until it is collected, no job starts.
  worker.Start([] { throw std::runtime_error("drawing failed"); });
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_THROW(worker.Start([] {}), std::exception);
  EXPECT_THROW(worker.Wait(), std::runtime_error);
  worker.Wait(); // collected: nothing more to report
  worker.Start([&value] { value = 7; });
  worker.Wait();
  EXPECT_EQ(value, 7);
}

TEST(BackgroundWorker, TheDestructorWaitsForTheJobUnderWay)
{
  std::atomic<int> finished{ 0 };
  {
    morea_core::BackgroundWorker worker;
    worker.Start([&finished] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      finished.store(1);
    });
  }
  EXPECT_EQ(finished.load(), 1);
}

#if defined(__linux__)
#  include <sched.h>

// Idle-priority workers run every index like any others, on threads the
// scheduler runs only where nothing else wants the core.
TEST(ThreadPool, IdlePriorityWorkersRunAtIdlePriority)
{
  ThreadPool                 pool(4, morea_core::WorkerPriority::Idle);
  const std::thread::id      caller = std::this_thread::get_id();
  std::atomic<int>           ran{ 0 }, idle{ 0 }, others{ 0 };
  const int                  callerPolicy = sched_getscheduler(0);
  // Idle-priority workers get a core only when nothing else wants it, so the
  // caller sleeps in its item until one has run (on a loaded machine a busy
  // caller could otherwise take every item before any worker is scheduled).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  pool.ParallelFor(8, [&](std::size_t) {
    ran.fetch_add(1);
    if (std::this_thread::get_id() == caller)
    {
      while (others.load() == 0 && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      return;
    }
    if (sched_getscheduler(0) == SCHED_IDLE)
      idle.fetch_add(1);
    others.fetch_add(1);
  });
  EXPECT_EQ(ran.load(), 8);
  ASSERT_GT(others.load(), 0) << "the workers took part";
  EXPECT_EQ(idle.load(), others.load()) << "every worker runs at idle priority";
  EXPECT_EQ(sched_getscheduler(0), callerPolicy) << "the caller keeps its own";
  morea_core::BackgroundWorker worker(morea_core::WorkerPriority::Idle);
  int                     policy = -1;
  worker.Start([&policy] { policy = sched_getscheduler(0); });
  worker.Wait();
  EXPECT_EQ(policy, SCHED_IDLE);
}
#endif

TEST(ThreadPool, TheHostThreadLimitHoldsForPoolsAndOneOffLoops)
{
  morea_core::SetHostThreadLimit(3);
  EXPECT_EQ(morea_core::HostThreads(), 3u);
  EXPECT_EQ(morea_core::ThreadPool(0).NumberOfThreads(), 3u);
  EXPECT_EQ(morea_core::ThreadPool(5).NumberOfThreads(), 5u) << "an explicit count is kept";
  std::mutex                  mutex;
  std::set<std::thread::id>   seen;
  std::atomic<std::size_t>    done{ 0 };
  morea_core::ParallelForOnNewThreads(64, [&](std::size_t) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::lock_guard<std::mutex> lock(mutex);
    seen.insert(std::this_thread::get_id());
    ++done;
  });
  EXPECT_EQ(done.load(), 64u);
  EXPECT_LE(seen.size(), 3u);
  morea_core::SetHostThreadLimit(0);
  EXPECT_EQ(morea_core::HostThreads(), std::max(1u, std::thread::hardware_concurrency()));
}
