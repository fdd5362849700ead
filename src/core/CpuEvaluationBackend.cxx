// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The CPU evaluation backend: the reference implementation of
// EvaluationBackend, multi-threaded over the tetrahedra of whole solutions and
// over the candidates of a parallel group.
#include "morea_core/EvaluationBackend.h"

#include "morea_core/Error.h"
#include "morea_core/Random.h"
#include "morea_core/ThreadPool.h"

#include <algorithm>
#include <array>
#include <chrono>

namespace morea_core
{
Corners
CornersWithReplacedPoints(const Tetrahedron & t, const std::vector<Vec3> & points,
                          const std::vector<std::uint32_t> & moved, const Vec3 * replacements)
{
  Corners corners;
  for (int i = 0; i < 4; ++i)
  {
    const auto it = std::find(moved.begin(), moved.end(), t[i]);
    corners[i] = it == moved.end() ? points[t[i]] : replacements[static_cast<std::size_t>(it - moved.begin())];
  }
  return corners;
}

void
CandidateCorners(const PartialCandidate & c, const Tetrahedron & t, Corners & source, Corners & target)
{
  source = CornersWithReplacedPoints(t, c.parent->source, c.element->points, c.source);
  target = CornersWithReplacedPoints(t, c.parent->target, c.element->points, c.target);
}

std::uint64_t
RepairSeed(std::uint64_t candidateSeed, int side)
{
  return HashCombine(candidateSeed, static_cast<std::uint64_t>(side));
}

CandidateFolds
CheckCandidateFolds(const PartialCandidate & c, const FoldHandling & handling)
{
  CandidateFolds result;
  if (!handling.constraint)
    return result;
  const FoldConstraint & constraint = *handling.constraint;
  const auto &           tets = constraint.Topology().Tetrahedra();
  const FosElement &     element = *c.element;
  std::vector<Vec3>      scratch;
  for (int side = 0; side < 2; ++side)
  {
    const std::vector<Vec3> & from = side == 0 ? c.parent->source : c.parent->target;
    Vec3 *                    moved = side == 0 ? c.source : c.target;
    bool                      folded = false;
    for (std::uint32_t t : element.dependentTetrahedra)
    {
      const Corners corners = CornersWithReplacedPoints(tets[t], from, element.points, moved);
      constraint.TetrahedronViolation(t, corners[0], corners[1], corners[2], corners[3], folded);
      if (folded)
        break;
    }
    if (!folded)
      continue;
    ++result.foldedSides;
    if (!handling.repair)
      continue;
    if (!handling.base)
      throw Error("evaluation backend: the fold repair needs the base mesh");
    scratch = from;
    for (std::size_t k = 0; k < element.points.size(); ++k)
      scratch[element.points[k]] = moved[k];
    const RepairResult r = RepairPoints(scratch, &element.points, &element.dependentTetrahedra, *handling.base,
                                        constraint, RepairSeed(c.seed, side),
                                        handling.options);
    for (std::size_t k = 0; k < element.points.size(); ++k)
      moved[k] = scratch[element.points[k]];
    if (r.after.Feasible())
      ++result.repairedSides;
  }
  return result;
}

namespace
{
class CpuEvaluationBackend final : public EvaluationBackend
{
public:
  CpuEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads)
    : m_Evaluator(evaluator)
    , m_Pool(ThreadPool::Shared(threads))
  {}

  std::string
  Name() const override
  {
    return "cpu";
  }

