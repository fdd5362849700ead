// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/OutputFolderLock.h"

#include "morea_core/Error.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

namespace morea_core
{
namespace
{
/** The process id an earlier owner wrote into the lock file, or "". */
std::string
OwnerOf(int descriptor)
{
  char          text[32] = {};
  const ssize_t n = ::pread(descriptor, text, sizeof text - 1, 0);
  std::string   owner = n > 0 ? std::string(text, static_cast<std::size_t>(n)) : std::string();
  while (!owner.empty() && (owner.back() == '\n' || owner.back() == ' '))
    owner.pop_back();
  return owner;
}
} // namespace

OutputFolderLock::OutputFolderLock(const std::string & folder)
{
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec)
    throw Error("cannot create the output folder '" + folder + "': " + ec.message());
  const std::string path = (std::filesystem::path(folder) / FileName).string();
  m_Descriptor = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (m_Descriptor < 0)
    throw Error("cannot open '" + path + "' to claim the output folder: " + std::strerror(errno));
  // Per open file, so two owners in one process exclude each other too.
  if (::flock(m_Descriptor, LOCK_EX | LOCK_NB) != 0)
  {
    const int         error = errno;
    const std::string owner = OwnerOf(m_Descriptor);
    ::close(m_Descriptor);
    m_Descriptor = -1;
    if (error == EWOULDBLOCK)
      throw Error("the output folder '" + folder + "' is in use by another run" +
                  (owner.empty() ? std::string() : " (process " + owner + ")") +
                  "; wait for it to finish or choose another output folder");
    throw Error("cannot lock '" + path + "': " + std::strerror(error));
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(m_Descriptor, 0) != 0 ||
      ::pwrite(m_Descriptor, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size()))
  {
    const int error = errno;
    ::close(m_Descriptor);
    m_Descriptor = -1;
    throw Error("cannot write '" + path + "': " + std::strerror(error));
  }
}

OutputFolderLock::~OutputFolderLock()
{
  if (m_Descriptor >= 0)
    ::close(m_Descriptor); // releases the lock; the file stays (removing it would race a new owner)
}
} // namespace morea_core
