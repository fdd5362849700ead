// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The memory a run needs against what is free (MemoryEstimate.h), and the
// optimiser's part of it (MoRvGomea::MemoryFor), counted from the types it
// keeps (MoRvGomeaParts.h).
#include "MoRvGomeaParts.h"

#include "morea_core/Error.h"
#include "morea_core/EvaluationBackend.h"
#include "morea_core/MemoryEstimate.h"
#include "morea_core/ParameterSet.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace morea_core
{
namespace
{
constexpr double GiB = 1024.0 * 1024.0 * 1024.0;

std::string
GiBText(double bytes)
{
  char text[32];
  std::snprintf(text, sizeof text, bytes < 10.0 * GiB ? "%.2f GiB" : "%.0f GiB", bytes / GiB);
  return text;
}

std::optional<double>
ReadNumber(const char * path)
{
  std::ifstream in(path);
  double        value = 0.0;
  if (in >> value)
    return value;
  return std::nullopt;
}

/** `key`'s value in a file of "key value [unit]" lines (meminfo, memory.stat). */
std::optional<double>
ReadKeyedNumber(const char * path, const std::string & key)
{
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);)
  {
    std::istringstream fields(line);
    std::string        name;
    double             value = 0.0;
    if (fields >> name >> value && name == key)
      return value;
  }
  return std::nullopt;
}

/** Room left under the process's cgroup memory limit (containers, CI
 *  runners), counting the page cache it could drop as free; empty when no
 *  limit is set. */
std::optional<double>
CgroupRoom()
{
  struct Layout
  {
    const char * limit;
    const char * usage;
    const char * stat;
    const char * inactiveFile;
  };
  static const Layout layouts[] = {
    { "/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current", "/sys/fs/cgroup/memory.stat", "inactive_file" },
    { "/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes",
      "/sys/fs/cgroup/memory/memory.stat", "total_inactive_file" },
  };
  for (const Layout & l : layouts)
  {
    const auto limit = ReadNumber(l.limit); // "max" (no limit) reads as nothing
    const auto usage = ReadNumber(l.usage);
    if (!limit || !usage || *limit >= 1e18)
      continue;
    const double reclaimable = ReadKeyedNumber(l.stat, l.inactiveFile).value_or(0.0);
    return std::max(0.0, *limit - *usage + reclaimable);
  }
  return std::nullopt;
}

/** "a population of 700 (ea_population_size) on a mesh of 600 points and
 *  3644 tetrahedra". */
std::string
RunText(const RunShape & shape, bool atLeast)
{
  return "a population of " + std::to_string(shape.population) + " (ea_population_size) and an archive of " +
         std::to_string(shape.archiveCapacity) + " (ea_archive_size) on a mesh of " +
         (atLeast ? std::to_string(shape.points) + " points (morea_mesh_num_points)"
                  : std::to_string(shape.points) + " points and " + std::to_string(shape.tetrahedra) + " tetrahedra");
}

/** The largest population whose `fixed` + `perSolution` x population fits
 *  in `available`, or "" when not even the fixed part fits. From a lower
 *  bound of the cost (`atLeast`) it is an upper bound. */
std::string
PopulationThatFits(double fixed, double perSolution, double available, bool atLeast)
{
  if (perSolution <= 0.0 || available <= fixed)
    return {};
  const double fits = std::floor((available - fixed) / perSolution);
  if (fits < 2.0)
    return {};
  return std::string(atLeast ? " (at most about " : " (about ") +
         std::to_string(static_cast<long long>(std::min(fits, 1e15))) + " fit)";
}
} // namespace

MemoryEstimate
operator+(const MemoryEstimate & a, const MemoryEstimate & b)
{
  MemoryEstimate sum;
  sum.hostFixed = a.hostFixed + b.hostFixed;
  sum.hostPerSolution = a.hostPerSolution + b.hostPerSolution;
  sum.deviceFixed = a.deviceFixed + b.deviceFixed;
  sum.devicePerSolution = a.devicePerSolution + b.devicePerSolution;
  sum.device = a.device >= 0 ? a.device : b.device;
  return sum;
}

RunShape
RunShapeOf(const GomeaOptions & options, const MeshTopology & topology, const ParallelStructure & parallel)
{
  RunShape shape;
  shape.population = options.populationSize;
  shape.archiveCapacity = options.archiveCapacity;
  shape.clusters = options.numberOfClusters;
  shape.points = topology.NumberOfPoints();
  shape.tetrahedra = topology.NumberOfTetrahedra();
  shape.elements = parallel.elements.size();
  for (const FosElement & e : parallel.elements)
  {
    const std::size_t variables = 6 * e.points.size();
    shape.modelDoubles += variables + variables * variables;
  }
  for (const auto & group : parallel.groups)
  {
    std::size_t points = 0, tetrahedra = 0;
    for (std::uint32_t e : group)
    {
      points += parallel.elements[e].points.size();
      tetrahedra += parallel.elements[e].dependentTetrahedra.size();
    }
    // The batch with the most candidate storage: its values dominate.
    if (tetrahedra > shape.groupTetrahedra || (tetrahedra == shape.groupTetrahedra && group.size() > shape.groupElements))
    {
      shape.groupElements = group.size();
      shape.groupPoints = points;
      shape.groupTetrahedra = tetrahedra;
    }
  }
  return shape;
}

RunShape
RunShapeAtLeast(const GomeaOptions & options, std::size_t points)
{
  RunShape shape;
  shape.population = options.populationSize;
  shape.archiveCapacity = options.archiveCapacity;
  shape.clusters = options.numberOfClusters;
  shape.points = points;
  shape.tetrahedra = points > 3 ? points - 3 : 0;
  shape.elements = (points + 1) / 2;
  shape.modelDoubles = shape.elements * (12 + 12 * 12); // edges: 2 points, 12 variables
  shape.groupElements = 1;
  shape.groupPoints = 2;
  shape.groupTetrahedra = 1;
  return shape;
}

