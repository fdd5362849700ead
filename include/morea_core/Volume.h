// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: a plain 3D voxel grid with axis-aligned
// physical geometry (the core's exchange format with the ITK layer).
#ifndef morea_Volume_h
#define morea_Volume_h

#include <array>
#include <cstddef>
#include <vector>

namespace morea_core
{
using Vec3 = std::array<double, 3>;

/** Voxel (i,j,k) is stored at i + size[0]*(j + size[1]*k); its centre is at
 *  origin + spacing * (i,j,k) in mm (identity direction). */
template <typename T>
struct Volume
{
  std::array<std::size_t, 3> size{ { 0, 0, 0 } };
  Vec3                       spacing{ { 1.0, 1.0, 1.0 } };
  Vec3                       origin{ { 0.0, 0.0, 0.0 } };
  std::vector<T>             data;

  Volume() = default;
  Volume(std::array<std::size_t, 3> s, Vec3 sp, Vec3 o, T fill = T{})
    : size(s)
    , spacing(sp)
    , origin(o)
    , data(s[0] * s[1] * s[2], fill)
  {}

  std::size_t
  NumberOfVoxels() const
  {
    return size[0] * size[1] * size[2];
  }
  std::size_t
  Offset(std::size_t i, std::size_t j, std::size_t k) const
  {
    return i + size[0] * (j + size[1] * k);
  }
  T &
  operator()(std::size_t i, std::size_t j, std::size_t k)
  {
    return data[Offset(i, j, k)];
  }
  const T &
  operator()(std::size_t i, std::size_t j, std::size_t k) const
  {
    return data[Offset(i, j, k)];
  }
  Vec3
  PointAt(std::size_t i, std::size_t j, std::size_t k) const
  {
    return { origin[0] + spacing[0] * static_cast<double>(i), origin[1] + spacing[1] * static_cast<double>(j),
             origin[2] + spacing[2] * static_cast<double>(k) };
  }
  /** Same grid, other pixel type. */
  template <typename U>
  Volume<U>
  Like(U fill = U{}) const
  {
    return Volume<U>(size, spacing, origin, fill);
  }
};
} // namespace morea_core

#endif
