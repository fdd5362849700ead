// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Gzip compression of a whole file on several threads, as one gzip member.
#ifndef morea_ParallelGzip_h
#define morea_ParallelGzip_h

#include <cstddef>
#include <string>

namespace itk
{
namespace morea
{
/** Writes `to` as the gzip file of `from`'s bytes, at zlib's default level.
 *
 *  zlib deflates about 45 MB a second of a displacement field of doubles on
 *  one core, so a chosen solution's field took a second or more to write.
 *  Here chunks of `chunkBytes` are deflated on threads of their own, each
 *  primed with the 32 KiB before it (back-references may reach into it, as
 *  one stream's would), and every chunk but the last ends on a byte boundary
 *  (a sync flush), so the pieces join into one deflate stream; the CRC-32 of
 *  the whole is combined from the pieces'. Any gzip reader reads the result:
 *  it is one member, and it inflates to exactly `from`'s bytes.
 *
 *  Throws itk::ExceptionObject on a read, write or zlib error; `to` may then
 *  be left partly written (callers write to a temporary path). */
void
GzipFileInChunks(const std::string & from, const std::string & to, std::size_t chunkBytes = std::size_t{ 4 } << 20);
} // namespace morea
} // namespace itk

#endif
