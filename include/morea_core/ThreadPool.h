// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: a fixed set of worker threads that run
// index ranges (the CPU backend's parallel loops), kept alive between calls
// because the optimiser issues many short loops per generation.
#ifndef morea_ThreadPool_h
#define morea_ThreadPool_h

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace morea_core
{
/** How the operating system schedules a pool's or worker's threads. */
enum class WorkerPriority
{
  Normal,
  /** Only on cores that nothing else wants (SCHED_IDLE on Linux; Normal
   *  elsewhere): work beside a latency-bound thread and its pool that must
   *  never delay them. */
  Idle
};

/** Host threads the process's parallel work uses: the limit a tool set from
 *  its --threads (SetHostThreadLimit), else one per hardware thread. Pools
 *  made with 0 threads, one-off parallel loops and the voxel fold repair take
 *  it, so that registrations side by side on one host (a batch, one per GPU)
 *  keep to their share of the cores in every stage, not only the optimiser. */
std::size_t
HostThreads();
/** 0 lifts the limit. */
void
SetHostThreadLimit(std::size_t threads);

class ThreadPool
{
public:
  /** `threads` = 0: one per hardware thread. The calling thread works too
   *  (at its own priority; `priority` is that of the workers). */
  explicit ThreadPool(std::size_t threads = 0, WorkerPriority priority = WorkerPriority::Normal);
  ~ThreadPool();
  ThreadPool(const ThreadPool &) = delete;
  ThreadPool &
  operator=(const ThreadPool &) = delete;

  /** The pool of `threads` threads (0: one per hardware thread) shared by
   *  all who ask for that many while one of them holds it: the optimiser and
   *  its backend take turns on one set of workers rather than keeping two
   *  sets that compete for the cores. */
  static std::shared_ptr<ThreadPool>
  Shared(std::size_t threads = 0);

  /** Calls work(i) for i in [0, count), spread over the threads; returns when
   *  all are done. The first exception thrown by `work` is rethrown here.
   *  A call while another is under way (from another thread, or from within
   *  `work`) runs on its calling thread alone. */
  void
  ParallelFor(std::size_t count, const std::function<void(std::size_t)> & work);

  std::size_t
  NumberOfThreads() const
  {
    return m_Workers.size() + 1;
  }

private:
  void
  WorkerLoop();
  void
  RunShare();
  /** The next published call after `seen` (even numbers: published), or 0
   *  when the pool stops; spins a little before sleeping. */
  std::uint64_t
  AwaitCall(std::uint64_t seen);

  std::vector<std::thread> m_Workers;
  std::atomic<bool>        m_InUse{ false }; ///< a ParallelFor is under way
  // A call is published by an even m_Call; odd while its parameters are
  // written, which waits until no worker is inside the call before.
  std::atomic<std::uint64_t>               m_Call{ 0 };
  std::atomic<std::size_t>                 m_Inside{ 0 }; ///< workers in RunShare
  std::atomic<std::size_t>                 m_Next{ 0 };
  const std::function<void(std::size_t)> * m_Work{ nullptr };
  std::size_t                              m_Count{ 0 };
  std::size_t                              m_Grain{ 1 };
  std::atomic<bool>                        m_Stop{ false };
  // Sleeping workers wait for m_WakeWord to change (ThreadPool.cxx); the
  // condition variable serves where there is no futex.
  std::atomic<std::uint32_t> m_WakeWord{ 0 };
  std::atomic<int>           m_Sleeping{ 0 };
  std::mutex                 m_Mutex;
  std::condition_variable    m_Wake;
  std::exception_ptr         m_Error;           ///< under m_Mutex
  std::atomic<bool>          m_Failed{ false }; ///< m_Error is set
};

/** A thread of its own that runs one job at a time beside its owner: the
 *  optimiser draws its next batches there while its own thread feeds the
 *  backend. Start hands a job over; Wait returns once it has ended and
 *  rethrows what it threw. The destructor waits for a job under way. */
class BackgroundWorker
{
public:
  explicit BackgroundWorker(WorkerPriority priority = WorkerPriority::Normal);
  ~BackgroundWorker();
  BackgroundWorker(const BackgroundWorker &) = delete;
  BackgroundWorker &
  operator=(const BackgroundWorker &) = delete;

  /** Runs `job` on the worker's thread; throws while another is under way
   *  or its error has not been collected by Wait. */
  void
  Start(std::function<void()> job);
  /** Returns when no job is under way (at once when none was started),
   *  rethrowing the last job's exception, once. */
  void
  Wait();

private:
  void
  Loop(WorkerPriority priority);

  std::mutex              m_Mutex;
  std::condition_variable m_Changed;
  std::function<void()>   m_Job;          ///< under m_Mutex
  bool                    m_Busy{ false }; ///< a job is handed over or running; under m_Mutex
  bool                    m_Stop{ false }; ///< under m_Mutex
  std::exception_ptr      m_Error;        ///< under m_Mutex
  std::thread             m_Thread;       ///< last: starts once the rest is made
};
} // namespace morea_core

#endif
