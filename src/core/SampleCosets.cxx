// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/SampleCosets.h"

#include "morea_core/Error.h"
#include "morea_core/TetrahedronSampling.h"

#include <string>
#include <vector>

namespace morea_core
{
namespace
{
/** W's basis for each block size, as index offsets (tools/cosets/sobol-warp-cosets.py:
 *  for 2^9 grown from the closest offsets; for larger blocks (--bits B) the
 *  elementary box shape, of all whose top-bit counts lie within 2 of each
 *  other, whose cosets touch the fewest 4 x 4 x 2-texel blocks in a
 *  tetrahedron of 1.5 x 2^B voxels; for 2^12 three shapes tie). Blocks per
 *  row of 32, against 32 consecutive samples and against the 2^9 W in each
 *  aligned 512: 2^10: 23.0 (53.5, 27.1), 2^11: 24.9 (61.3, 34.9), 2^12: 27.2
 *  (67.1, 44.5), 2^13: 28.8 (70.1, 54.2), 2^14: 30.8 (72.0, 62.4). */
constexpr std::uint32_t CosetBases[CosetLevels][5] = {
  { 216, 392, 464, 332, 432 },         // 2^9
  { 516, 264, 784, 576, 128 },         // 2^10: top bits (1, 1, 1, 2)
  { 516, 264, 912, 1696, 576 },        // 2^11: (1, 2, 1, 2)
  { 3204, 3976, 3344, 2080, 576 },     // 2^12: (1, 2, 2, 2)
  { 6408, 3344, 2080, 576, 5760 },     // 2^13: (2, 2, 2, 2)
  { 6408, 12816, 14112, 15680, 10624 } // 2^14: (2, 2, 2, 3)
};

SampleCosetLayout
BuildLayout()
{
  SampleCosetLayout layout;
  for (int level = 0; level < CosetLevels; ++level)
  {
    const int                  bits = MinCosetBits + level;
    const std::uint32_t        size = std::uint32_t{ 1 } << bits;
    std::vector<bool>          spanned(size, false);
    std::vector<std::uint32_t> members{ 0 };
    spanned[0] = true;
    // Adds v to the span if it is independent: the span doubles.
    const auto add = [&](std::uint32_t v) {
      if (v >= size || spanned[v])
        return false;
      for (std::size_t i = 0, count = members.size(); i < count; ++i)
      {
        members.push_back(members[i] ^ v);
        spanned[members.back()] = true;
      }
      return true;
    };
    for (std::uint32_t v : CosetBases[level])
      if (!add(v))
        throw Error("sample cosets: the basis for blocks of 2^" + std::to_string(bits) + " is not independent");
    for (std::uint32_t lane = 0; lane < 32; ++lane)
    {
      std::uint32_t x = 0;
      for (int b = 0; b < 5; ++b)
        if ((lane >> b) & 1u)
          x ^= CosetBases[level][b];
      layout.laneOffsets[level][lane] = x;
    }
    // The complement from unit vectors, lowest first.
    int rows = 0;
    for (int b = 0; b < bits; ++b)
      if (add(std::uint32_t{ 1 } << b))
        layout.rowOffsets[level][rows++] = std::uint32_t{ 1 } << b;
    if (rows != bits - 5)
      throw Error("sample cosets: no complement spans the blocks of 2^" + std::to_string(bits));
  }
  return layout;
}
} // namespace

const SampleCosetLayout &
SampleCosets()
{
  static const SampleCosetLayout layout = BuildLayout();
  return layout;
}

std::uint32_t
CosetSampleIndex(const SampleCosetLayout & layout, std::uint32_t samples, std::uint32_t chunk, std::uint32_t row,
                 std::uint32_t lane)
{
  const std::uint32_t wholeChunks = samples / CosetChunkSamples;
  if (chunk >= wholeChunks || row >= CosetRowsPerChunk || lane >= 32)
    throw Error("sample cosets: no such sample of a whole chunk");
  const CosetBlock    block = WholeChunkBlock(wholeChunks, chunk);
  const int           level = block.bits - MinCosetBits;
  const std::uint32_t coset = CosetRowsPerChunk * (chunk - block.firstChunk) + row;
  const std::uint32_t gray = coset ^ (coset >> 1);
  std::uint32_t       index = block.firstChunk * CosetChunkSamples ^ layout.laneOffsets[level][lane];
  for (int b = 0; b < block.bits - 5; ++b)
    if ((gray >> b) & 1u)
      index ^= layout.rowOffsets[level][b];
  return index;
}

std::array<std::uint32_t, 4>
SobolStateOfOffset(std::uint32_t x, const std::uint32_t * directions)
{
  if (directions == nullptr)
    directions = SobolDirectionNumbers();
  const std::uint32_t          gray = x ^ (x >> 1);
  std::array<std::uint32_t, 4> state{};
  for (int b = 0; b < 32; ++b)
    if ((gray >> b) & 1u)
      for (int d = 0; d < 4; ++d)
        state[d] ^= directions[d * 32 + b];
  return state;
}
} // namespace morea_core
