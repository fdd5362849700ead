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

// Hands out chunks of indices from an atomic counter: many work items
// (sampling a candidate, unpacking its values) take well under a microsecond,
// and 16 threads taking them one at a time under a mutex were serialised on
// it. Chunks stay small (8 per thread) so that uneven items still balance.
void
ThreadPool::RunShare()
{
  const std::function<void(std::size_t)> * work = nullptr;
  std::size_t                              count = 0, grain = 1;
  {
    std::lock_guard<std::mutex> lock(m_Mutex);
    work = m_Work;
    count = m_Count;
    grain = m_Grain;
  }
  if (!work)
    return;
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
      m_Next.store(count); // stop handing out work
      return;
    }
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
    m_Grain = std::max<std::size_t>(1, count / (8 * (m_Workers.size() + 1)));
    m_Next.store(0);
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
