// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/ChildProcess.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#if defined(__unix__) || defined(__APPLE__)
#  include <cerrno>
#  include <csignal>
#  include <fcntl.h>
#  include <poll.h>
#  include <sys/resource.h>
#  include <sys/types.h>
#  include <sys/wait.h>
#  include <unistd.h>
#  define MOREA_HAVE_FORK 1
#else
#  define MOREA_HAVE_FORK 0
#endif

namespace morea_core
{
namespace
{
/** `work` here, its exception turned into a failure. */
ChildResult
RunHere(const std::function<std::string()> & work)
{
  ChildResult r;
  try
  {
    r.bytes = work();
    r.ok = true;
  }
  catch (const std::exception & e)
  {
    r.failure = e.what();
  }
  catch (...)
  {
    r.failure = "an unknown exception";
  }
  return r;
}

#if MOREA_HAVE_FORK
// The answer on the pipe: one byte ('K' bytes follow, 'E' a message), the
// length (8 bytes), then the bytes. Anything shorter means the child died.
bool
WriteAll(int fd, const char * p, std::size_t n)
{
  while (n > 0)
  {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR)
      continue;
    if (w <= 0)
      return false;
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

[[noreturn]] void
ChildMain(int fd, const std::function<std::string()> & work)
{
  // A crash here is expected now and then: no core file for it.
  struct rlimit noCore = { 0, 0 };
  ::setrlimit(RLIMIT_CORE, &noCore);
  // Nor a crash report from a handler the parent installed: what the child
  // printed last is what its parent keeps for the failure.
  for (int signal : { SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT })
    ::signal(signal, SIG_DFL);
  char        kind = 'K';
  std::string bytes;
  try
  {
    bytes = work();
  }
  catch (const std::exception & e)
  {
    kind = 'E';
    bytes = e.what();
  }
  catch (...)
  {
    kind = 'E';
    bytes = "an unknown exception";
  }
  const std::uint64_t length = bytes.size();
  const bool          sent = WriteAll(fd, &kind, 1) &&
                    WriteAll(fd, reinterpret_cast<const char *>(&length), sizeof length) &&
                    WriteAll(fd, bytes.data(), bytes.size());
  // _exit: no atexit handlers, no flushing of the parent's stdio buffers.
  ::_exit(sent ? 0 : 3);
}

/** The last non-empty line of `text`, without the program's name before an
 *  assertion message ("prog: file:line: ..."). */
std::string
LastLine(const std::string & text)
{
  std::size_t end = text.find_last_not_of(" \t\r\n");
  if (end == std::string::npos)
    return {};
  const std::size_t start = text.rfind('\n', end);
  std::string       line = text.substr(start == std::string::npos ? 0 : start + 1, end + 1 - (start == std::string::npos ? 0 : start + 1));
  const std::size_t colon = line.find(": ");
  if (colon != std::string::npos && line.find('/') != std::string::npos && line.find('/') > colon)
    line.erase(0, colon + 2);
  return line.size() <= 300 ? line : line.substr(line.size() - 300);
}

std::string
DescribeSignal(int signal)
{
  const char * name = ::strsignal(signal);
  return "signal " + std::to_string(signal) + (name ? std::string(", ") + name : std::string());
}
#endif
} // namespace

bool
ChildProcessesAvailable()
{
  return MOREA_HAVE_FORK != 0;
}

ChildResult
RunInChildProcess(const std::function<std::string()> & work, double timeoutSeconds)
{
#if !MOREA_HAVE_FORK
  (void)timeoutSeconds;
  return RunHere(work);
#else
  // Two pipes: the answer, and what the child prints (a library's assertion
  // message, say), which is kept for the failure instead of reaching the
  // terminal of a run that goes on without it.
  int answer[2], output[2];
  if (::pipe(answer) != 0)
    return RunHere(work); // no pipe, no child: out of descriptors, so run it here
  if (::pipe(output) != 0)
  {
    ::close(answer[0]);
    ::close(answer[1]);
    return RunHere(work);
  }
  for (int fd : { answer[0], answer[1], output[0], output[1] })
    ::fcntl(fd, F_SETFD, FD_CLOEXEC);
  // Whatever this process has buffered for its output goes now: the child
  // has a copy of the buffers, and should it flush them, the output would
  // appear twice.
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0)
  {
    for (int fd : { answer[0], answer[1], output[0], output[1] })
      ::close(fd);
    return RunHere(work); // out of processes or memory: better here than not at all
  }
  if (pid == 0)
  {
    ::close(answer[0]);
    ::close(output[0]);
    ::dup2(output[1], STDOUT_FILENO);
    ::dup2(output[1], STDERR_FILENO);
    ChildMain(answer[1], work);
  }
  ::close(answer[1]);
  ::close(output[1]);

  // Read both until the child closes them (it exits), or time runs out.
  ChildResult result;
  std::string received, printed;
  const auto  deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutSeconds);
  char        buffer[1 << 16];
  bool        open[2] = { true, true };
  while (open[0] || open[1])
  {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0)
    {
      result.timedOut = true;
      break;
    }
    struct pollfd p[2] = { { open[0] ? answer[0] : -1, POLLIN, 0 }, { open[1] ? output[0] : -1, POLLIN, 0 } };
    const int     ready = ::poll(p, 2, static_cast<int>(std::min<long long>(left.count(), 1 << 30)));
    if (ready <= 0)
      continue; // interrupted, or the deadline check above ends it
    for (int i = 0; i < 2; ++i)
    {
      if (!open[i] || p[i].revents == 0)
        continue;
      const ssize_t n = ::read(i == 0 ? answer[0] : output[0], buffer, sizeof buffer);
      if (n < 0 && errno == EINTR)
        continue;
      if (n <= 0)
      {
        open[i] = false;
        continue;
      }
      std::string & to = i == 0 ? received : printed;
      to.append(buffer, static_cast<std::size_t>(n));
      if (i == 1 && printed.size() > 4096)
        printed.erase(0, printed.size() - 4096); // the end says what went wrong
    }
  }
  ::close(answer[0]);
  ::close(output[0]);
  if (result.timedOut)
    ::kill(pid, SIGKILL);
  int   status = 0;
  pid_t waited;
  do
    waited = ::waitpid(pid, &status, 0);
  while (waited < 0 && errno == EINTR);
  if (result.timedOut)
  {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g s", timeoutSeconds);
    result.failure = std::string("did not finish within ") + limit + " (killed)";
    return result;
  }
  std::uint64_t length = 0;
  if (received.size() >= 1 + sizeof length)
    std::memcpy(&length, received.data() + 1, sizeof length);
  const bool complete = received.size() >= 1 + sizeof length && received.size() == 1 + sizeof length + length;
  if (!complete)
  {
    result.crashed = true;
    if (waited == pid && WIFSIGNALED(status))
      result.failure = "crashed (" + DescribeSignal(WTERMSIG(status)) + ")";
    else if (waited == pid && WIFEXITED(status))
      result.failure = "exited with status " + std::to_string(WEXITSTATUS(status)) + " without an answer";
    else
      result.failure = "ended without an answer";
    const std::string said = LastLine(printed);
    if (!said.empty())
      result.failure += " saying \"" + said + "\"";
    return result;
  }
  if (received[0] == 'K')
  {
    result.ok = true;
    result.bytes = received.substr(1 + sizeof length);
  }
  else
    result.failure = received.substr(1 + sizeof length);
  return result;
#endif
}
} // namespace morea_core
