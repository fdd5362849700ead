// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// A batch of MO-RV-GOMEA's candidates: the backend's view of it, its
// evaluation and its acceptance in a fixed order; and forced improvements.
#include "MoRvGomeaParts.h"

#include "morea_core/Error.h"
#include "morea_core/RefusalBound.h"
#include "morea_core/ThreadPool.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

namespace morea_core
{
// Small helpers the acceptance calls once per candidate, defined here so
// that they inline there.
Fitness
MoRvGomea::Steered(const Fitness & raw) const
{
  return SteeredFitness(raw, m_SteeringLimit);
}

Fitness
MoRvGomea::CurrentFitness(std::size_t s) const
{
  return Steered(m_Totals[s].ToFitness(m_Topology.NumberOfTetrahedra()));
}

TetrahedronValues
MoRvGomea::SumOverElement(std::size_t s, std::size_t e) const
{
  // Always in one order, so that a resumed run sums as the uninterrupted
  // one did.
  ObjectiveTotals sum;
  const auto &    stored = m_TetValues[s];
  for (std::uint32_t t : m_Parallel.elements[e].dependentTetrahedra)
    sum.Add(stored[t]);
  return sum.sum;
}

TetrahedronValues
MoRvGomea::ElementSum(std::size_t s, std::size_t e) const
{
  const std::size_t at = s * m_Parallel.elements.size() + e;
  return m_ElementSumStale[at] ? SumOverElement(s, e) : m_ElementSums[at];
}

void
MoRvGomea::BuildPartials(CandidateBatch & candidateBatch, ThreadPool & pool) const
{
  const std::vector<Candidate> & candidates = candidateBatch.candidates;
  std::vector<PartialCandidate> & batch = candidateBatch.partials;
  batch.resize(candidates.size());
  // Sized here, reset on the pool: a serial fill of a paper-scale
  // generation's bounds took about 3 ms of it.
  candidateBatch.folds.resize(candidates.size());
  candidateBatch.sums.resize(candidates.size());
  candidateBatch.bounds.resize(m_Options.boundRefusals ? candidates.size() : 0);
  pool.ParallelFor(candidates.size(), [&](std::size_t i) {
    const Candidate &  c = candidates[i];
    PartialCandidate & p = batch[i];
    candidateBatch.folds[i] = CandidateFolds{};
    if (m_Options.boundRefusals)
      candidateBatch.bounds[i] = RefusalBound{};
    p.parent = &m_Population[c.solution];
    p.parentKey = 0;
    p.element = &m_Parallel.elements[c.element];
    p.source = candidateBatch.Source(c);
    p.target = candidateBatch.Target(c);
    p.values = candidateBatch.Values(c);
    p.sum = &candidateBatch.sums[i];
    p.folds = &candidateBatch.folds[i];
    p.seed = c.seed;
    p.evaluateFolded = true;
    p.bound = m_Options.boundRefusals ? &candidateBatch.bounds[i] : nullptr;
  });
  candidateBatch.partialsBuilt = true;
  candidateBatch.parentStateSet = 0;
}

void
MoRvGomea::SetParentState(CandidateBatch & candidateBatch, std::size_t begin, std::size_t end) const
{
  m_Pool->ParallelFor(end - begin, [&](std::size_t k) {
    const Candidate &  c = candidateBatch.candidates[begin + k];
    PartialCandidate & p = candidateBatch.partials[begin + k];
    // An id names one set of points (a change gets a new id, a donor's
    // points keep the donor's), so the key lets the backend keep parents.
    p.parentKey = std::max<std::uint64_t>(1, HashCombine(m_KeySalt, m_Ids[c.solution]));
    p.evaluateFolded = std::llround(m_Totals[c.solution].sum.folded) != 0;
    if (p.bound)
      p.bound->skipped = false;
    const std::size_t at = c.solution * m_Parallel.elements.size() + c.element;
    if (m_ElementSumStale[at])
    {
      m_ElementSums[at] = SumOverElement(c.solution, c.element);
      m_ElementSumStale[at] = 0;
    }
  });
}

void
MoRvGomea::FillBound(CandidateBatch & candidateBatch, std::size_t i) const
{
  const Candidate &  c = candidateBatch.candidates[i];
  RefusalBound &     bound = candidateBatch.bounds[i];
  // Other acceptance rules than the archive's are not bounded.
  bound.screened = !c.forced && c.singleObjective < 0;
  if (!bound.screened)
    return;
  ObjectiveTotals rest = m_Totals[c.solution];
  rest.Add(ElementSum(c.solution, c.element), -1.0);
  bound.rest = rest.sum;
  bound.parent = CurrentFitness(c.solution);
}

RefusalScreen
MoRvGomea::ScreenFor(CandidateBatch & candidateBatch) const
{
  RefusalScreen screen;
  screen.archive = m_Archive->Objectives();
  screen.witnesses = m_Archive->Witnesses();
  screen.tetrahedra = m_Topology.NumberOfTetrahedra();
  screen.guidanceLimit = m_SteeringLimit;
  screen.fill = [this, &candidateBatch](std::size_t i) { FillBound(candidateBatch, i); };
  return screen;
}

std::size_t
MoRvGomea::ProcessCandidates(CandidateBatch & candidateBatch, GenerationRecord & record,
                             const EvaluationBackend::Meanwhile & meanwhile, CandidateBatch * next)
{
  std::vector<Candidate> & candidates = candidateBatch.candidates;
  // 1. Fold checks (and repair) and evaluation of the whole batch at once,
  //    in the backend (the GPU checks where the points already are). A
  //    candidate still folded cannot replace a fold-free parent: it needs no
  //    values then. Built while the batch before was evaluated, where it was
  //    drawn then; what that batch's acceptance changes is set here.
  if (!candidateBatch.partialsBuilt)
    BuildPartials(candidateBatch, *m_Pool);
  candidateBatch.partialsBuilt = false;
  std::vector<PartialCandidate> &    batch = candidateBatch.partials;
  const std::vector<CandidateFolds> & folds = candidateBatch.folds;
  // In parallel: the device waits for this (a batch holds tens of thousands).
  // Those of solutions the batch before had finished with are set already.
  const auto parentStart = std::chrono::steady_clock::now();
  SetParentState(candidateBatch, candidateBatch.parentStateSet, candidates.size());
  record.phaseSeconds.parentState += SecondsSince(parentStart);
  // Per solution, the end of its last candidate in this batch (0: none): a
  // solution is finished with once the parts handed over reach it.
  std::vector<std::size_t> lastEnd;
  if (next)
  {
    lastEnd.assign(m_Population.size(), 0);
    for (std::size_t i = 0; i < candidates.size(); ++i)
      lastEnd[candidates[i].solution] = i + 1;
  }
  // 2. Acceptance of each part of the batch as the backend hands it over
  //    (in order), while the device may still compute the next part.
  std::size_t       accepted = 0;
  double            acceptanceSeconds = 0.0;
  const auto        accept = [&](std::size_t begin, std::size_t end) {
    const auto phaseStart = std::chrono::steady_clock::now();
    accepted += AcceptCandidates(candidateBatch, batch, folds, begin, end, record);
    // The next batch's candidates of solutions this batch has finished with
    // (a prefix: both batches take the solutions in one order) are final:
    // their parents' state is set part by part (so that little of it is
    // left for the hand-over in which the device waits), and the backend may
    // start on them while the rest is handed over (when it takes them:
    // during one part of the batch).
    if (next && next->partialsBuilt && end < candidates.size())
    {
      std::size_t head = next->parentStateSet;
      while (head < next->candidates.size() && lastEnd[next->candidates[head].solution] <= end)
        ++head;
      SetParentState(*next, next->parentStateSet, head);
      next->parentStateSet = head;
      if (m_Backend.WantsNextPartials())
      {
        const RefusalScreen screen = m_Options.boundRefusals ? ScreenFor(*next) : RefusalScreen{};
        m_Backend.StartNextPartials(next->partials, head, m_Options.boundRefusals ? &screen : nullptr);
      }
    }
    acceptanceSeconds += SecondsSince(phaseStart);
  };
  const BackendStatistics before = m_Backend.Statistics();
  double                  meanwhileSeconds = 0.0;
  const auto              timedMeanwhile = [&] {
    const auto phaseStart = std::chrono::steady_clock::now();
    meanwhile();
    meanwhileSeconds += SecondsSince(phaseStart);
  };
  if (m_Options.boundRefusals)
  {
    m_Backend.SetRefusalScreen(ScreenFor(candidateBatch));
  }
  else
    m_Backend.ClearRefusalScreen();
  const auto evaluationStart = std::chrono::steady_clock::now();
  m_Backend.EvaluatePartials(batch, accept, meanwhile ? EvaluationBackend::Meanwhile(timedMeanwhile) : nullptr);
  const double foldSeconds = m_Backend.Statistics().foldSeconds - before.foldSeconds;
  record.phaseSeconds.foldChecks += foldSeconds;
  record.phaseSeconds.evaluation +=
    SecondsSince(evaluationStart) - foldSeconds - acceptanceSeconds - meanwhileSeconds;
  record.phaseSeconds.acceptance += acceptanceSeconds;
  record.accepted += accepted;
  return accepted;
}

std::size_t
MoRvGomea::AcceptCandidates(CandidateBatch & candidateBatch, const std::vector<PartialCandidate> & batch,
                            const std::vector<CandidateFolds> & folds, std::size_t begin, std::size_t end,
                            GenerationRecord & record)
{
  std::vector<Candidate> & candidates = candidateBatch.candidates;
  std::vector<std::size_t> batchIndex;
  for (std::size_t i = begin; i < end; ++i)
  {
    Candidate & c = candidates[i];
    ++record.candidates;
    record.folded += folds[i].foldedSides;
    record.repaired += folds[i].repairedSides;
    if (folds[i].Folded() && !batch[i].evaluateFolded)
      continue;
    batchIndex.push_back(i);
    record.tetrahedronEvaluations += static_cast<double>(m_Parallel.elements[c.element].dependentTetrahedra.size());
  }

  // 3. Acceptance in a fixed order. Candidates of one solution touch disjoint
  //    tetrahedra, so each one's change of the totals does not depend on the
  //    others. Everything but the archive's changes is worked out in
  //    parallel first, one solution's candidates in order as a chain, as if
  //    the archive stayed as it is: the totals each candidate sees after the
  //    ones before it (those the chain accepts), its fitness and its
  //    parent's, and the archive's verdict on it (ElitistArchive::Judge; runs
  //    of a chain try first the entry that refused the one before). The
  //    ordered pass then only brings the verdicts up to date
  //    (ElitistArchive::Accepts(f, verdict) looks at newer entries only),
  //    passes over those refused for good, and applies the acceptances. Late
  //    in a paper-scale run on 16 cores, timed in two leases of one machine
  //    type, the ordered pass took 0.033 s per generation before and 0.017 s
  //    after. Where the archive's changes overturn a
  //    chain's guess, the rest of that chain is judged afresh in the ordered
  //    pass, as it would be without the chains: decisions and sums are those
  //    of a plain ordered pass.
  const std::size_t count = batchIndex.size();
  auto &            j = candidateBatch.judged;
  j.Reserve(count, m_Population.size());
  // The guesses: rejected for good (infeasible, dominated by or equal to an
  // entry) unless the archive is thinned meanwhile; rejected; accepted.
  enum class Guess : std::uint8_t
  {
    Refused,
    Rejected,
    Accepted
  };
  // The chains: batch positions grouped by solution, in order.
  for (std::size_t b = 0; b < count; ++b)
  {
    j.solution[b] = static_cast<std::uint32_t>(candidates[batchIndex[b]].solution);
    ++j.chainStart[j.solution[b] + 1];
  }
  std::partial_sum(j.chainStart.begin(), j.chainStart.end(), j.chainStart.begin());
  {
    std::vector<std::size_t> fill(j.chainStart.begin(), j.chainStart.end() - 1);
    for (std::size_t b = 0; b < count; ++b)
      j.order[fill[j.solution[b]]++] = b;
  }
  // A candidate whose bound spared its sampling (RefusalBound.h) has the
  // bound for values: its fitness here is the bound's, and one the archive
  // refuses is refused whatever its samples, as its guess says. Where the
  // bound is not refused on the chain's totals so far (an earlier candidate
  // of the chain was accepted), the chain stops there; the backend samples
  // all stopped candidates at once and their chains go on.
  const auto boundOf = [&](std::size_t b) { return batch[batchIndex[b]].bound; };
  const auto skipped = [&](std::size_t b) { return boundOf(b) != nullptr && boundOf(b)->skipped; };
  const auto runChain = [&](std::size_t s) {
    CandidateBatch::Judged::Chain & chain = j.chains[s];
    for (; chain.at < j.chainStart[s + 1]; ++chain.at)
    {
      const std::size_t  b = j.order[chain.at];
      const Candidate &  c = candidates[batchIndex[b]];
      j.changes[b] = CandidateChange(s, c, candidateBatch.sums[batchIndex[b]]);
      ObjectiveTotals totals = chain.held;
      totals.Add(j.changes[b]);
      const Fitness next = Steered(totals.ToFitness(m_Topology.NumberOfTetrahedra()));
      j.next[b] = next;
      j.now[b] = chain.now;
      j.verdicts[b] = ArchiveVerdict{};
      bool accept = false;
      if (c.forced || c.singleObjective >= 0)
        accept = Accepted(c, next, chain.now, nullptr);
      else
      {
        // A skipped candidate's bound was refused by the entry it names.
        const std::uint64_t hint = skipped(b) && boundOf(b)->witness ? boundOf(b)->witness : chain.witness;
        j.verdicts[b] = m_Archive->Judge(next, hint);
        chain.witness = j.verdicts[b].witness;
        accept = ConstraintDominates(next, chain.now) || j.verdicts[b].kind == ArchiveVerdict::Kind::Accepted;
      }
      const Guess guess = accept ? Guess::Accepted
                                 : (j.verdicts[b].kind == ArchiveVerdict::Kind::Rejected ? Guess::Refused
                                                                                         : Guess::Rejected);
      if (guess != Guess::Refused && skipped(b))
        return; // needs its samples
      j.guess[b] = static_cast<std::uint8_t>(guess);
      if (accept)
      {
        chain.held = totals;
        chain.now = next;
      }
    }
  };
  std::vector<std::size_t> stopped;
  for (std::size_t s = 0; s < m_Population.size(); ++s)
    if (j.chainStart[s] < j.chainStart[s + 1])
    {
      j.chains[s] = CandidateBatch::Judged::Chain{ j.chainStart[s], m_Totals[s], CurrentFitness(s), 0 };
      stopped.push_back(s);
    }
  std::vector<std::size_t> later;
  while (!stopped.empty())
  {
    m_Pool->ParallelFor(stopped.size(), [&](std::size_t k) { runChain(stopped[k]); });
    later.clear();
    std::vector<std::size_t> still;
    for (std::size_t s : stopped)
      if (j.chains[s].at < j.chainStart[s + 1])
      {
        later.push_back(batchIndex[j.order[j.chains[s].at]]);
        still.push_back(s);
      }
    if (!later.empty())
      m_Backend.SampleSkipped(batch, later);
    stopped.swap(still);
  }
  // Chains whose guess the ordered pass overturned; their later candidates
  // are judged on the totals the solution then has.
  std::vector<bool>         overturned(m_Population.size(), false);
  std::vector<std::uint8_t> acceptedOf(m_Population.size(), 0);
  std::vector<std::uint32_t> changed; // the solutions with an accepted candidate
  std::vector<std::size_t>   acceptedCandidates;
  const std::uint64_t revision = m_Archive->ThinningRevision();
  std::size_t         accepted = 0;
  for (std::size_t b = 0; b < count; ++b)
  {
    // Most candidates are refused for good: skipped without a look at them
    // while their chain holds and the archive is not thinned.
    const std::size_t s = j.solution[b];
    const auto guess = static_cast<Guess>(j.guess[b]);
    if (guess == Guess::Refused && !overturned[s] && m_Archive->ThinningRevision() == revision)
      continue;
    Candidate &        c = candidates[batchIndex[b]];
    const FosElement & element = m_Parallel.elements[c.element];
    ObjectiveTotals    totals = m_Totals[s];
    totals.Add(j.changes[b]);
    bool sampledNow = false;
    if (skipped(b))
    {
      // Its bound, judged afresh on the totals and archive of now.
      const Fitness low = Steered(totals.ToFitness(m_Topology.NumberOfTetrahedra()));
      if (!ConstraintDominates(low, CurrentFitness(s)) &&
          m_Archive->Judge(low, j.verdicts[b].witness).kind == ArchiveVerdict::Kind::Rejected)
        continue;
      m_Backend.SampleSkipped(batch, { batchIndex[b] });
      j.changes[b] = CandidateChange(s, c, candidateBatch.sums[batchIndex[b]]);
      totals = m_Totals[s];
      totals.Add(j.changes[b]);
      sampledNow = true;
    }
    ArchiveVerdict & verdict = j.verdicts[b];
    const Fitness *  now = &j.now[b];
    const Fitness *  next = &j.next[b];
    Fitness          current, fresh;
    if (overturned[s] || sampledNow)
    {
      current = CurrentFitness(s);
      fresh = Steered(totals.ToFitness(m_Topology.NumberOfTetrahedra()));
      now = &current;
      next = &fresh;
      verdict.kind = ArchiveVerdict::Kind::Unknown; // on other totals: its witness is only a hint now
    }
    const bool accept = Accepted(c, *next, *now, &verdict);
    if (accept != (guess == Guess::Accepted))
      overturned[s] = true;
    if (!accept)
      continue;
    DualMesh &                solution = m_Population[s];
    const Vec3 *              source = candidateBatch.Source(c);
    const Vec3 *              target = candidateBatch.Target(c);
    for (std::size_t k = 0; k < element.points.size(); ++k)
    {
      solution.source[element.points[k]] = source[k];
      solution.target[element.points[k]] = target[k];
    }
    m_Totals[s] = totals;
    m_Ids[s] = m_NextId++;
    m_Archive->Insert(*next, solution, m_Ids[s], verdict);
    c.accepted = true;
    ++accepted;
    acceptedCandidates.push_back(batchIndex[b]);
    if (!acceptedOf[s])
      changed.push_back(static_cast<std::uint32_t>(s));
    acceptedOf[s] = 1;
  }
  // The accepted candidates' tetrahedra's values, and the element sums they
  // make stale, after the ordered pass and in parallel (scattered writes,
  // most of them cache misses): nothing in this pass reads what another
  // candidate of the solution changes, as they touch disjoint tetrahedra
  // (and so disjoint elements' sums). One solution per task, so no two
  // tasks mark one flag.
  const std::size_t elements = m_Parallel.elements.size();
  m_Backend.FetchValues(batch, acceptedCandidates);
  m_Pool->ParallelFor(changed.size(), [&](std::size_t k) {
    const std::size_t s = changed[k];
    for (std::size_t at = j.chainStart[s]; at < j.chainStart[s + 1]; ++at)
    {
      const Candidate & c = candidates[batchIndex[j.order[at]]];
      if (!c.accepted)
        continue;
      const FosElement &        element = m_Parallel.elements[c.element];
      const TetrahedronValues * values = candidateBatch.Values(c);
      for (std::size_t i = 0; i < element.dependentTetrahedra.size(); ++i)
      {
        const std::uint32_t t = element.dependentTetrahedra[i];
        m_TetValues[s][t] = values[i];
        for (std::uint32_t e = m_TetElementStart[t]; e < m_TetElementStart[t + 1]; ++e)
          m_ElementSumStale[s * elements + m_TetElements[e]] = 1;
      }
    }
  });
  return accepted;
}

TetrahedronValues
MoRvGomea::CandidateChange(std::size_t s, const Candidate & c, const TetrahedronValues & sum) const
{
  // The sum of the candidate's values, added in order from 0: the bits a
  // sum over its values here would give.
  ObjectiveTotals change{ sum };
  change.Add(ElementSum(s, c.element), -1.0);
  return change.sum;
}

bool
MoRvGomea::Accepted(const Candidate & c, const Fitness & next, const Fitness & now, ArchiveVerdict * verdict) const
{
  if (c.forced)
    return ConstraintDominates(next, now);
  if (c.singleObjective >= 0)
  {
    const auto m = static_cast<std::size_t>(c.singleObjective);
    if (next.feasible != now.feasible)
      return next.feasible;
    if (!next.feasible)
      return next.constraint < now.constraint;
    return next.objectives[m] < now.objectives[m];
  }
  return ConstraintDominates(next, now) || (verdict != nullptr && m_Archive->Accepts(next, *verdict));
}

void
MoRvGomea::ForcedImprovement(std::size_t s, int singleObjective, RandomGenerator & random, GenerationRecord & record)
{
  const auto & entries = m_Archive->Entries();
  if (entries.empty())
    return;
  std::size_t donor = static_cast<std::size_t>(random.Uniform() * static_cast<double>(entries.size()));
  if (singleObjective >= 0)
    for (std::size_t j = 0; j < entries.size(); ++j)
      if (entries[j].fitness.objectives[singleObjective] < entries[donor].fitness.objectives[singleObjective])
        donor = j;
  const DualMesh donorMesh = entries[donor].solution; // a copy: accepting may change the archive
  ++record.forcedImprovements;
  std::size_t accepted = 0;
  CandidateBatch & batch = *m_Batches[0]; // no batch is drawn ahead now
  for (const auto & group : m_Parallel.groups)
  {
    batch.candidates.clear();
    for (std::uint32_t e : group)
    {
      Candidate c;
      c.solution = s;
      c.element = e;
      c.forced = true;
      c.seed = random.NextU64();
      batch.candidates.push_back(c);
    }
    batch.Layout(m_Parallel);
    for (const Candidate & c : batch.candidates)
    {
      const auto & points = m_Parallel.elements[c.element].points;
      for (std::size_t k = 0; k < points.size(); ++k)
      {
        batch.Source(c)[k] = donorMesh.source[points[k]];
        batch.Target(c)[k] = donorMesh.target[points[k]];
      }
    }
    accepted += ProcessCandidates(batch, record);
  }
  if (accepted == 0)
  {
    // Nothing helped piecewise: take the donor over whole.
    m_Population[s] = donorMesh;
    m_Ids[s] = entries[donor].id;
    m_Backend.EvaluateSolutions({ &m_Population[s] }, { &m_TetValues[s] });
    m_Totals[s] = ObjectiveTotals{};
    for (const auto & v : m_TetValues[s])
      m_Totals[s].Add(v);
    InvalidateElementSums(s);
    record.tetrahedronEvaluations += static_cast<double>(m_Topology.NumberOfTetrahedra());
  }
}
} // namespace morea_core
