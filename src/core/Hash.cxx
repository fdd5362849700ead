// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/Hash.h"

#include <cstring>

namespace morea_core
{
namespace
{
// The reference algorithm's constants and steps (github.com/Cyan4973/xxHash, xxhash.h).
constexpr std::uint64_t Prime1 = 0x9E3779B185EBCA87ULL;
constexpr std::uint64_t Prime2 = 0xC2B2AE3D27D4EB4FULL;
constexpr std::uint64_t Prime3 = 0x165667B19E3779F9ULL;
constexpr std::uint64_t Prime4 = 0x85EBCA77C2B2AE63ULL;
constexpr std::uint64_t Prime5 = 0x27D4EB2F165667C5ULL;

std::uint64_t
Rotate(std::uint64_t x, int r)
{
  return (x << r) | (x >> (64 - r));
}
// Little-endian reads; memcpy, as the bytes need not be aligned.
std::uint64_t
Read64(const unsigned char * p)
{
  std::uint64_t v;
  std::memcpy(&v, p, sizeof v);
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  v = __builtin_bswap64(v);
#endif
  return v;
}
std::uint64_t
Read32(const unsigned char * p)
{
  std::uint32_t v;
  std::memcpy(&v, p, sizeof v);
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  v = __builtin_bswap32(v);
#endif
  return v;
}
std::uint64_t
Round(std::uint64_t accumulator, std::uint64_t input)
{
  accumulator += input * Prime2;
  return Rotate(accumulator, 31) * Prime1;
}
std::uint64_t
Merge(std::uint64_t accumulator, std::uint64_t value)
{
  accumulator ^= Round(0, value);
  return accumulator * Prime1 + Prime4;
}
} // namespace

std::uint64_t
Hash64(const void * data, std::size_t size, std::uint64_t seed)
{
  const auto *        p = static_cast<const unsigned char *>(data);
  const auto * const  end = p + size;
  std::uint64_t       h;
  if (size >= 32)
  {
    std::uint64_t v[4] = { seed + Prime1 + Prime2, seed + Prime2, seed, seed - Prime1 };
    for (; end - p >= 32; p += 32)
      for (int lane = 0; lane < 4; ++lane)
        v[lane] = Round(v[lane], Read64(p + 8 * lane));
    h = Rotate(v[0], 1) + Rotate(v[1], 7) + Rotate(v[2], 12) + Rotate(v[3], 18);
    for (int lane = 0; lane < 4; ++lane)
      h = Merge(h, v[lane]);
  }
  else
    h = seed + Prime5;
  h += static_cast<std::uint64_t>(size);
  for (; end - p >= 8; p += 8)
  {
    h ^= Round(0, Read64(p));
    h = Rotate(h, 27) * Prime1 + Prime4;
  }
  if (end - p >= 4)
  {
    h ^= Read32(p) * Prime1;
    h = Rotate(h, 23) * Prime2 + Prime3;
    p += 4;
  }
  for (; p < end; ++p)
  {
    h ^= *p * Prime5;
    h = Rotate(h, 11) * Prime1;
  }
  h ^= h >> 33;
  h *= Prime2;
  h ^= h >> 29;
  h *= Prime3;
  h ^= h >> 32;
  return h;
}

std::string
HashText(std::uint64_t hash)
{
  static const char digits[] = "0123456789abcdef";
  std::string       text(16, '0');
  for (int i = 15; i >= 0; --i, hash >>= 4)
    text[static_cast<std::size_t>(i)] = digits[hash & 15];
  return text;
}
} // namespace morea_core
