// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/NearContourBlocks.h"

#include "morea_core/Error.h"
#include "morea_core/ObjectiveData.h"

#include <algorithm>
#include <limits>
#include <string>

namespace morea_core
{
NearContourBlocks
FindNearContourBlocks(const ChannelVolume & volume, double radius)
{
  constexpr std::size_t B = NearContourBlocks::BlockSize;
  NearContourBlocks     out;
  std::size_t           n[3];
  for (int a = 0; a < 3; ++a)
  {
    n[a] = (volume.size[a] + B - 1) / B;
    out.blocks[a] = static_cast<int>(n[a]);
  }
  if (volume.channels > 1 + NearContourBlocks::MaxStructures)
    throw Error("near-contour blocks: at most " + std::to_string(NearContourBlocks::MaxStructures) +
                " structures, not " + std::to_string(volume.channels - 1));
  out.mask.assign(n[0] * n[1] * n[2], 0);
  // The texture filter rounds its weights and sums in single precision.
  const double limit = radius * (1.0 + 1e-5) + 1e-6;
  std::size_t  v = 0;
  for (std::size_t z = 0; z < volume.size[2]; ++z)
    for (std::size_t y = 0; y < volume.size[1]; ++y)
      for (std::size_t x = 0; x < volume.size[0]; ++x, ++v)
      {
        std::uint16_t structures = 0;
        for (std::size_t g = 1; g < volume.channels; ++g)
          if (volume.data[volume.channels * v + g] < limit)
            structures |= static_cast<std::uint16_t>(1u << (g - 1));
        if (structures == 0)
          continue;
        // Voxel i lies in the ranges of block i / B and, on a block's first
        // voxel, of the block before.
        const std::size_t at[3] = { x, y, z };
        std::size_t       from[3], to[3];
        for (int a = 0; a < 3; ++a)
        {
          to[a] = at[a] / B;
          from[a] = at[a] % B == 0 && at[a] > 0 ? to[a] - 1 : to[a];
        }
        for (std::size_t bz = from[2]; bz <= to[2]; ++bz)
          for (std::size_t by = from[1]; by <= to[1]; ++by)
            for (std::size_t bx = from[0]; bx <= to[0]; ++bx)
              out.mask[(bz * n[1] + by) * n[0] + bx] |= structures;
      }
  return out;
}
} // namespace morea_core
