// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the memory a run needs, estimated before
// the optimisation, against what is free. A population or archive too large
// for the machine is refused with the figures, rather than ending in
// std::bad_alloc (or the system's out-of-memory killer) after minutes.
//
// The optimiser states its host memory (MoRvGomea::MemoryFor), a backend its
// own and its device's free memory (EvaluationBackend::MemoryFor and
// FreeDeviceMemory: the CUDA backend's device and pinned buffers); each as a
// fixed part and a part per solution of the population, so that a refusal
// can say how large a population fits. The mesh model, objective data and a
// backend's images exist when the whole estimate is checked: what is free
// then is what is left for the rest.
#ifndef morea_MemoryEstimate_h
#define morea_MemoryEstimate_h

#include <cstddef>
#include <optional>
#include <string>

namespace morea_core
{
class EvaluationBackend;
struct GomeaOptions;
class MeshTopology;
class ParameterSet;
struct ParallelStructure;

/** What a run's memory grows with: the optimiser's options and the mesh's sizes. */
struct RunShape
{
  std::size_t population{ 0 };      ///< ea_population_size
  std::size_t archiveCapacity{ 0 }; ///< ea_archive_size
  std::size_t clusters{ 0 };        ///< ea_num_clusters (the optimiser adds one per objective)
  std::size_t points{ 0 };          ///< mesh points
  std::size_t tetrahedra{ 0 };
  std::size_t elements{ 0 };        ///< FOS elements
  /** Doubles of one cluster's distributions over all elements (a mean and a
   *  Cholesky factor each: v + v^2 for v = 6 x the element's points). */
  std::size_t modelDoubles{ 0 };
  /** The largest parallel group: its elements, their points and their
   *  dependent tetrahedra. A batch holds these for every solution. */
  std::size_t groupElements{ 0 };
  std::size_t groupPoints{ 0 };
  std::size_t groupTetrahedra{ 0 };
  bool        checkpoints{ false }; ///< checkpoint files are written (two buffers of the whole state)
};

/** The shape of a run of `options` on a mesh model. */
RunShape
RunShapeOf(const GomeaOptions & options, const MeshTopology & topology, const ParallelStructure & parallel);

/** Before the mesh exists: the least any mesh of `points` points gives (a
 *  tetrahedralisation of n points has at least n - 3 tetrahedra, an edge
 *  cover of them at least n / 2 edges), so that an estimate from it never
 *  exceeds the run's. */
RunShape
RunShapeAtLeast(const GomeaOptions & options, std::size_t points);

/** Bytes, as a fixed part and a part per solution of the population. */
struct MemoryEstimate
{
  double hostFixed{ 0.0 };
  double hostPerSolution{ 0.0 };
  double deviceFixed{ 0.0 };
  double devicePerSolution{ 0.0 };
  int    device{ -1 }; ///< the CUDA device the device bytes are on; -1: none

  double
  Host(std::size_t population) const
  {
    return hostFixed + hostPerSolution * static_cast<double>(population);
  }
  double
  Device(std::size_t population) const
  {
    return deviceFixed + devicePerSolution * static_cast<double>(population);
  }
};

/** Both parts added; the device of whichever has one. */
MemoryEstimate
operator+(const MemoryEstimate & a, const MemoryEstimate & b);

/** What is free now, in bytes; empty where it cannot be read. */
struct AvailableMemory
{
  std::optional<double> host;
  std::optional<double> device;
};

/** MemAvailable of /proc/meminfo (memory a process can take without
 *  swapping); empty where there is none. */
std::optional<double>
AvailableHostMemory();

/** "" when `estimate` fits in `available`; otherwise why not, with the
 *  figures and what to lower (naming ea_population_size and how large a
 *  population would fit). `atLeast`: the shape is a lower bound (before the
 *  mesh exists), and the message says so. */
std::string
MemoryShortfall(const RunShape & shape, const MemoryEstimate & estimate, const AvailableMemory & available,
                bool atLeast = false);

/** Before the optimiser is made: throws morea_core::Error with MemoryShortfall's
 *  message when what the optimiser and `backend` will allocate for `shape`
 *  does not fit in the host's available memory or the backend's device's
 *  free memory. */
void
CheckRunMemory(const RunShape & shape, const EvaluationBackend & backend);

/** The cheap check before any work (preprocessing, meshing): the
 *  optimiser's host memory for the population and archive of `parameters`
 *  on a mesh of at least morea_mesh_num_points points. Refuses absurd sizes
 *  (ea_population_size = 1e7) at once. */
void
CheckRunMemory(const ParameterSet & parameters);
} // namespace morea_core

#endif
