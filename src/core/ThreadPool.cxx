// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/ThreadPool.h"

#include "morea_core/Error.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <system_error>

#if defined(__x86_64__) || defined(__i386__)
#  include <immintrin.h>
#endif
#if defined(__linux__)
#  include <climits>
#  include <linux/futex.h>
#  include <pthread.h>
#  include <sched.h>
#  include <sys/syscall.h>
#  include <unistd.h>
#endif

namespace morea_core
{
namespace
{
void
CpuRelax()
{
#if defined(__x86_64__) || defined(__i386__)
  _mm_pause();
#else
  std::this_thread::yield();
#endif
}

// How long an idle worker watches for the next call before it sleeps. The
// optimiser issues calls microseconds to a millisecond apart (a batch's
// parts, its acceptance rounds), and waking sleeping workers through the
// kernel for each took a share of those calls' time. Late paper-scale
// generations on an H100 host (16 cores), medians of 5 rounds: 0.171 s
// (bound on) and 0.207 s (off) per generation with 30 us in a shared pool,
// 0.218 and 0.231 s with 30 us in two pools, 0.248 and 0.222 s without
// spinning; 200 us was no better than 30. With the futex wake below, 250
// late generations took 29.99 s (100 us), 31.09 s (30 us) and 34.08 s
// (300 us) in one lease, with equal medians for 30 and 100 us.
constexpr auto SpinTime = std::chrono::microseconds(30);

// Sleeping workers wait for the wake word to change. On Linux they wait on
// it directly (a futex): woken together under a condition variable's mutex,
// they took it one after another, each hand-over through the kernel, and the
// caller queued behind them. Elsewhere a condition variable stands in.
void
WaitWhileUnchanged(std::atomic<std::uint32_t> & word, std::uint32_t seen, std::mutex & mutex,
                   std::condition_variable & wake)
{
#if defined(__linux__)
  static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t), "the futex is the atomic's word");
  (void)mutex;
  (void)wake;
  // Returns at once when the word has changed already; a spurious return
  // is harmless (the caller looks again).
  syscall(SYS_futex, reinterpret_cast<std::uint32_t *>(&word), FUTEX_WAIT_PRIVATE, seen, nullptr, nullptr, 0);
#else
  std::unique_lock<std::mutex> lock(mutex);
  wake.wait(lock, [&] { return word.load() != seen; });
#endif
}

/** Puts the calling thread at `priority`; best effort (a refusal leaves it
 *  as it was). */
void
SetOwnPriority(WorkerPriority priority)
{
#if defined(__linux__)
  if (priority == WorkerPriority::Idle)
  {
    sched_param parameters{};
    parameters.sched_priority = 0;
    pthread_setschedparam(pthread_self(), SCHED_IDLE, &parameters);
  }
#else
  (void)priority;
#endif
}

/** Changes the wake word and wakes up to `count` threads waiting on it. */
void
ChangeAndWake(std::atomic<std::uint32_t> & word, std::size_t count, std::mutex & mutex, std::condition_variable & wake)
{
  word.fetch_add(1);
#if defined(__linux__)
  (void)mutex;
  (void)wake;
  const int n = static_cast<int>(std::min<std::size_t>(count, INT_MAX));
  syscall(SYS_futex, reinterpret_cast<std::uint32_t *>(&word), FUTEX_WAKE_PRIVATE, n, nullptr, nullptr, 0);
#else
  (void)count;
  // A waiter tests the word under the mutex: once the mutex has been free
  // after the change, every waiter either saw it or waits to be notified.
  { std::lock_guard<std::mutex> lock(mutex); }
  wake.notify_all();
#endif
}
} // namespace

namespace
{
std::atomic<std::size_t> hostThreadLimit{ 0 };
} // namespace

std::size_t
HostThreads()
{
  const std::size_t limit = hostThreadLimit.load();
  return limit > 0 ? limit : std::max<std::size_t>(1, std::thread::hardware_concurrency());
}

void
SetHostThreadLimit(std::size_t threads)
{
  hostThreadLimit.store(threads);
}

std::shared_ptr<ThreadPool>
ThreadPool::Shared(std::size_t threads)
{
  if (threads == 0)
    threads = HostThreads();
  static std::mutex                                   mutex;
  static std::map<std::size_t, std::weak_ptr<ThreadPool>> pools;
  std::lock_guard<std::mutex>                         lock(mutex);
  std::shared_ptr<ThreadPool>                         pool = pools[threads].lock();
  if (!pool)
  {
    pool = std::make_shared<ThreadPool>(threads);
    pools[threads] = pool;
  }
  return pool;
}

ThreadPool::ThreadPool(std::size_t threads, WorkerPriority priority)
{
  if (threads == 0)
    threads = HostThreads();
  m_Workers.reserve(threads - 1);
  for (std::size_t i = 1; i < threads; ++i)
  {
    try
    {
      m_Workers.emplace_back([this, priority] {
        SetOwnPriority(priority);
        WorkerLoop();
      });
    }
    catch (const std::system_error &)
    {
      break; // the system has no thread to spare now: a smaller pool, the same results
    }
  }
}

ThreadPool::~ThreadPool()
{
  m_Stop.store(true);
  ChangeAndWake(m_WakeWord, m_Workers.size(), m_Mutex, m_Wake);
  for (auto & w : m_Workers)
    w.join();
}

