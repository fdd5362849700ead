// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: a 64-bit checksum of bytes (XXH64, written
// out here so the core needs no library for it), for checkpoints that must
// not be read when damaged and for fingerprints of a run's inputs.
#ifndef morea_Hash_h
#define morea_Hash_h

#include <cstddef>
#include <cstdint>
#include <string>

namespace morea_core
{
/** XXH64 of `size` bytes at `data` (the reference algorithm: the same value
 *  as xxhash's XXH64 on any platform; about 10 GB/s). */
std::uint64_t
Hash64(const void * data, std::size_t size, std::uint64_t seed = 0);

inline std::uint64_t
Hash64(const std::string & bytes, std::uint64_t seed = 0)
{
  return Hash64(bytes.data(), bytes.size(), seed);
}

/** The hash as 16 hexadecimal digits. */
std::string
HashText(std::uint64_t hash);
} // namespace morea_core

#endif
