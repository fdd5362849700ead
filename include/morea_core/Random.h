// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: a seeded random generator whose sequence is
// the same on every platform and compiler (std::normal_distribution is not).
#ifndef morea_Random_h
#define morea_Random_h

#include <cstdint>

namespace morea_core
{
/** xoshiro256** seeded through SplitMix64. */
class RandomGenerator
{
public:
  explicit RandomGenerator(std::uint64_t seed = 0);

  std::uint64_t
  NextU64();
  /** Uniform in [0, 1). */
  double
  Uniform();
  /** Uniform in [low, high). */
  double
  Uniform(double low, double high);
  /** Standard normal (Box-Muller; the spare value is kept). */
  double
  Normal();

private:
  std::uint64_t m_State[4]{};
  double        m_SpareNormal{ 0.0 };
  bool          m_HasSpare{ false };
};

/** Mixes several values into one 64-bit hash (SplitMix64 finaliser). */
std::uint64_t
HashCombine(std::uint64_t a, std::uint64_t b);
} // namespace morea_core

#endif
