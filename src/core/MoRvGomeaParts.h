// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The optimiser's internal types, shared by its source files
// (MoRvGomea.cxx: the generation; MoRvGomeaModels.cxx: selection,
// clustering and the distributions; MoRvGomeaAcceptance.cxx: a batch's
// evaluation and acceptance). Not installed.
#ifndef morea_MoRvGomeaParts_h
#define morea_MoRvGomeaParts_h

#include "morea_core/MoRvGomea.h"

#include <chrono>
#include <cstdint>
#include <vector>

namespace morea_core
{
// Generations without improvement tolerated: 25 + the number of variables
// (per distribution; per solution that of an edge element, 12).
constexpr std::size_t NoImprovementStretchBase = 25;

inline double
SecondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/** A cluster of the selection and its per-element distributions. */
struct MoRvGomea::ClusterModel
{
  std::vector<std::size_t>         members; ///< population indices used for estimation
  ObjectiveVector                  mean{};  ///< in normalised objective space
  int                              singleObjective{ -1 };
  std::vector<std::vector<double>> means;    ///< per element
  std::vector<std::vector<double>> cholesky; ///< per element, lower, row-major
  std::vector<std::size_t>         population; ///< solutions varied with this cluster's model
};

/** One partial change of one solution: an element's new coordinates. Its
 *  coordinates, drawn variables and values live in its CandidateBatch. */
struct MoRvGomea::Candidate
{
  std::size_t   solution{ 0 };
  std::size_t   element{ 0 };
  int           singleObjective{ -1 }; ///< acceptance rule: -1 Pareto, else that objective
  bool          forced{ false };       ///< forced improvement: must dominate the parent
  std::uint64_t seed{ 0 };             ///< of its sampling and repair streams
  bool          anticipate{ false };   ///< add the anticipated mean shift
  std::size_t   cluster{ 0 };
  bool          accepted{ false };
  std::size_t   firstPoint{ 0 }; ///< in the batch's source/target (6 variables per point in samples)
  std::size_t   firstValue{ 0 }; ///< in the batch's values
};

/** Candidates and the storage of their coordinates, drawn variables and
 *  values, kept from batch to batch: a generation's hundreds of thousands
 *  of candidates then cost no allocation each. */
struct MoRvGomea::CandidateBatch
{
  std::vector<Candidate>         candidates;
  std::vector<Vec3>              source, target;
  std::vector<double>            samples; ///< drawn variables (before projection), for the ratio test
  std::vector<TetrahedronValues> values;
  /** Per candidate, the sum of its values (PartialCandidate::sum). */
  std::vector<TetrahedronValues> sums;
  /** The backend's view of the candidates and their fold outcomes
   *  (BuildPartials); `partialsBuilt` until ProcessCandidates uses them. */
  std::vector<PartialCandidate> partials;
  std::vector<CandidateFolds>   folds;
  std::vector<RefusalBound>     bounds; ///< per candidate, when GomeaOptions::boundRefusals
  bool                          partialsBuilt{ false };
  /** Candidates [0, parentStateSet) have their parent's state
   *  (SetParentState) while the batch before is handed over. */
  std::size_t parentStateSet{ 0 };
  /** AcceptCandidates' per-candidate working storage (see there). */
  struct Judged
  {
    std::vector<TetrahedronValues> changes;
    std::vector<ArchiveVerdict>    verdicts;
    std::vector<Fitness>           next, now;
    std::vector<std::uint32_t>     solution;
    std::vector<std::uint8_t>      guess; ///< the parallel pass's guess (refused for good, rejected, accepted)
    std::vector<std::size_t>       order, chainStart;
    /** Per solution, the chain's state in the parallel pass. */
    struct Chain
    {
      std::size_t     at{ 0 }; ///< the next candidate, in `order`
      ObjectiveTotals held;    ///< the totals after the candidates accepted so far
      Fitness         now;     ///< their fitness
      std::uint64_t   witness{ 0 };
    };
    std::vector<Chain> chains;

    void
    Reserve(std::size_t count, std::size_t population)
    {
      if (changes.size() < count)
      {
        changes.resize(count);
        verdicts.resize(count);
        next.resize(count);
        now.resize(count);
        solution.resize(count);
        guess.resize(count);
        order.resize(count);
      }
      chainStart.assign(population + 1, 0);
      chains.resize(population);
    }
  } judged;

  /** Places each candidate's data; storage only grows. */
  void
  Layout(const ParallelStructure & parallel)
  {
    std::size_t pointCount = 0, valueCount = 0;
    for (Candidate & c : candidates)
    {
      const FosElement & element = parallel.elements[c.element];
      c.firstPoint = pointCount;
      c.firstValue = valueCount;
      pointCount += element.points.size();
      valueCount += element.dependentTetrahedra.size();
    }
    if (source.size() < pointCount)
    {
      source.resize(pointCount);
      target.resize(pointCount);
      samples.resize(6 * pointCount);
    }
    if (values.size() < valueCount)
      values.resize(valueCount);
  }
  Vec3 *
  Source(const Candidate & c)
  {
    return source.data() + c.firstPoint;
  }
  Vec3 *
  Target(const Candidate & c)
  {
    return target.data() + c.firstPoint;
  }
  double *
  Sample(const Candidate & c)
  {
    return samples.data() + 6 * c.firstPoint;
  }
  TetrahedronValues *
  Values(const Candidate & c)
  {
    return values.data() + c.firstValue;
  }
};
} // namespace morea_core

#endif
