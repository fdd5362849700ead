// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: what the intensity and guidance objectives
// sample (SPEC 5): per image one multi-channel volume holding the windowed
// intensity and, per guidance structure, the distance to its contour, so that
// one trilinear weight computation serves all channels of a sample.
#ifndef morea_ObjectiveData_h
#define morea_ObjectiveData_h

#include "morea_core/Volume.h"

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

namespace morea_core
{
/** Channels interleaved per voxel: data[channels * voxelOffset + c]. Grid as
 *  in Volume (voxel centre = origin + spacing * index, domain frame, mm). */
struct ChannelVolume
{
  std::array<std::size_t, 3> size{ { 0, 0, 0 } };
  Vec3                       spacing{ { 1.0, 1.0, 1.0 } };
  Vec3                       origin{ { 0.0, 0.0, 0.0 } };
  std::size_t                channels{ 0 };
  std::vector<float>         data;

  /** Trilinear interpolation of all channels at `p` (clamped to the grid);
   *  writes `channels` values to `out`. */
  void
  Sample(const Vec3 & p, float * out) const
  {
    std::size_t base[3];
    double      f[3];
    for (int a = 0; a < 3; ++a)
    {
      double x = (p[a] - origin[a]) / spacing[a];
      const double last = static_cast<double>(size[a] - 1);
      x = x < 0.0 ? 0.0 : (x > last ? last : x);
      double i = std::floor(x);
      if (i >= last && size[a] > 1)
        i = last - 1.0;
      base[a] = static_cast<std::size_t>(i);
      f[a] = size[a] > 1 ? x - i : 0.0;
    }
    const std::size_t sx = size[0] > 1 ? channels : 0;
    const std::size_t sy = size[1] > 1 ? channels * size[0] : 0;
    const std::size_t sz = size[2] > 1 ? channels * size[0] * size[1] : 0;
    const float *     v = data.data() + channels * (base[0] + size[0] * (base[1] + size[1] * base[2]));
    const double      w[8] = { (1 - f[0]) * (1 - f[1]) * (1 - f[2]), f[0] * (1 - f[1]) * (1 - f[2]),
                               (1 - f[0]) * f[1] * (1 - f[2]),       f[0] * f[1] * (1 - f[2]),
                               (1 - f[0]) * (1 - f[1]) * f[2],       f[0] * (1 - f[1]) * f[2],
                               (1 - f[0]) * f[1] * f[2],             f[0] * f[1] * f[2] };
    const std::size_t o[8] = { 0, sx, sy, sx + sy, sz, sx + sz, sy + sz, sx + sy + sz };
    for (std::size_t c = 0; c < channels; ++c)
    {
      double s = 0.0;
      for (int k = 0; k < 8; ++k)
        s += w[k] * static_cast<double>(v[o[k] + c]);
      out[c] = static_cast<float>(s);
    }
  }
};

/** Everything the image objectives read, in the mesh's domain frame. */
struct ObjectiveData
{
  /** Channel 0: intensity in [0, 1], exactly 0 for background (outside the
   *  body or the field of view); channel 1 + g: distance in mm from the voxel
   *  centre to the contour (surface) of guidance structure g. */
  ChannelVolume fixed;
  ChannelVolume moving;
  std::vector<std::string> guidanceNames;
  /** Per guidance structure |C_g| / |G|: its share of all contour points. */
  std::vector<double> guidanceWeights;
  double              guidanceRadius{ 0.0 }; ///< r in mm: only samples within r of a contour count
  double              samplingRate{ 1.0 };   ///< samples per voxel volume
  double              voxelVolume{ 1.0 };    ///< mm^3 of one voxel of the fixed grid

  std::size_t
  NumberOfGuidanceStructures() const
  {
    return guidanceWeights.size();
  }
};

/** The guidance radius of SPEC 5: 2.5 % of the image width (the largest extent
 *  of the domain). */
inline double
DefaultGuidanceRadius(const Vec3 & domainExtent)
{
  double w = 0.0;
  for (double e : domainExtent)
    w = e > w ? e : w;
  return 0.025 * w;
}
} // namespace morea_core

#endif
