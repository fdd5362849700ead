// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: checkpoints written behind the optimiser.
// A checkpoint of the paper's configuration is about 50 MB; written every ten
// generations by the thread that runs them, the checkpoints and the initial
// population took 5.0-5.4 s of a run on an H100 machine's host, outside the
// generations, and 2.5-2.9 s written behind them (1.2-1.3 s with buffers
// reused, TakeBuffer). The state is serialised
// in memory on the caller's thread (the optimiser goes on changing it), and
// the file is written and renamed into place on a thread of its own.
#ifndef morea_CheckpointWriter_h
#define morea_CheckpointWriter_h

#include <cstddef>
#include <exception>
#include <string>
#include <thread>

namespace morea_core
{
/** When checkpoints are written during a run (always after its last
 *  generation as well): every `generations` generations, and at the first
 *  generation that ends at least `seconds` after the last checkpoint (or the
 *  run's start); 0 turns either off. On the GPU a generation of the paper's
 *  configuration takes about 0.1 s, so a count of generations writes a 50 MB
 *  file every second; a duration keeps the cost the same on every backend. */
struct CheckpointSchedule
{
  std::size_t generations{ 0 };
  double      seconds{ 0.0 };

  /** "N" (generations), "Ns" or "Nmin" (a duration; N may have a fraction);
   *  "0": only after the last generation. Throws Error on anything else. */
  static CheckpointSchedule
  Parse(const std::string & text);

  /** Whether a checkpoint is due after `generation`, `secondsSinceLast`
   *  after the last one. */
  bool
  Due(std::size_t generation, double secondsSinceLast) const
  {
    return (generations > 0 && generation % generations == 0) || (seconds > 0.0 && secondsSinceLast >= seconds);
  }
};

/** Writes `bytes` to `path` atomically: to `path.partial`, synced (fsync),
 *  then renamed and the folder synced, so
 *  that `path` holds either the old or the new file, never half of one.
 *  Throws Error (and leaves no partial file) when it cannot. */
void
WriteFileAtomically(const std::string & path, const std::string & bytes);

/** One file write at a time on a thread of its own (WriteFileAtomically). */
class CheckpointWriter
{
public:
  CheckpointWriter() = default;
  /** Waits for the write in progress; its error, if any, is lost (call Wait). */
  ~CheckpointWriter();
  CheckpointWriter(const CheckpointWriter &) = delete;
  CheckpointWriter &
  operator=(const CheckpointWriter &) = delete;

  /** Waits for the previous write (throwing its error), then starts
   *  writing `bytes` to `path` and returns. */
  void
  Write(std::string bytes, std::string path);

  /** Waits for the write in progress (throwing its error) and hands back
   *  its buffer, empty but with its room kept (filling 50 MB took 36 ms in
   *  a fresh buffer, mostly page faults, and 8 ms in a reused one, on a
   *  2-core development machine). */
  std::string
  TakeBuffer();

  /** Waits for the write in progress; throws its error. */
  void
  Wait();

private:
  std::thread        m_Thread;
  std::exception_ptr m_Error;
  std::string        m_Spare; ///< the last write's buffer (set by its thread)
};
} // namespace morea_core

#endif
