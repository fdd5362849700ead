#include "morea/ThreadPool.h"

#include <algorithm>

namespace morea
{
ThreadPool::ThreadPool(std::size_t threads)
{
  if (threads == 0)
    threads = std::max<std::size_t>(1, std::thread::hardware_concurrency());
  for (std::size_t i = 1; i < threads; ++i)
    m_Workers.emplace_back([this] { WorkerLoop(); });
}

ThreadPool::~ThreadPool()
{
  {
    std::lock_guard<std::mutex> lock(m_Mutex);
    m_Stop = true;
  }
  m_Wake.notify_all();
  for (auto & w : m_Workers)
    w.join();
}

// Takes indices one at a time under the lock: the work items (partial
// evaluations) take microseconds to milliseconds, far more than the lock.
void
ThreadPool::RunShare()
{
  std::unique_lock<std::mutex> lock(m_Mutex);
  while (m_Next < m_Count)
  {
    const std::size_t i = m_Next++;
    const auto *      work = m_Work;
    lock.unlock();
    try
    {
      (*work)(i);
    }
    catch (...)
    {
      lock.lock();
      if (!m_Error)
        m_Error = std::current_exception();
      m_Next = m_Count; // stop handing out work
      continue;
    }
    lock.lock();
  }
}

void
ThreadPool::WorkerLoop()
{
  std::size_t seen = 0;
  for (;;)
  {
    {
      std::unique_lock<std::mutex> lock(m_Mutex);
      m_Wake.wait(lock, [&] { return m_Stop || m_Generation != seen; });
      if (m_Stop)
        return;
      seen = m_Generation;
      ++m_Busy;
    }
    RunShare();
    {
      std::lock_guard<std::mutex> lock(m_Mutex);
      --m_Busy;
    }
    m_Done.notify_all();
  }
}

void
ThreadPool::ParallelFor(std::size_t count, const std::function<void(std::size_t)> & work)
{
  if (count == 0)
    return;
  if (m_Workers.empty() || count == 1)
  {
    for (std::size_t i = 0; i < count; ++i)
      work(i);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(m_Mutex);
    m_Work = &work;
    m_Count = count;
    m_Next = 0;
    m_Error = nullptr;
    ++m_Generation;
  }
  m_Wake.notify_all();
  RunShare();
  std::exception_ptr error;
  {
    std::unique_lock<std::mutex> lock(m_Mutex);
    m_Done.wait(lock, [&] { return m_Busy == 0 && m_Next >= m_Count; });
    m_Work = nullptr;
    error = m_Error;
    m_Error = nullptr;
  }
  if (error)
    std::rethrow_exception(error);
}
} // namespace morea
