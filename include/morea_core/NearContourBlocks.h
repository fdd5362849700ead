// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the blocks of an image where an
// interpolated contour distance may lie below the guidance radius. Guidance
// counts only samples within the radius of a contour, and with tetrahedra far
// larger than the radius most samples of a tetrahedron near a contour are
// not: the CUDA texture sampling reads a sample's distance only in a marked
// block (a bit per block instead of a filtered fetch per sample).
#ifndef morea_NearContourBlocks_h
#define morea_NearContourBlocks_h

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace morea_core
{
struct ChannelVolume;

struct NearContourBlocks
{
  /** Edge of a block, in voxels. */
  static constexpr int BlockSize = 4;

  std::array<int, 3>        blocks{ { 0, 0, 0 } }; ///< per axis, ceil(size / BlockSize)
  /** Structures a mask holds (a bit each). */
  static constexpr int MaxStructures = 16;

  /** Per block, x fastest: bit g set where structure g may be near (0:
   *  near none). */
  std::vector<std::uint16_t> mask;

  /** The block of continuous voxel index `x` (voxel centres at integers):
   *  the one holding the first voxel of its trilinear footprint, floor(x),
   *  clamped to the grid as clamped interpolation reads it. (The CUDA
   *  sampling kernel computes the same in texel coordinates, x + 1/2.) */
  std::size_t
  BlockOf(const double x[3]) const
  {
    std::size_t index = 0;
    for (int a = 2; a >= 0; --a)
    {
      const double b = std::floor(x[a] / BlockSize);
      const int    clamped = b < 0.0 ? 0 : (b > blocks[a] - 1 ? blocks[a] - 1 : static_cast<int>(b));
      index = index * static_cast<std::size_t>(blocks[a]) + static_cast<std::size_t>(clamped);
    }
    return index;
  }
};

/** Marks each block of `volume` (channel 0 the intensity, then one distance
 *  map per structure, in mm; at most MaxStructures) with bit g where any
 *  voxel that a trilinear sample starting in the block reads, [BlockSize b,
 *  BlockSize b + BlockSize] per axis, has a distance to structure g below
 *  `radius` (plus a margin for rounding). An interpolated distance is never
 *  below the smallest of its voxels, so a sample in a block without bit g is
 *  at least `radius` from structure g's contour. Throws for more than
 *  MaxStructures structures. */
NearContourBlocks
FindNearContourBlocks(const ChannelVolume & volume, double radius);
} // namespace morea_core

#endif
