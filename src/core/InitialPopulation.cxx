// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/InitialPopulation.h"

#include "morea_core/ParallelForThreads.h"
#include "morea_core/ParameterSet.h"

#include <algorithm>
#include <cmath>

namespace morea_core
{
namespace
{
struct Kernel
{
  Vec3   centre;
  double weight;
  double inverseTwoSigmaSquared;
};
bool
WithinVolumeRatio(const std::vector<Vec3> & points, const TetrahedralMesh & base, double limit)
{
  for (const Tetrahedron & t : base.tetrahedra)
  {
    const double ratio = SignedVolume(t, points) / SignedVolume(t, base.points);
    if (!(ratio * limit >= 1.0 && ratio <= limit))
      return false;
  }
  return true;
}
} // namespace

InitialPopulationOptions
InitialPopulationOptions::FromParameters(const ParameterSet & parameters)
{
  InitialPopulationOptions options;
  options.noiseFactor = parameters.GetString("morea_init_noise_method") == "none"
                          ? 0.0
                          : parameters.GetReal("morea_init_noise_factor");
  return options;
}

std::size_t
ApplyRadialBasisDeformation(std::vector<Vec3> & points, const TetrahedralMesh & base,
                            const FoldConstraint & constraint, RandomGenerator & random,
                            const InitialPopulationOptions & options)
{
  const Vec3   extent = base.domain.Extent();
  const double minExtent = std::min({ extent[0], extent[1], extent[2] });
  std::vector<Kernel> kernels;
  for (std::size_t k = 0; k < options.kernelsPerMesh; ++k)
  {
    Kernel kernel;
    for (int a = 0; a < 3; ++a)
      kernel.centre[a] = random.Uniform(base.domain.lower[a], base.domain.upper[a]);
    kernel.weight = random.Uniform(0.2, 1.0);
    const double sigma = random.Uniform(0.25, 0.5) * minExtent;
    kernel.inverseTwoSigmaSquared = 1.0 / (2.0 * sigma * sigma);
    kernels.push_back(kernel);
  }
  const std::size_t rounds =
    std::min(options.maxRounds, 1 + static_cast<std::size_t>(random.Uniform() * static_cast<double>(options.maxRounds)));
  const double      step = options.roundStep * options.noiseFactor * minExtent;
  if (!(step > 0.0) || kernels.empty())
    return 0;

  // The pull field is fixed per mesh; rounds follow it in small steps so each
  // one can be checked for folds.
  std::vector<Vec3> pull(points.size());
  std::size_t       applied = 0;
  std::vector<Vec3> trial(points.size());
  double            roundStep = step;
  for (std::size_t r = 0, refusals = 0; r < rounds && refusals < 4; ++r)
  {
    double largest = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i)
    {
      Vec3 d{ { 0.0, 0.0, 0.0 } };
      for (const Kernel & k : kernels)
      {
        const Vec3   towards{ { k.centre[0] - points[i][0], k.centre[1] - points[i][1], k.centre[2] - points[i][2] } };
        const double r2 = towards[0] * towards[0] + towards[1] * towards[1] + towards[2] * towards[2];
        const double g = k.weight * std::exp(-r2 * k.inverseTwoSigmaSquared);
        for (int a = 0; a < 3; ++a)
          d[a] += g * towards[a];
      }
      pull[i] = d;
      largest = std::max(largest, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    }
    if (!(largest > 0.0))
      break;
    const double scale = roundStep / largest;
    for (std::size_t i = 0; i < points.size(); ++i)
    {
      const Vec3 moved{ { points[i][0] + scale * pull[i][0], points[i][1] + scale * pull[i][1],
                          points[i][2] + scale * pull[i][2] } };
      trial[i] = ProjectToDomain(moved, base.pins[i], base.domain);
    }
    if (!constraint.Evaluate(trial).Feasible() || !WithinVolumeRatio(trial, base, options.volumeRatioLimit))
    {
      // Refused: the same pull would be refused again, so go on in smaller steps.
      roundStep *= 0.5;
      ++refusals;
      continue;
    }
    points.swap(trial);
    ++applied;
  }
  return applied;
}

std::vector<DualMesh>
GenerateInitialPopulation(const TetrahedralMesh & base, const FoldConstraint & constraint, std::size_t size,
                          std::uint64_t seed, const InitialPopulationOptions & options)
{
  std::vector<DualMesh> population(size, DualMesh::FromBase(base));
  // Solution 0 stays the base mesh.
  ParallelForOnNewThreads(size > 0 ? size - 1 : 0, [&](std::size_t item) {
    const std::size_t i = item + 1;
    RandomGenerator   random(HashCombine(HashCombine(seed, 0x696e6974ull), i)); // "init"
    ApplyRadialBasisDeformation(population[i].source, base, constraint, random, options);
    ApplyRadialBasisDeformation(population[i].target, base, constraint, random, options);
  });
  return population;
}
} // namespace morea_core
