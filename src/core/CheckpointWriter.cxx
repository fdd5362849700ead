// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/CheckpointWriter.h"

#include "morea_core/Error.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <utility>

#if defined(__unix__) || defined(__APPLE__)
#  include <cerrno>
#  include <fcntl.h>
#  include <unistd.h>
#  define MOREA_POSIX_FILES 1
#else
#  define MOREA_POSIX_FILES 0
#endif

namespace morea_core
{
#if MOREA_POSIX_FILES
namespace
{
/** Writes and syncs `bytes` to a new file `path`. A rename alone is atomic
 *  for readers but not across a power cut: without fsync the new name can
 *  reach the disk before the data, leaving an empty or partial checkpoint. */
void
WriteSynced(const std::string & path, const std::string & bytes)
{
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw Error("cannot write " + path + ": " + std::strerror(errno));
  const char * p = bytes.data();
  std::size_t  left = bytes.size();
  while (left > 0)
  {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR)
      continue;
    if (n <= 0)
    {
      const std::string why = std::strerror(n < 0 ? errno : EIO);
      ::close(fd);
      throw Error("writing " + path + " failed: " + why);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0)
  {
    const std::string why = std::strerror(errno);
    ::close(fd);
    throw Error("writing " + path + " failed (fsync): " + why);
  }
  if (::close(fd) != 0)
    throw Error("writing " + path + " failed: " + std::strerror(errno));
}

/** Syncs the folder, so that the rename into it is on the disk too. */
void
SyncFolderOf(const std::string & path)
{
  std::string folder = std::filesystem::path(path).parent_path().string();
  if (folder.empty())
    folder = ".";
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0)
    return; // some file systems do not open folders: the file itself is synced
  ::fsync(fd);
  ::close(fd);
}
} // namespace
#endif

CheckpointSchedule
CheckpointSchedule::Parse(const std::string & text)
{
  const auto bad = [&text] {
    return Error("checkpoint interval '" + text +
                 "': expected a number of generations (10), a duration (30s, 2.5min) or 0 (only at the end)");
  };
  std::size_t  used = 0;
  double       value = 0.0;
  try
  {
    value = std::stod(text, &used);
  }
  catch (const std::exception &)
  {
    throw bad();
  }
  const std::string number = text.substr(0, used), unit = text.substr(used);
  // Digits with at most one point: no sign, exponent, spaces, hex or inf.
  if (number.find_first_not_of("0123456789.") != std::string::npos || number.find('.') != number.rfind('.') ||
      !std::isdigit(static_cast<unsigned char>(number[0])) || !std::isfinite(value))
    throw bad();
  CheckpointSchedule schedule;
  if (unit.empty())
  {
    if (value != std::floor(value) || value > 1e15)
      throw bad();
    schedule.generations = static_cast<std::size_t>(value);
  }
  else if (unit == "s")
    schedule.seconds = value;
  else if (unit == "min")
    schedule.seconds = 60.0 * value;
  else
    throw bad();
  return schedule;
}

void
WriteFileAtomically(const std::string & path, const std::string & bytes)
{
  const std::string temporary = path + ".partial";
#if MOREA_POSIX_FILES
  try
  {
    WriteSynced(temporary, bytes);
  }
  catch (const Error &)
  {
    std::remove(temporary.c_str());
    throw;
  }
#else
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out)
      throw Error("cannot write " + temporary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out)
    {
      std::remove(temporary.c_str());
      throw Error("writing " + temporary + " failed");
    }
  }
#endif
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec)
  {
    std::remove(temporary.c_str());
    throw Error("cannot rename " + temporary + " to " + path + ": " + ec.message());
  }
#if MOREA_POSIX_FILES
  SyncFolderOf(path);
#endif
}

CheckpointWriter::~CheckpointWriter()
{
  if (m_Thread.joinable())
    m_Thread.join();
}

void
CheckpointWriter::Write(std::string bytes, std::string path)
{
  Wait();
  m_Thread = std::thread([this, bytes = std::move(bytes), path = std::move(path)]() mutable {
    try
    {
      WriteFileAtomically(path, bytes);
    }
    catch (...)
    {
      m_Error = std::current_exception(); // read after join
    }
    m_Spare = std::move(bytes); // likewise
  });
}

std::string
CheckpointWriter::TakeBuffer()
{
  Wait();
  std::string buffer = std::move(m_Spare);
  m_Spare = std::string();
  buffer.clear();
  return buffer;
}

void
CheckpointWriter::Wait()
{
  if (m_Thread.joinable())
    m_Thread.join();
  if (m_Error)
    std::rethrow_exception(std::exchange(m_Error, nullptr));
}
} // namespace morea_core
