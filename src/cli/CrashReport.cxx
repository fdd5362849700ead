// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "CrashReport.h"

#if defined(__linux__)
#  include <features.h> // defines __GLIBC__ where glibc is the C library
#endif
#if defined(__GLIBC__)
#  include <csignal>
#  include <cstring>
#  include <execinfo.h>
#  include <unistd.h>
#  define MOREA_HAVE_CRASH_REPORT 1
#else
#  define MOREA_HAVE_CRASH_REPORT 0
#endif

namespace morea_cli
{
#if MOREA_HAVE_CRASH_REPORT
namespace
{
struct ReportedSignal
{
  int          number;
  const char * name;
};
constexpr ReportedSignal ReportedSignals[] = {
  { SIGSEGV, "SIGSEGV" }, { SIGBUS, "SIGBUS" }, { SIGFPE, "SIGFPE" }, { SIGILL, "SIGILL" }, { SIGABRT, "SIGABRT" }
};

const char *
SignalName(int signal)
{
  for (const auto & s : ReportedSignals)
    if (s.number == signal)
      return s.name;
  return "?";
}

void
WriteText(const char * text)
{
  ssize_t ignored = ::write(STDERR_FILENO, text, std::strlen(text));
  (void)ignored;
}

// Only async-signal-safe calls here: write, backtrace_symbols_fd (after the
// warm-up in InstallCrashReport), raise. SA_RESETHAND has put the default
// action back, so the raise ends the process with the same signal (the
// exit status, and a core file where enabled, are what they would be).
void
ReportCrash(int signal)
{
  WriteText("morea: crashed with signal ");
  WriteText(SignalName(signal));
  WriteText("; backtrace (please report it):\n");
  void *    frames[64];
  const int count = ::backtrace(frames, 64);
  ::backtrace_symbols_fd(frames, count, STDERR_FILENO);
  ::raise(signal);
}
} // namespace

void
InstallCrashReport()
{
  // The first backtrace() loads libgcc's unwinder (it allocates): done here,
  // not in the handler.
  void * warm[1];
  ::backtrace(warm, 1);
  struct sigaction action
  {};
  action.sa_handler = ReportCrash;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND | SA_NODEFER;
  for (const auto & s : ReportedSignals)
    ::sigaction(s.number, &action, nullptr);
}
#else
void
InstallCrashReport()
{}
#endif
} // namespace morea_cli
