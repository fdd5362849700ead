// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "ParallelGzip.h"

#include "itkMacro.h"
#include "morea_core/ParallelForThreads.h"

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <vector>

namespace itk
{
namespace morea
{
namespace
{
constexpr std::size_t WindowBytes = 32768; // deflate's largest back-reference

/** One chunk deflated as part of a longer stream. */
struct Piece
{
  std::vector<unsigned char> bytes;
  std::size_t                length{ 0 }; ///< of the input it deflates
  uLong                      crc{ 0 };
  std::string                error; ///< empty when deflated
};

Piece
DeflatePiece(const unsigned char * data, std::size_t begin, std::size_t end, bool last)
{
  Piece    piece;
  z_stream s{};
  if (deflateInit2(&s, Z_DEFAULT_COMPRESSION, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
  {
    piece.error = "deflateInit2 failed";
    return piece;
  }
  const std::size_t primed = std::min(begin, WindowBytes);
  if (primed > 0 && deflateSetDictionary(&s, data + begin - primed, static_cast<uInt>(primed)) != Z_OK)
    piece.error = "deflateSetDictionary failed";
  const std::size_t length = end - begin;
  piece.length = length;
  piece.crc = crc32(0L, data + begin, static_cast<uInt>(length));
  // Room for incompressible data plus the sync flush's empty stored block;
  // grown below should deflate still need more.
  piece.bytes.resize(deflateBound(&s, static_cast<uLong>(length)) + 64);
  s.next_in = const_cast<Bytef *>(data + begin);
  s.avail_in = static_cast<uInt>(length);
  std::size_t produced = 0;
  while (piece.error.empty())
  {
    s.next_out = piece.bytes.data() + produced;
    s.avail_out = static_cast<uInt>(piece.bytes.size() - produced);
    const int rc = deflate(&s, last ? Z_FINISH : Z_SYNC_FLUSH);
    produced = piece.bytes.size() - s.avail_out;
    if (last && rc == Z_STREAM_END)
      break;
    // Flushed: everything is out (a second call after an exactly full
    // buffer has nothing left to add: Z_BUF_ERROR), ending on a byte boundary.
    if (!last && (rc == Z_OK || rc == Z_BUF_ERROR) && s.avail_in == 0 && s.avail_out > 0)
      break;
    if (s.avail_out == 0 && (rc == Z_OK || rc == Z_BUF_ERROR))
      piece.bytes.resize(piece.bytes.size() * 2);
    else
      piece.error = "deflate failed (" + std::to_string(rc) + ")";
  }
  deflateEnd(&s);
  piece.bytes.resize(produced);
  return piece;
}

void
PutLittleEndian32(std::ofstream & out, std::uint32_t v)
{
  const unsigned char b[4] = { static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8),
                               static_cast<unsigned char>(v >> 16), static_cast<unsigned char>(v >> 24) };
  out.write(reinterpret_cast<const char *>(b), 4);
}
} // namespace

void
GzipFileInChunks(const std::string & from, const std::string & to, std::size_t chunkBytes)
{
  if (chunkBytes == 0)
    itkGenericExceptionMacro(<< "gzip of '" << from << "': the chunk size must be positive");
  std::ifstream in(from, std::ios::binary);
  if (!in)
    itkGenericExceptionMacro(<< "gzip: cannot read '" << from << "'");
  const std::vector<unsigned char> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad())
    itkGenericExceptionMacro(<< "gzip: cannot read '" << from << "'");

  const std::size_t  chunks = std::max<std::size_t>(1, (data.size() + chunkBytes - 1) / chunkBytes);
  std::vector<Piece> pieces(chunks);
  morea_core::ParallelForOnNewThreads(chunks, [&](std::size_t i) {
    const std::size_t begin = i * chunkBytes;
    pieces[i] = DeflatePiece(data.data(), begin, std::min(data.size(), begin + chunkBytes), i + 1 == chunks);
  });

  std::ofstream out(to, std::ios::binary | std::ios::trunc);
  // Header: magic, deflate, no flags, no time, no extra flags, Unix.
  const unsigned char header[10] = { 0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3 };
  out.write(reinterpret_cast<const char *>(header), sizeof header);
  uLong crc = crc32(0L, Z_NULL, 0);
  for (const Piece & p : pieces)
  {
    if (!p.error.empty())
      itkGenericExceptionMacro(<< "gzip of '" << from << "': " << p.error);
    out.write(reinterpret_cast<const char *>(p.bytes.data()), static_cast<std::streamsize>(p.bytes.size()));
    crc = crc32_combine(crc, p.crc, static_cast<z_off_t>(p.length));
  }
  PutLittleEndian32(out, static_cast<std::uint32_t>(crc));
  PutLittleEndian32(out, static_cast<std::uint32_t>(data.size())); // the size modulo 2^32, as gzip keeps it
  if (!out.flush())
    itkGenericExceptionMacro(<< "gzip: cannot write '" << to << "'");
}
} // namespace morea
} // namespace itk
