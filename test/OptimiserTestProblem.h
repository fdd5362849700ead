// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Test helper: a small registration problem for the core optimiser, with no
// ITK: a 30 mm box meshed by 4x4x4 cubes, a fixed image with a bright ball
// and a moving image with the ball shifted and larger, and the ball as the one
// guidance structure (analytic distance maps).
#ifndef morea_test_OptimiserTestProblem_h
#define morea_test_OptimiserTestProblem_h

#include "BoxMesh.h"

#include "morea_core/EvaluationBackend.h"
#include "morea_core/FoldConstraint.h"
#include "morea_core/InitialPopulation.h"
#include "morea_core/MoRvGomea.h"
#include "morea_core/ObjectiveData.h"
#include "morea_core/ParallelStructure.h"
#include "morea_core/Random.h"
#include "morea_core/TetrahedronObjectives.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace morea_test
{
inline morea_core::ChannelVolume
BallImage(const morea_core::Vec3 & centre, double radius, double spacing, std::size_t size)
{
  morea_core::ChannelVolume v;
  v.size = { size, size, size };
  v.spacing = { spacing, spacing, spacing };
  v.origin = { 0.0, 0.0, 0.0 };
  v.channels = 2;
  v.data.resize(2 * size * size * size);
  for (std::size_t k = 0; k < size; ++k)
    for (std::size_t j = 0; j < size; ++j)
      for (std::size_t i = 0; i < size; ++i)
      {
        const double x = spacing * static_cast<double>(i) - centre[0];
        const double y = spacing * static_cast<double>(j) - centre[1];
        const double z = spacing * static_cast<double>(k) - centre[2];
        const double r = std::sqrt(x * x + y * y + z * z);
        const std::size_t o = 2 * (i + size * (j + size * k));
        // A soft edge keeps the intensity objective smooth; the first slab
        // is background (exactly 0) so the background rule is exercised.
        v.data[o] = i == 0 ? 0.0f : static_cast<float>(0.3 + 0.5 / (1.0 + std::exp((r - radius) / 1.0)));
        v.data[o + 1] = static_cast<float>(std::abs(r - radius));
      }
  return v;
}

struct OptimiserTestProblem
{
  morea_core::TetrahedralMesh               base;
  morea_core::MeshTopology                  topology;
  morea_core::ParallelStructure             parallel;
  std::unique_ptr<morea_core::FoldConstraint> constraint;
  std::vector<double>                  elasticity;
  morea_core::RigidityModel                 rigidity;
  morea_core::ObjectiveData                 data;
  std::unique_ptr<morea_core::TetrahedronEvaluator> evaluator;

  OptimiserTestProblem()
  {
    morea_core::MeshDomain domain;
    domain.lower = { 0.0, 0.0, 0.0 };
    domain.upper = { 30.0, 30.0, 30.0 };
    const BoxMesh box = MakeBoxMesh(domain, { 4, 4, 4 });
    base.domain = domain;
    base.points = Perturb(box, 0.15, 3);
    base.tetrahedra = box.tetrahedra;
    for (const auto & p : base.points)
    {
      base.pins.push_back(morea_core::PinOf(p, domain, 1e-9));
      base.origins.push_back(morea_core::PointOrigin::Random);
      base.structures.push_back(-1);
    }
    topology = morea_core::MeshTopology(base.tetrahedra, base.points.size());
    parallel = morea_core::BuildParallelStructure(topology);
    constraint = std::make_unique<morea_core::FoldConstraint>(topology, base.points);
    elasticity.assign(topology.NumberOfTetrahedra(), 1.0);
    data.fixed = BallImage({ 15.0, 15.0, 15.0 }, 6.0, 1.0, 31);
    data.moving = BallImage({ 17.0, 15.0, 14.0 }, 7.5, 1.0, 31);
    data.guidanceNames = { "ball" };
    data.guidanceWeights = { 1.0 };
    data.guidanceRadius = 3.0;
    data.samplingRate = 0.25;
    data.voxelVolume = 1.0;
    evaluator = std::make_unique<morea_core::TetrahedronEvaluator>(topology, *constraint, elasticity, data);
  }

  /** `n` guidance structures in place of the ball: structure g is a sphere
   *  whose centre lies on a ring about the ball's, its radius and weight
   *  differing with g, so that the contours cross and many places lie near
   *  several of them. The intensity stays; the evaluator reads the new maps. */
  void
  UseStructures(std::size_t n)
  {
    const auto rebuild = [n](morea_core::ChannelVolume & image, const morea_core::Vec3 & centre, double radius) {
      const std::size_t    voxels = image.size[0] * image.size[1] * image.size[2];
      std::vector<float>   out((1 + n) * voxels);
      const double         pi = 3.14159265358979323846;
      for (std::size_t v = 0; v < voxels; ++v)
      {
        out[(1 + n) * v] = image.data[image.channels * v];
        const std::size_t i = v % image.size[0], j = v / image.size[0] % image.size[1],
                          k = v / (image.size[0] * image.size[1]);
        const morea_core::Vec3 x{ { image.origin[0] + image.spacing[0] * static_cast<double>(i),
                               image.origin[1] + image.spacing[1] * static_cast<double>(j),
                               image.origin[2] + image.spacing[2] * static_cast<double>(k) } };
        for (std::size_t g = 0; g < n; ++g)
        {
          const double angle = 2.0 * pi * static_cast<double>(g) / static_cast<double>(n);
          const morea_core::Vec3 c{ { centre[0] + 4.0 * std::cos(angle), centre[1] + 4.0 * std::sin(angle),
                                 centre[2] + 1.5 * (static_cast<double>(g % 3) - 1.0) } };
          const double r = std::sqrt((x[0] - c[0]) * (x[0] - c[0]) + (x[1] - c[1]) * (x[1] - c[1]) +
                                     (x[2] - c[2]) * (x[2] - c[2]));
          out[(1 + n) * v + 1 + g] = static_cast<float>(std::abs(r - radius * (0.5 + 0.1 * static_cast<double>(g % 5))));
        }
      }
      image.channels = 1 + n;
      image.data = std::move(out);
    };
    rebuild(data.fixed, { { 15.0, 15.0, 15.0 } }, 6.0);
    rebuild(data.moving, { { 17.0, 15.0, 14.0 } }, 7.5);
    data.guidanceNames.clear();
    data.guidanceWeights.clear();
    double total = 0.0;
    for (std::size_t g = 0; g < n; ++g)
    {
      data.guidanceNames.push_back("sphere" + std::to_string(g));
      data.guidanceWeights.push_back(1.0 + 0.25 * static_cast<double>(g % 4));
      total += data.guidanceWeights.back();
    }
    for (double & w : data.guidanceWeights)
      w /= total;
  }

  /** A rigid slab: tetrahedra whose centroid has x < 10 mm wholly, those
   *  with x in [10, 15) half (as if straddling a bone's surface). The
   *  evaluator then adds the rigidity term with `weight`, and with a
   *  `strainLimit` its constraint. */
  void
  UseRigidSlab(double weight = 1000.0, double strainLimit = 0.0)
  {
    std::vector<double> fraction(topology.NumberOfTetrahedra(), 0.0);
    for (std::size_t t = 0; t < fraction.size(); ++t)
    {
      double x = 0.0;
      for (std::uint32_t p : topology.Tetrahedra()[t])
        x += 0.25 * base.points[p][0];
      fraction[t] = x < 10.0 ? 1.0 : x < 15.0 ? 0.5 : 0.0;
    }
    rigidity = morea_core::BuildRigidityModel(base, fraction, weight, strainLimit);
    evaluator = std::make_unique<morea_core::TetrahedronEvaluator>(topology, *constraint, elasticity, rigidity, data);
  }

  morea_core::GomeaOptions
  Options(std::uint64_t seed = 5, std::size_t generations = 8) const
  {
    morea_core::GomeaOptions o;
    o.populationSize = 24;
    o.numberOfClusters = 3;
    o.archiveCapacity = 40;
    o.generations = generations;
    o.steeringStart = 5;
    o.fullEvaluationInterval = 4;
    o.seed = seed;
    return o;
  }

  std::vector<morea_core::DualMesh>
  InitialPopulation(const morea_core::GomeaOptions & o) const
  {
    return morea_core::GenerateInitialPopulation(base, *constraint, o.populationSize, o.seed);
  }
};

/** Partial candidates of every element of `group` for each parent, their
 *  points moved by Gaussian steps of `sigma` mm per coordinate and kept in the
 *  domain, as the optimiser samples them; owns positions and outputs (the
 *  candidates point into it, so it is neither copied nor moved). */
struct RandomCandidates
{
  std::vector<std::vector<morea_core::Vec3>>              source, target;
  std::vector<std::vector<morea_core::TetrahedronValues>> values;
  std::vector<morea_core::CandidateFolds>                 folds;
  std::vector<morea_core::PartialCandidate>               candidates;

  RandomCandidates(const OptimiserTestProblem & problem, const std::vector<morea_core::DualMesh> & parents,
                   const std::vector<std::uint32_t> & group, double sigma, std::uint64_t seed)
  {
    morea_core::RandomGenerator random(seed);
    for (const morea_core::DualMesh & parent : parents)
      for (std::uint32_t e : group)
      {
        const morea_core::FosElement & element = problem.parallel.elements[e];
        std::vector<morea_core::Vec3>  s, t;
        for (std::uint32_t p : element.points)
        {
          morea_core::Vec3 a = parent.source[p], b = parent.target[p];
          for (int axis = 0; axis < 3; ++axis)
          {
            a[axis] += sigma * random.Normal();
            b[axis] += sigma * random.Normal();
          }
          s.push_back(morea_core::ProjectToDomain(a, problem.base.pins[p], problem.base.domain));
          t.push_back(morea_core::ProjectToDomain(b, problem.base.pins[p], problem.base.domain));
        }
        source.push_back(std::move(s));
        target.push_back(std::move(t));
        values.emplace_back(element.dependentTetrahedra.size());
        morea_core::PartialCandidate c;
        c.parent = &parent;
        c.element = &element;
        c.seed = random.NextU64();
        candidates.push_back(c);
      }
    folds.resize(candidates.size());
    for (std::size_t i = 0; i < candidates.size(); ++i)
    {
      candidates[i].source = source[i].data();
      candidates[i].target = target[i].data();
      candidates[i].values = values[i].data();
      candidates[i].folds = &folds[i];
    }
  }
  RandomCandidates(const RandomCandidates &) = delete;
  RandomCandidates &
  operator=(const RandomCandidates &) = delete;

  /** One side of candidate i as a whole mesh side: the parent's points with
   *  the element's replaced. */
  std::vector<morea_core::Vec3>
  Side(std::size_t i, int side) const
  {
    const morea_core::PartialCandidate & c = candidates[i];
    std::vector<morea_core::Vec3>        points = side == 0 ? c.parent->source : c.parent->target;
    for (std::size_t k = 0; k < c.element->points.size(); ++k)
      points[c.element->points[k]] = side == 0 ? c.source[k] : c.target[k];
    return points;
  }
};
} // namespace morea_test

#endif
