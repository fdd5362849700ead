#include "morea/CheckpointWriter.h"

#include "morea/Error.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <utility>

namespace morea
{
void
WriteFileAtomically(const std::string & path, const std::string & bytes)
{
  const std::string temporary = path + ".partial";
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
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec)
  {
    std::remove(temporary.c_str());
    throw Error("cannot rename " + temporary + " to " + path + ": " + ec.message());
  }
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
} // namespace morea