MemoryEstimate
MoRvGomea::MemoryFor(const RunShape & shape)
{
  const double points = static_cast<double>(shape.points);
  const double solution = static_cast<double>(sizeof(DualMesh)) + 2.0 * points * sizeof(Vec3);

  // Per solution of the population: its points, its tetrahedra's values,
  // its element sums (and their stale flags), the small per-solution state,
  // and its candidates in each of the three batches (the largest group's).
  double perSolution = solution;
  perSolution += static_cast<double>(shape.tetrahedra) * sizeof(TetrahedronValues) +
                 sizeof(std::vector<TetrahedronValues>);
  perSolution += static_cast<double>(shape.elements) * (sizeof(TetrahedronValues) + sizeof(std::uint8_t));
  perSolution += sizeof(std::uint64_t) + sizeof(ObjectiveTotals) + sizeof(std::size_t) + 3 * sizeof(Fitness);
  constexpr double candidate =
    sizeof(Candidate) + sizeof(PartialCandidate) + sizeof(CandidateFolds) + sizeof(RefusalBound) +
    2 * sizeof(TetrahedronValues) /* sum, change */ + sizeof(ArchiveVerdict) + 2 * sizeof(Fitness) +
    sizeof(std::uint32_t) + sizeof(std::uint8_t) + sizeof(std::size_t);
  const double batch = static_cast<double>(shape.groupElements) * candidate +
                       static_cast<double>(shape.groupPoints) * (2 * sizeof(Vec3) + 6 * sizeof(double)) +
                       static_cast<double>(shape.groupTetrahedra) * sizeof(TetrahedronValues) +
                       sizeof(CandidateBatch::Judged::Chain) + sizeof(std::size_t);
  perSolution += 3.0 * batch;

  // The archive (one over its capacity before thinning), the distributions
  // of k clusters and one per objective (the generation's models and the
  // states kept between generations), and each tetrahedron's elements.
  double fixed = static_cast<double>(shape.archiveCapacity + 1) * (sizeof(ArchiveEntry) + 2.0 * points * sizeof(Vec3));
  const double clusters = static_cast<double>(shape.clusters + NumberOfObjectives);
  fixed += clusters * (static_cast<double>(shape.modelDoubles) * sizeof(double) +
                       static_cast<double>(shape.elements) * (sizeof(DistributionState) + 2 * sizeof(std::vector<double>)));
  fixed += static_cast<double>(shape.tetrahedra) * 7 * sizeof(std::uint32_t);

  // Checkpoints: the state as bytes, being written, and the buffer kept for
  // the next one.
  if (shape.checkpoints)
  {
    perSolution += 2.0 * 2.0 * points * sizeof(Vec3);
    fixed += 2.0 * static_cast<double>(shape.archiveCapacity) * 2.0 * points * sizeof(Vec3);
  }
  MemoryEstimate estimate;
  estimate.hostFixed = fixed;
  estimate.hostPerSolution = perSolution;
  return estimate;
}

std::optional<double>
AvailableHostMemory()
{
  const auto kib = ReadKeyedNumber("/proc/meminfo", "MemAvailable:");
  std::optional<double> available;
  if (kib)
    available = *kib * 1024.0;
  if (const auto room = CgroupRoom())
    available = available ? std::min(*available, *room) : *room;
  return available;
}

std::string
MemoryShortfall(const RunShape & shape, const MemoryEstimate & estimate, const AvailableMemory & available,
                bool atLeast)
{
  const double host = estimate.Host(shape.population);
  const std::string about = atLeast ? "at least about " : "about ";
  if (available.host && host > *available.host)
    return "not enough memory: the optimisation needs " + about + GiBText(host) + " of host memory for " +
           RunText(shape, atLeast) + ", and " + GiBText(*available.host) +
           " are available; lower ea_population_size" +
           PopulationThatFits(estimate.hostFixed, estimate.hostPerSolution, *available.host, atLeast) +
           ", ea_archive_size or morea_mesh_num_points, or free memory";
  const double device = estimate.Device(shape.population);
  if (estimate.device >= 0 && available.device && device > *available.device)
    return "not enough GPU memory: the optimisation needs " + about + GiBText(device) + " on CUDA device " +
           std::to_string(estimate.device) + " for " + RunText(shape, atLeast) + ", and " +
           GiBText(*available.device) + " are free; lower ea_population_size" +
           PopulationThatFits(estimate.deviceFixed, estimate.devicePerSolution, *available.device, atLeast) +
           " or morea_mesh_num_points, or run on the cpu backend";
  return {};
}

void
CheckRunMemory(const RunShape & shape, const EvaluationBackend & backend)
{
  AvailableMemory available;
  available.host = AvailableHostMemory();
  available.device = backend.FreeDeviceMemory();
  const std::string shortfall = MemoryShortfall(shape, MoRvGomea::MemoryFor(shape) + backend.MemoryFor(shape), available);
  if (!shortfall.empty())
    throw Error(shortfall);
}

void
CheckRunMemory(const ParameterSet & parameters)
{
  const GomeaOptions options = GomeaOptions::FromParameters(parameters);
  const RunShape     shape =
    RunShapeAtLeast(options, static_cast<std::size_t>(parameters.GetInteger("morea_mesh_num_points")));
  AvailableMemory available;
  available.host = AvailableHostMemory();
  const std::string shortfall = MemoryShortfall(shape, MoRvGomea::MemoryFor(shape), available, true);
  if (!shortfall.empty())
    throw Error(shortfall);
}
} // namespace morea_core