// Hands out chunks of indices from an atomic counter: many work items
// (sampling a candidate, unpacking its values) take well under a microsecond,
// and 16 threads taking them one at a time under a mutex were serialised on
// it. Chunks stay small (8 per thread) so that uneven items still balance.
void
ThreadPool::RunShare()
{
  const std::function<void(std::size_t)> * work = m_Work;
  const std::size_t                        count = m_Count, grain = m_Grain;
  for (;;)
  {
    const std::size_t begin = m_Next.fetch_add(grain);
    if (begin >= count)
      return;
    const std::size_t end = std::min(count, begin + grain);
    try
    {
      for (std::size_t i = begin; i < end; ++i)
        (*work)(i);
    }
    catch (...)
    {
      std::lock_guard<std::mutex> lock(m_Mutex);
      if (!m_Error)
        m_Error = std::current_exception();
      m_Failed.store(true);
      m_Next.store(count); // stop handing out work
      return;
    }
  }
}

std::uint64_t
ThreadPool::AwaitCall(std::uint64_t seen)
{
  const auto ready = [&](std::uint64_t call) { return call != seen && call % 2 == 0; };
  const auto until = std::chrono::steady_clock::now() + SpinTime;
  for (unsigned k = 0;; ++k)
  {
    if (m_Stop.load())
      return 0;
    const std::uint64_t call = m_Call.load();
    if (ready(call))
      return call;
    CpuRelax();
    if (k % 64 == 63 && std::chrono::steady_clock::now() > until)
      break;
  }
  // A call published after this count was read by ParallelFor is seen here
  // (all sequentially consistent); one published before, it wakes (the wake
  // word changes after the call is published). The value returned is the
  // published one that was seen: m_Call may be odd again by now, while the
  // next call's parameters are written.
  for (;;)
  {
    const std::uint32_t word = m_WakeWord.load();
    m_Sleeping.fetch_add(1);
    const std::uint64_t call = m_Call.load();
    if (m_Stop.load() || ready(call))
    {
      m_Sleeping.fetch_sub(1);
      return m_Stop.load() ? 0 : call;
    }
    WaitWhileUnchanged(m_WakeWord, word, m_Mutex, m_Wake);
    m_Sleeping.fetch_sub(1);
  }
}

void
ThreadPool::WorkerLoop()
{
  std::uint64_t seen = 0;
  for (;;)
  {
    const std::uint64_t call = AwaitCall(seen);
    if (call == 0)
      return;
    m_Inside.fetch_add(1);
    // The parameters are those of `call` only while it is still published:
    // its successor waits for m_Inside to drop before writing them.
    if (m_Call.load() == call)
      RunShare();
    m_Inside.fetch_sub(1);
    seen = call;
  }
}

void
ThreadPool::ParallelFor(std::size_t count, const std::function<void(std::size_t)> & work)
{
  if (count == 0)
    return;
  bool idle = false;
  if (m_Workers.empty() || count == 1 || !m_InUse.compare_exchange_strong(idle, true))
  {
    for (std::size_t i = 0; i < count; ++i)
      work(i);
    return;
  }
  struct Release
  {
    std::atomic<bool> & inUse;
    ~Release() { inUse.store(false); }
  } release{ m_InUse };
  // Unpublish the last call and wait for workers still inside it (they
  // find no work left) before its parameters change.
  m_Call.fetch_add(1);
  while (m_Inside.load() != 0)
    CpuRelax();
  m_Work = &work;
  m_Count = count;
  m_Grain = std::max<std::size_t>(1, count / (8 * (m_Workers.size() + 1)));
  m_Next.store(0);
  m_Call.fetch_add(1);
  // Only as many as there are items for the others: a small call wakes few.
  if (m_Sleeping.load() > 0)
    ChangeAndWake(m_WakeWord, std::min(m_Workers.size(), count - 1), m_Mutex, m_Wake);
  RunShare();
  // All handed out; wait for the chunks still running.
  while (m_Inside.load() != 0)
    CpuRelax();
  if (!m_Failed.load())
    return;
  std::exception_ptr error;
  {
    std::lock_guard<std::mutex> lock(m_Mutex);
    error = m_Error;
    m_Error = nullptr;
    m_Failed.store(false);
  }
  std::rethrow_exception(error);
}

BackgroundWorker::BackgroundWorker(WorkerPriority priority)
  : m_Thread([this, priority] { Loop(priority); })
{}

BackgroundWorker::~BackgroundWorker()
{
  {
    std::unique_lock<std::mutex> lock(m_Mutex);
    m_Changed.wait(lock, [this] { return !m_Busy; });
    m_Stop = true;
  }
  m_Changed.notify_all();
  m_Thread.join();
}

void
BackgroundWorker::Start(std::function<void()> job)
{
  if (!job)
    throw Error("background worker: no job to start");
  {
    std::lock_guard<std::mutex> lock(m_Mutex);
    if (m_Busy || m_Error)
      throw Error("background worker: a job is under way or its outcome was not collected");
    m_Job = std::move(job);
    m_Busy = true;
  }
  m_Changed.notify_all();
}

void
BackgroundWorker::Wait()
{
  std::exception_ptr error;
  {
    std::unique_lock<std::mutex> lock(m_Mutex);
    m_Changed.wait(lock, [this] { return !m_Busy; });
    std::swap(error, m_Error);
  }
  if (error)
    std::rethrow_exception(error);
}

void
BackgroundWorker::Loop(WorkerPriority priority)
{
  SetOwnPriority(priority);
  std::unique_lock<std::mutex> lock(m_Mutex);
  for (;;)
  {
    m_Changed.wait(lock, [this] { return m_Stop || (m_Busy && m_Job); });
    if (m_Stop)
      return;
    std::function<void()> job = std::move(m_Job);
    m_Job = nullptr;
    lock.unlock();
    std::exception_ptr error;
    try
    {
      job();
    }
    catch (...)
    {
      error = std::current_exception();
    }
    job = nullptr; // what it holds goes before Wait returns
    lock.lock();
    m_Error = error;
    m_Busy = false;
    m_Changed.notify_all();
  }
}
} // namespace morea_core
