// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration mesh generation: running a fragile library call
// in a child process, so that its crash becomes an error of the caller.
//
// TetGen 1.5 (Debian's libtet 1.5.0) frees its memory twice whenever it stops
// with an error in library mode (terminatetetgen() calls freememory(), then
// the unwound tetgenmesh's destructor calls it again): every error it detects
// (self-intersecting constraints, a face it cannot recover) becomes a
// segmentation fault or a corrupted heap. A forked child takes the damage.
#ifndef morea_ChildProcess_h
#define morea_ChildProcess_h

#include <functional>
#include <string>

namespace morea_core
{
struct ChildResult
{
  bool        ok{ false };
  std::string bytes;   ///< what `work` returned (ok)
  std::string failure; ///< why not (not ok): the child's exception message, signal or time-out
  bool        crashed{ false }; ///< the child died of a signal or exited without an answer
  bool        timedOut{ false };
};

/** Runs `work` in a forked child process and returns its bytes (sent back
 *  through a pipe). An exception in `work` comes back as its message; a
 *  crash (signal), an exit without an answer or a run longer than
 *  `timeoutSeconds` (the child is killed) as a failure. Where fork() is not
 *  available (Windows), `work` runs in this process.
 *
 *  The child has only the calling thread: `work` must not wait for locks
 *  that other threads may hold (memory allocation is safe with glibc, whose
 *  fork handlers reset the allocator's locks). */
ChildResult
RunInChildProcess(const std::function<std::string()> & work, double timeoutSeconds);

/** Whether RunInChildProcess really forks on this platform. */
bool
ChildProcessesAvailable();
} // namespace morea_core

#endif
