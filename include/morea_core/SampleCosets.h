// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the order in which a GPU's warps take a
// tetrahedron's Sobol samples (the CUDA backend's texture path).
//
// A tetrahedron's sample k is the scrambled Sobol point of Gray code
// k ^ (k >> 1). The Gray code and the direction numbers are linear over XOR,
// so within an aligned block of 2^B indices, samples whose indices differ by
// x differ by the same XOR of direction numbers wherever the block lies. A
// warp's 32 lanes take one coset of a 5-dimensional index subspace W chosen
// for each B so that its points lie close together (they share the top bits
// of every Sobol coordinate, an elementary box), and so read fewer texture
// sectors than 32 consecutive samples spread over the whole tetrahedron.
//
// The samples of a whole chunk (512) are taken in 16 rows of 32. A task of n
// samples has floor(n / 512) whole chunks, split into aligned blocks by the
// binary digits of that count (the largest first), each block of 2^(B - 9)
// chunks up to B = MaxCosetBits; a block's 2^(B - 5) cosets are taken in
// Gray-code order over a complement of W, 16 per chunk. The points are those
// of indices 0 .. 512 floor(n / 512) - 1, each once; only the order in which
// they are summed differs from the CPU's.
//
// Plain inline code: nvcc compiles WholeChunkBlock for the device.
#ifndef morea_SampleCosets_h
#define morea_SampleCosets_h

#include <array>
#include <cstdint>

#ifndef MOREA_HOST_DEVICE
#  ifdef __CUDACC__
#    define MOREA_HOST_DEVICE __host__ __device__
#  else
#    define MOREA_HOST_DEVICE
#  endif
#endif

namespace morea_core
{
constexpr std::uint32_t CosetChunkSamples = 512;
constexpr std::uint32_t CosetRowsPerChunk = 16;
constexpr int           MinCosetBits = 9; ///< a whole chunk
constexpr int           MaxCosetBits = 14;
constexpr int           CosetLevels = MaxCosetBits - MinCosetBits + 1;
constexpr int           MaxCosetRowBits = MaxCosetBits - 5;

/** The block of whole chunks that chunk `chunk` of a task with `wholeChunks`
 *  whole chunks belongs to: its size 2^bits samples and its first chunk. */
struct CosetBlock
{
  int           bits;
  std::uint32_t firstChunk;
};

MOREA_HOST_DEVICE inline CosetBlock
WholeChunkBlock(std::uint32_t wholeChunks, std::uint32_t chunk)
{
  // Blocks follow the binary digits of wholeChunks from the highest: chunk
  // lies in the block of the highest bit where it differs from the count.
  std::uint32_t differ = wholeChunks ^ chunk;
  int           level = 31;
  while (level > 0 && !((differ >> level) & 1u))
    --level;
  if (level > MaxCosetBits - MinCosetBits)
    level = MaxCosetBits - MinCosetBits;
  return CosetBlock{ MinCosetBits + level, chunk & ~((std::uint32_t{ 1 } << level) - 1u) };
}

/** Index offsets for each block size (level = B - MinCosetBits): each lane's
 *  element of W, and a basis of a complement of W (the rows' steps). */
struct SampleCosetLayout
{
  std::array<std::array<std::uint32_t, 32>, CosetLevels>              laneOffsets{};
  std::array<std::array<std::uint32_t, MaxCosetRowBits>, CosetLevels> rowOffsets{};
};

/** The layout, built from the chosen bases once; throws Error if a basis does
 *  not span its block with its complement (a wrong table). */
const SampleCosetLayout &
SampleCosets();

/** The sample index that lane `lane` takes in row `row` of whole chunk
 *  `chunk` (chunk < samples / 512) of a task of `samples` samples. */
std::uint32_t
CosetSampleIndex(const SampleCosetLayout & layout, std::uint32_t samples, std::uint32_t chunk, std::uint32_t row,
                 std::uint32_t lane);

/** The unshifted Sobol state of the samples whose indices differ by `x`
 *  within an aligned block: the XOR of the direction numbers of x's Gray code
 *  (4 dimensions x 32 bits, row-major; by default SobolDirectionNumbers()). */
std::array<std::uint32_t, 4>
SobolStateOfOffset(std::uint32_t x, const std::uint32_t * directions = nullptr);
} // namespace morea_core

#endif
