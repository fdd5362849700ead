// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: one run per output folder.
#ifndef morea_OutputFolderLock_h
#define morea_OutputFolderLock_h

#include <string>

namespace morea_core
{
/** Owns an output folder for as long as it lives: an exclusive lock on
 *  FOLDER/.morea.lock (flock, so a killed run leaves no lock behind and
 *  `--resume` can take the folder over). The file keeps the owner's process
 *  id for the message a second run gets. Creates the folder. */
class OutputFolderLock
{
public:
  /** Throws morea_core::Error naming the folder and the process that owns it when
   *  another run (in this process or another) holds it. */
  explicit OutputFolderLock(const std::string & folder);
  ~OutputFolderLock();
  OutputFolderLock(const OutputFolderLock &) = delete;
  OutputFolderLock &
  operator=(const OutputFolderLock &) = delete;

  /** The lock file's name inside a locked folder. */
  static constexpr const char * FileName = ".morea.lock";

private:
  int m_Descriptor{ -1 };
};
} // namespace morea_core

#endif
