// MultiObjectiveRegistration core: a fixed set of worker threads that run
// index ranges (the CPU backend's parallel loops), kept alive between calls
// because the optimiser issues many short loops per generation.
#ifndef morea_ThreadPool_h
#define morea_ThreadPool_h

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace morea
{
class ThreadPool
{
public:
  /** `threads` = 0: one per hardware thread. The calling thread works too. */
  explicit ThreadPool(std::size_t threads = 0);
  ~ThreadPool();
  ThreadPool(const ThreadPool &) = delete;
  ThreadPool &
  operator=(const ThreadPool &) = delete;

  /** Calls work(i) for i in [0, count), spread over the threads; returns when
   *  all are done. The first exception thrown by `work` is rethrown here. */
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

  std::vector<std::thread>                   m_Workers;
  std::mutex                                 m_Mutex;
  std::condition_variable                    m_Wake;
  std::condition_variable                    m_Done;
  const std::function<void(std::size_t)> *   m_Work{ nullptr };
  std::size_t                                m_Count{ 0 };
  std::atomic<std::size_t>                   m_Next{ 0 };
  std::size_t                                m_Grain{ 1 };
  std::size_t                                m_Busy{ 0 };
  std::size_t                                m_Generation{ 0 };
  bool                                       m_Stop{ false };
  std::exception_ptr                         m_Error;
};
} // namespace morea

#endif
