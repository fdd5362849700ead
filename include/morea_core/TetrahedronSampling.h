// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: sample points inside a tetrahedron
// (SPEC 5, intensity objective): barycentric coordinates from a 4D Sobol
// sequence, scrambled by a digital shift seeded from the tetrahedron's own
// coordinates, so the same configuration always gets the same samples.
#ifndef morea_TetrahedronSampling_h
#define morea_TetrahedronSampling_h

#include "morea_core/TetrahedralMesh.h"

#include <array>
#include <cstdint>

namespace morea_core
{
/** The first four dimensions of the Sobol sequence (Joe-Kuo direction
 *  numbers), 32-bit, in Gray-code order, XOR-shifted by a seed. */
class ScrambledSobol4
{
public:
  explicit ScrambledSobol4(std::uint64_t seed);

  /** The next point, each coordinate in (0, 1) (never 0, so -log is finite). */
  std::array<double, 4>
  Next();

private:
  std::array<std::uint32_t, 4> m_State{};
  std::array<std::uint32_t, 4> m_Shift{};
  std::uint32_t                m_Index{ 0 };
};

/** The direction numbers ScrambledSobol4 uses: 4 dimensions x 32 bits,
 *  row-major (a CUDA backend copies them to reproduce the same samples). */
const std::uint32_t *
SobolDirectionNumbers();

/** A seed from the exact bit patterns of the four corners. */
std::uint64_t
TetrahedronSeed(const Vec3 & a, const Vec3 & b, const Vec3 & c, const Vec3 & d);

/** Barycentric weights uniform in the tetrahedron: -log(u_i), normalised. */
inline std::array<double, 4>
UniformBarycentric(const std::array<double, 4> & u);
} // namespace morea_core

#include <cmath>

namespace morea_core
{
inline std::array<double, 4>
UniformBarycentric(const std::array<double, 4> & u)
{
  std::array<double, 4> w{};
  double                sum = 0.0;
  for (int i = 0; i < 4; ++i)
    sum += (w[i] = -std::log(u[i]));
  for (double & x : w)
    x /= sum;
  return w;
}
} // namespace morea_core

#endif
