// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// NearContourBlocks: a block is marked exactly when a voxel its samples can
// read is below the radius, and no interpolated distance below the radius
// falls in an unmarked block (the CUDA sampling skips its distance fetch
// there).
#include "morea_core/NearContourBlocks.h"
#include "morea_core/Error.h"
#include "morea_core/ObjectiveData.h"
#include "morea_core/Random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace morea_core;

namespace
{
/** Intensity plus two distance maps to points, on a grid of the given size
 *  whose edges are not multiples of the block size. */
ChannelVolume
DistanceVolume(std::size_t nx, std::size_t ny, std::size_t nz)
{
  ChannelVolume volume;
  volume.size = { { nx, ny, nz } };
  volume.spacing = { { 1.5, 1.5, 1.5 } };
  volume.origin = { { -10.0, 4.0, 2.5 } };
  volume.channels = 3;
  volume.data.resize(3 * nx * ny * nz);
  const double centres[2][3] = { { 4.0, 3.0, 2.0 }, { 12.5, 9.0, 8.0 } }; // in voxels
  std::size_t  v = 0;
  for (std::size_t z = 0; z < nz; ++z)
    for (std::size_t y = 0; y < ny; ++y)
      for (std::size_t x = 0; x < nx; ++x, ++v)
      {
        volume.data[3 * v] = 0.5f;
        for (int g = 0; g < 2; ++g)
        {
          const double dx = x - centres[g][0], dy = y - centres[g][1], dz = z - centres[g][2];
          volume.data[3 * v + 1 + g] = static_cast<float>(1.5 * std::sqrt(dx * dx + dy * dy + dz * dz));
        }
      }
  return volume;
}
} // namespace

TEST(NearContourBlocks, MarksTheBlocksWhoseFootprintsReachBelowTheRadius)
{
  const ChannelVolume     volume = DistanceVolume(17, 14, 11);
  const double            radius = 4.0;
  const NearContourBlocks near = FindNearContourBlocks(volume, radius);
  ASSERT_EQ(near.blocks[0], 5);
  ASSERT_EQ(near.blocks[1], 4);
  ASSERT_EQ(near.blocks[2], 3);
  ASSERT_EQ(near.mask.size(), 60u);

  // Brute force: voxels [4 b, 4 b + 4] per axis, clamped to the grid.
  constexpr int B = NearContourBlocks::BlockSize;
  std::size_t   marked = 0, both = 0;
  for (int bz = 0; bz < near.blocks[2]; ++bz)
    for (int by = 0; by < near.blocks[1]; ++by)
      for (int bx = 0; bx < near.blocks[0]; ++bx)
      {
        float nearest[2] = { 1e30f, 1e30f };
        for (std::size_t z = B * bz; z <= std::min<std::size_t>(B * bz + B, volume.size[2] - 1); ++z)
          for (std::size_t y = B * by; y <= std::min<std::size_t>(B * by + B, volume.size[1] - 1); ++y)
            for (std::size_t x = B * bx; x <= std::min<std::size_t>(B * bx + B, volume.size[0] - 1); ++x)
            {
              const std::size_t v = x + volume.size[0] * (y + volume.size[1] * z);
              for (int g = 0; g < 2; ++g)
                nearest[g] = std::min(nearest[g], volume.data[3 * v + 1 + g]);
            }
        const std::size_t block = bx + near.blocks[0] * (by + near.blocks[1] * static_cast<std::size_t>(bz));
        const int expected = (nearest[0] < radius ? 1 : 0) | (nearest[1] < radius ? 2 : 0);
        EXPECT_EQ(near.mask[block], expected) << "block " << bx << " " << by << " " << bz;
        marked += near.mask[block] != 0;
        both += near.mask[block] == 3;
      }
  EXPECT_GT(marked, 2u);
  EXPECT_LT(marked, near.mask.size() / 2) << "most blocks are far from both points";
  EXPECT_LT(both, marked) << "blocks near one point only";
}

TEST(NearContourBlocks, NoInterpolatedDistanceBelowTheRadiusFallsInAnUnmarkedBlock)
{
  const ChannelVolume     volume = DistanceVolume(13, 10, 9);
  const double            radius = 5.0;
  const NearContourBlocks near = FindNearContourBlocks(volume, radius);
  RandomGenerator         random(7);
  std::size_t             within = 0, skipped = 0;
  for (int i = 0; i < 200000; ++i)
  {
    // Continuous voxel indices, a little outside the grid too (clamped).
    double x[3];
    Vec3   p;
    for (int a = 0; a < 3; ++a)
    {
      x[a] = -1.0 + (static_cast<double>(volume.size[a]) + 1.0) * random.Uniform();
      p[a] = volume.origin[a] + x[a] * volume.spacing[a];
    }
    float values[3];
    volume.Sample(p, values);
    const std::uint16_t bits = near.mask[near.BlockOf(x)];
    within += std::min(values[1], values[2]) < radius;
    skipped += bits == 0;
    for (int g = 0; g < 2; ++g)
      if (values[1 + g] < radius)
        ASSERT_TRUE((bits >> g) & 1u) << "sample at " << x[0] << " " << x[1] << " " << x[2] << " distance "
                                      << values[1 + g] << " to structure " << g;
  }
  EXPECT_GT(within, 1000u);
  EXPECT_GT(skipped, 50000u) << "most samples need no distance";
}

TEST(NearContourBlocks, NoStructuresMarkNothing)
{
  ChannelVolume volume;
  volume.size = { { 9, 9, 9 } };
  volume.channels = 1;
  volume.data.assign(729, 0.2f);
  const NearContourBlocks near = FindNearContourBlocks(volume, 3.0);
  EXPECT_EQ(near.mask.size(), 27u);
  EXPECT_EQ(std::count(near.mask.begin(), near.mask.end(), 1), 0);
}

TEST(NearContourBlocks, AtMostSixteenStructures)
{
  ChannelVolume volume;
  volume.size = { { 2, 2, 2 } };
  volume.channels = 18;
  volume.data.assign(8 * 18, 1.0f);
  EXPECT_THROW(FindNearContourBlocks(volume, 3.0), Error);
  volume.channels = 17;
  volume.data.assign(8 * 17, 1.0f);
  EXPECT_EQ(FindNearContourBlocks(volume, 3.0).mask[0], 0xffff);
  // Only the structures near a block: the 9th and the 16th here.
  for (std::size_t v = 0; v < 8; ++v)
    for (std::size_t g = 0; g < 16; ++g)
      volume.data[17 * v + 1 + g] = g == 8 || g == 15 ? 1.0f : 10.0f;
  EXPECT_EQ(FindNearContourBlocks(volume, 3.0).mask[0], 0x8100);
}
