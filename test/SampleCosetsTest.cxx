// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of the order in which the CUDA texture path's warps take a
// tetrahedron's Sobol samples (morea/SampleCosets.h).
#include "morea_core/SampleCosets.h"

#include "morea_core/Error.h"
#include "morea_core/TetrahedronSampling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

namespace
{
using namespace morea_core;

TEST(SampleCosets, BlocksFollowTheBinaryDigitsOfTheWholeChunks)
{
  // 11 whole chunks: blocks of 8, 2 and 1 chunks (2^12, 2^10, 2^9 samples).
  const std::uint32_t expectedBits[11] = { 12, 12, 12, 12, 12, 12, 12, 12, 10, 10, 9 };
  const std::uint32_t expectedFirst[11] = { 0, 0, 0, 0, 0, 0, 0, 0, 8, 8, 10 };
  for (std::uint32_t c = 0; c < 11; ++c)
  {
    const CosetBlock b = WholeChunkBlock(11, c);
    EXPECT_EQ(b.bits, static_cast<int>(expectedBits[c])) << "chunk " << c;
    EXPECT_EQ(b.firstChunk, expectedFirst[c]) << "chunk " << c;
  }
  // 100 = 64 + 32 + 4 chunks: blocks larger than 2^MaxCosetBits are split
  // into aligned blocks of that size.
  EXPECT_EQ(WholeChunkBlock(100, 40).bits, MaxCosetBits);
  EXPECT_EQ(WholeChunkBlock(100, 40).firstChunk, 32u);
  EXPECT_EQ(WholeChunkBlock(100, 70).bits, MaxCosetBits);
  EXPECT_EQ(WholeChunkBlock(100, 70).firstChunk, 64u);
  EXPECT_EQ(WholeChunkBlock(100, 99).bits, 11);
  EXPECT_EQ(WholeChunkBlock(100, 99).firstChunk, 96u);
  EXPECT_EQ(WholeChunkBlock(1, 0).bits, 9);
}

TEST(SampleCosets, WholeChunksTakeEveryIndexOnce)
{
  const SampleCosetLayout &  layout = SampleCosets();
  std::vector<std::uint32_t> counts = { 512, 1023, 1024, 1536, 4095, 4096, 5000, 12345, 16384, 16896, 40000, 70000 };
  for (std::uint32_t n = 600; n < 9000; n += 997)
    counts.push_back(n);
  for (std::uint32_t n : counts)
  {
    const std::uint32_t whole = n / CosetChunkSamples;
    std::vector<int>    taken(whole * CosetChunkSamples, 0);
    for (std::uint32_t chunk = 0; chunk < whole; ++chunk)
      for (std::uint32_t row = 0; row < CosetRowsPerChunk; ++row)
        for (std::uint32_t lane = 0; lane < 32; ++lane)
        {
          const std::uint32_t index = CosetSampleIndex(layout, n, chunk, row, lane);
          ASSERT_LT(index, taken.size()) << n << " samples, chunk " << chunk;
          ++taken[index];
        }
    EXPECT_TRUE(std::all_of(taken.begin(), taken.end(), [](int t) { return t == 1; })) << n << " samples";
  }
  EXPECT_THROW(CosetSampleIndex(layout, 1000, 1, 0, 0), Error);
}

// The device composes a sample's Sobol state from the block's first index,
// the lane's offset and the rows' offsets; by linearity that is the state
// ScrambledSobol4 reaches at the sample's index.
TEST(SampleCosets, ComposedStatesAreTheSequencesStates)
{
  const SampleCosetLayout & layout = SampleCosets();
  const std::uint32_t       n = 20000; // blocks of 2^14, 2^11, 2^10 and 2^9
  ScrambledSobol4           sobol(99);
  std::vector<std::array<std::uint32_t, 4>> states(n);
  for (auto & s : states)
  {
    const auto u = sobol.Next();
    for (int d = 0; d < 4; ++d)
      s[d] = static_cast<std::uint32_t>(u[d] * 4294967296.0 - 0.5); // u = (state + 1/2) / 2^32
  }
  for (std::uint32_t chunk = 0; chunk < n / CosetChunkSamples; ++chunk)
  {
    const CosetBlock b = WholeChunkBlock(n / CosetChunkSamples, chunk);
    const int        level = b.bits - MinCosetBits;
    const std::uint32_t coset = CosetRowsPerChunk * (chunk - b.firstChunk);
    for (std::uint32_t row = 0; row < CosetRowsPerChunk; row += 5)
      for (std::uint32_t lane = 0; lane < 32; lane += 7)
      {
        auto                state = SobolStateOfOffset(b.firstChunk * CosetChunkSamples);
        const auto          lanePart = SobolStateOfOffset(layout.laneOffsets[level][lane]);
        const std::uint32_t gray = (coset + row) ^ ((coset + row) >> 1);
        for (int d = 0; d < 4; ++d)
          state[d] ^= lanePart[d];
        for (int bit = 0; bit < b.bits - 5; ++bit)
          if ((gray >> bit) & 1u)
          {
            const auto rowPart = SobolStateOfOffset(layout.rowOffsets[level][bit]);
            for (int d = 0; d < 4; ++d)
              state[d] ^= rowPart[d];
          }
        const std::uint32_t index = CosetSampleIndex(layout, n, chunk, row, lane);
        for (int d = 0; d < 4; ++d)
          ASSERT_EQ(state[d] ^ states[0][d], states[index][d]) << "chunk " << chunk << " row " << row << " lane " << lane;
      }
  }
}

/** Mean over rows of the largest distance of a row's points from their
 *  centroid, in barycentric coordinates of the unit simplex. */
double
MeanRowSpread(const std::vector<std::array<double, 4>> & points, const std::vector<std::uint32_t> & order)
{
  double sum = 0.0;
  for (std::size_t row = 0; row < order.size() / 32; ++row)
  {
    std::array<double, 4> centre{};
    for (std::size_t lane = 0; lane < 32; ++lane)
      for (int d = 0; d < 4; ++d)
        centre[d] += points[order[32 * row + lane]][d] / 32.0;
    double spread = 0.0;
    for (std::size_t lane = 0; lane < 32; ++lane)
    {
      double r = 0.0;
      for (int d = 0; d < 4; ++d)
        r += std::pow(points[order[32 * row + lane]][d] - centre[d], 2);
      spread = std::max(spread, std::sqrt(r));
    }
    sum += spread;
  }
  return sum / static_cast<double>(order.size() / 32);
}

// Each block size's W keeps a row's points closer together than 32
// consecutive samples, and than the 2^9 block's W applied to each 512 of a
// larger block (what the kernel did before blocks had their own W).
TEST(SampleCosets, RowsOfLargerBlocksStayClose)
{
  const SampleCosetLayout & layout = SampleCosets();
  for (int bits = MinCosetBits; bits <= MaxCosetBits; ++bits)
  {
    const std::uint32_t                n = std::uint32_t{ 1 } << bits;
    ScrambledSobol4                    sobol(1234 + bits);
    std::vector<std::array<double, 4>> points(n);
    for (auto & p : points)
      p = UniformBarycentric(sobol.Next());
    std::vector<std::uint32_t> consecutive(n), cosets, smallCosets;
    for (std::uint32_t i = 0; i < n; ++i)
      consecutive[i] = i;
    for (std::uint32_t chunk = 0; chunk < n / CosetChunkSamples; ++chunk)
      for (std::uint32_t row = 0; row < CosetRowsPerChunk; ++row)
        for (std::uint32_t lane = 0; lane < 32; ++lane)
        {
          cosets.push_back(CosetSampleIndex(layout, n, chunk, row, lane));
          smallCosets.push_back(chunk * CosetChunkSamples + CosetSampleIndex(layout, CosetChunkSamples, 0, row, lane));
        }
    const double a = MeanRowSpread(points, consecutive), b = MeanRowSpread(points, smallCosets),
                 c = MeanRowSpread(points, cosets);
    std::cout << "blocks of 2^" << bits << ": row spread " << a << " consecutive, " << b << " 2^9 cosets, " << c
              << " own cosets\n";
    EXPECT_LT(c, 0.8 * a) << "2^" << bits;
    if (bits > MinCosetBits)
      EXPECT_LT(c, b) << "2^" << bits;
  }
}
} // namespace