  void
  EvaluateSolutions(const std::vector<const DualMesh *> & solutions,
                    const std::vector<std::vector<TetrahedronValues> *> & values) override
  {
    if (solutions.size() != values.size())
      throw Error("evaluation backend: as many value arrays as solutions are needed");
    const std::size_t tets = m_Evaluator.Topology().NumberOfTetrahedra();
    const std::size_t points = m_Evaluator.Topology().NumberOfPoints();
    for (std::size_t i = 0; i < solutions.size(); ++i)
    {
      if (solutions[i]->source.size() != points || solutions[i]->target.size() != points)
        throw Error("evaluation backend: a solution does not match the mesh");
      values[i]->assign(tets, TetrahedronValues{});
    }
    // Chunks of tetrahedra across all solutions keep every thread busy even
    // for a single solution.
    const auto            start = std::chrono::steady_clock::now();
    constexpr std::size_t chunk = 64;
    const std::size_t     chunksPerSolution = (tets + chunk - 1) / chunk;
    m_Pool->ParallelFor(solutions.size() * chunksPerSolution, [&](std::size_t job) {
      const std::size_t s = job / chunksPerSolution;
      const std::size_t begin = (job % chunksPerSolution) * chunk;
      const std::size_t end = std::min(tets, begin + chunk);
      for (std::size_t t = begin; t < end; ++t)
        (*values[s])[t] = m_Evaluator.Evaluate(t, *solutions[s]);
    });
    ++m_Statistics.batches;
    for (const auto * v : values)
      Count(*v);
    m_Statistics.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  using EvaluationBackend::EvaluatePartials;
  void
  EvaluatePartials(const std::vector<PartialCandidate> & candidates, const ReadyCandidates & ready,
                   const Meanwhile & meanwhile) override
  {
    if (meanwhile)
      meanwhile(); // nothing runs beside the caller here
    const auto   start = std::chrono::steady_clock::now();
    const auto & tets = m_Evaluator.Topology().Tetrahedra();
    std::vector<std::uint8_t> skip(candidates.size(), 0);
    if (m_FoldHandling.constraint)
    {
      m_Pool->ParallelFor(candidates.size(), [&](std::size_t i) {
        const PartialCandidate & c = candidates[i];
        if (!c.folds)
          return;
        *c.folds = CheckCandidateFolds(c, m_FoldHandling);
        skip[i] = c.folds->Folded() && !c.evaluateFolded;
      });
      m_Statistics.foldSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    // The corners' values first; a candidate whose bound is refused then
    // goes without samples.
    const RefusalScreen * screen = m_HasRefusalScreen ? &m_RefusalScreen : nullptr;
    m_Pool->ParallelFor(candidates.size(), [&](std::size_t i) {
      const PartialCandidate & c = candidates[i];
      if (c.bound)
        c.bound->skipped = false;
      if (skip[i])
        return;
      // Each tetrahedron's corners once, for its corner values and its samples.
      thread_local std::vector<std::array<Corners, 2>> corners;
      const auto &                                     dependent = c.element->dependentTetrahedra;
      corners.resize(dependent.size());
      ObjectiveTotals sums;
      for (std::size_t k = 0; k < dependent.size(); ++k)
      {
        CandidateCorners(c, tets[dependent[k]], corners[k][0], corners[k][1]);
        c.values[k] = m_Evaluator.EvaluateCorners(dependent[k], corners[k][0], corners[k][1]);
        sums.Add(c.values[k]);
      }
      if (screen && c.bound && screen->fill)
        screen->fill(i);
      std::size_t entry = 0;
      if (screen && c.bound && RefusedWhateverItsSamples(*c.bound, sums.sum, *screen, &entry))
      {
        c.bound->skipped = true;
        c.bound->witness = entry < screen->witnesses.size() ? screen->witnesses[entry] : 0;
        SumCandidateValues(c);
        return;
      }
      for (std::size_t k = 0; k < dependent.size(); ++k)
        m_Evaluator.AddSampleSums(corners[k][0], corners[k][1], c.values[k]);
      SumCandidateValues(c);
    });
    ++m_Statistics.batches;
    for (std::size_t i = 0; i < candidates.size(); ++i)
    {
      const PartialCandidate & c = candidates[i];
      if (skip[i])
        continue;
      m_Statistics.tetrahedra += c.element->dependentTetrahedra.size();
      double samples = 0.0;
      for (std::size_t k = 0; k < c.element->dependentTetrahedra.size(); ++k)
        samples += c.values[k].samples;
      if (c.bound && c.bound->skipped)
      {
        ++m_Statistics.boundSkipped;
        m_Statistics.boundSkippedSamples += samples;
      }
      else
        m_Statistics.samples += samples;
    }
    m_Statistics.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (ready)
      ready(0, candidates.size());
  }

  void
  SampleSkipped(const std::vector<PartialCandidate> & candidates, const std::vector<std::size_t> & which) override
  {
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i : which)
      if (i >= candidates.size() || !candidates[i].bound || !candidates[i].bound->skipped)
        throw Error("evaluation backend: only candidates the bound skipped can be sampled later");
    m_Pool->ParallelFor(which.size(), [&](std::size_t w) {
      AddSampleSums(candidates[which[w]]);
      SumCandidateValues(candidates[which[w]]);
    });
    for (std::size_t i : which)
    {
      const PartialCandidate & c = candidates[i];
      c.bound->skipped = false;
      ++m_Statistics.boundSampledLater;
      double samples = 0.0;
      for (std::size_t k = 0; k < c.element->dependentTetrahedra.size(); ++k)
        samples += c.values[k].samples;
      m_Statistics.samples += samples;
      m_Statistics.boundSampledLaterSamples += samples;
      m_Statistics.boundSkippedSamples -= samples;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    m_Statistics.seconds += seconds;
    m_Statistics.boundSampleLaterSeconds += seconds;
    ++m_Statistics.boundSampleLaterCalls;
  }

private:
  /** Completes a candidate's values from EvaluateCorners with its samples. */
  void
  AddSampleSums(const PartialCandidate & c) const
  {
    const auto & tets = m_Evaluator.Topology().Tetrahedra();
    const auto & dependent = c.element->dependentTetrahedra;
    Corners      source, target;
    for (std::size_t k = 0; k < dependent.size(); ++k)
    {
      CandidateCorners(c, tets[dependent[k]], source, target);
      m_Evaluator.AddSampleSums(source, target, c.values[k]);
    }
  }

  void
  Count(const std::vector<TetrahedronValues> & values)
  {
    m_Statistics.tetrahedra += values.size();
    for (const auto & v : values)
      m_Statistics.samples += v.samples;
  }

  const TetrahedronEvaluator & m_Evaluator;
  std::shared_ptr<ThreadPool> m_Pool;
};
} // namespace

std::unique_ptr<EvaluationBackend>
CreateCpuEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads)
{
  return std::make_unique<CpuEvaluationBackend>(evaluator, threads);
}
} // namespace morea_core
