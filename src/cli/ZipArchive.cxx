// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "ZipArchive.h"

#include "itkMOREAImageIO.h"
#include "morea_core/Error.h"
#include "morea_core/OutputFolderLock.h"

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <vector>

namespace morea_cli
{
using namespace morea_core;

namespace
{
namespace fs = std::filesystem;

void
Put16(std::string & out, std::uint32_t v)
{
  out += static_cast<char>(v & 0xff);
  out += static_cast<char>((v >> 8) & 0xff);
}

void
Put32(std::string & out, std::uint32_t v)
{
  Put16(out, v & 0xffff);
  Put16(out, v >> 16);
}

/** Raw deflate (no zlib header), as ZIP's method 8 stores it. */
std::string
Deflate(const std::string & data, const std::string & name)
{
  z_stream stream{};
  if (deflateInit2(&stream, Z_DEFAULT_COMPRESSION, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw Error("zip: cannot start compressing '" + name + "'");
  std::string out(deflateBound(&stream, static_cast<uLong>(data.size())), '\0');
  stream.next_in = reinterpret_cast<Bytef *>(const_cast<char *>(data.data()));
  stream.avail_in = static_cast<uInt>(data.size());
  stream.next_out = reinterpret_cast<Bytef *>(out.data());
  stream.avail_out = static_cast<uInt>(out.size());
  const int status = deflate(&stream, Z_FINISH);
  out.resize(stream.total_out);
  deflateEnd(&stream);
  if (status != Z_STREAM_END)
    throw Error("zip: cannot compress '" + name + "'");
  return out;
}

struct Entry
{
  std::string   name;
  std::uint32_t crc{ 0 };
  std::uint32_t compressedSize{ 0 };
  std::uint32_t size{ 0 };
  std::uint32_t offset{ 0 };
};
} // namespace

std::string
ZipFolder(const std::string & folder)
{
  const fs::path root = fs::path(folder).lexically_normal();
  const fs::path top = root.filename().empty() ? root.parent_path() : root;
  if (!fs::is_directory(top))
    throw Error("zip: '" + folder + "' is not a folder");
  const std::string archive = top.string() + ".zip";
  std::vector<fs::path> files;
  for (const auto & entry : fs::recursive_directory_iterator(top))
    if (entry.is_regular_file() && entry.path().filename() != OutputFolderLock::FileName)
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());

  constexpr std::uint64_t limit = std::numeric_limits<std::uint32_t>::max();
  std::string             body;
  std::vector<Entry>      entries;
  for (const auto & path : files)
  {
    std::ifstream in(path, std::ios::binary);
    if (!in)
      throw Error("zip: cannot read '" + path.string() + "'");
    const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (data.size() >= limit)
      throw Error("zip: '" + path.string() + "' is 4 GiB or larger; set zip = false and archive the folder yourself");
    Entry e;
    e.name = (top.filename() / fs::relative(path, top)).generic_string();
    e.crc = static_cast<std::uint32_t>(
      crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef *>(data.data()), static_cast<uInt>(data.size())));
    e.size = static_cast<std::uint32_t>(data.size());
    const std::string packed = Deflate(data, path.string());
    e.compressedSize = static_cast<std::uint32_t>(packed.size());
    e.offset = static_cast<std::uint32_t>(body.size());
    // Local file header: version 2.0, no flags, deflate, no time stamp.
    Put32(body, 0x04034b50);
    Put16(body, 20);
    Put16(body, 0);
    Put16(body, 8);
    Put16(body, 0);
    Put16(body, 0x21); // 1980-01-01
    Put32(body, e.crc);
    Put32(body, e.compressedSize);
    Put32(body, e.size);
    Put16(body, static_cast<std::uint32_t>(e.name.size()));
    Put16(body, 0);
    body += e.name;
    body += packed;
    if (body.size() >= limit)
      throw Error("zip: the archive of '" + folder + "' would reach 4 GiB; set zip = false");
    entries.push_back(e);
  }
  const auto directoryOffset = static_cast<std::uint32_t>(body.size());
  for (const auto & e : entries)
  {
    Put32(body, 0x02014b50);
    Put16(body, 20);
    Put16(body, 20);
    Put16(body, 0);
    Put16(body, 8);
    Put16(body, 0);
    Put16(body, 0x21);
    Put32(body, e.crc);
    Put32(body, e.compressedSize);
    Put32(body, e.size);
    Put16(body, static_cast<std::uint32_t>(e.name.size()));
    Put16(body, 0); // extra
    Put16(body, 0); // comment
    Put16(body, 0); // disk
    Put16(body, 0); // internal attributes
    Put32(body, 0); // external attributes
    Put32(body, e.offset);
    body += e.name;
  }
  const auto directorySize = static_cast<std::uint32_t>(body.size() - directoryOffset);
  Put32(body, 0x06054b50);
  Put16(body, 0);
  Put16(body, 0);
  Put16(body, static_cast<std::uint32_t>(entries.size()));
  Put16(body, static_cast<std::uint32_t>(entries.size()));
  Put32(body, directorySize);
  Put32(body, directoryOffset);
  Put16(body, 0);
  itk::morea::WriteTextFile(body, archive);
  return archive;
}
} // namespace morea_cli
