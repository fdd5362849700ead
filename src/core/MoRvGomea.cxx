// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MO-RV-GOMEA (MoRvGomea.h): set-up, the population's evaluation and the
// generation: models, batches drawn and evaluated in turn, bookkeeping.
// Its models and acceptance are in MoRvGomeaModels.cxx and
// MoRvGomeaAcceptance.cxx.
#include "MoRvGomeaParts.h"

#include "morea_core/Error.h"
#include "morea_core/MeshRepair.h"
#include "morea_core/ParameterSet.h"
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
GomeaOptions
GomeaOptions::FromParameters(const ParameterSet & p)
{
  GomeaOptions o;
  o.populationSize = static_cast<std::size_t>(p.GetInteger("ea_population_size"));
  o.numberOfClusters = static_cast<std::size_t>(p.GetInteger("ea_num_clusters"));
  o.archiveCapacity = static_cast<std::size_t>(p.GetInteger("ea_archive_size"));
  o.generations = static_cast<std::size_t>(p.GetInteger("ea_num_generations"));
  o.steeringEnabled = p.GetBool("ea_adaptive_steering_enabled");
  o.steeringStart = static_cast<std::size_t>(p.GetInteger("ea_adaptive_steering_activated_at_num_generations"));
  o.steeringThreshold = p.GetReal("ea_adaptive_steering_guidance_threshold");
  o.repair = p.GetString("morea_repair_method") == "gaussian";
  o.seed = static_cast<std::uint64_t>(p.GetInteger("seed"));
  o.Check();
  return o;
}

void
GomeaOptions::Check() const
{
  if (populationSize < 2)
    throw Error("optimiser: the population needs at least 2 solutions");
  if (numberOfClusters < 1 || archiveCapacity < 1)
    throw Error("optimiser: at least one cluster and an archive of at least 1 are needed");
  if (numberOfClusters > populationSize)
    // Clustering would have to make do with one cluster per solution (fewer
    // than asked for, without a word): say so instead.
    throw Error("optimiser: ea_num_clusters = " + std::to_string(numberOfClusters) +
                " is more than the population (ea_population_size = " + std::to_string(populationSize) +
                "); every cluster needs solutions of its own: use at most " + std::to_string(populationSize) +
                " clusters, or a larger population (the paper: 10 clusters of 700 solutions)");
  if (!(selectionFraction > 0.0 && selectionFraction <= 1.0))
    throw Error("optimiser: the selection fraction must be in (0, 1]");
  if (firstGeneration >= generations)
    throw Error("optimiser: a run from generation " + std::to_string(firstGeneration) + " to " +
                std::to_string(generations) + " has no generation to run");
}

MoRvGomea::MoRvGomea(const TetrahedralMesh & base, const MeshTopology & topology, const ParallelStructure & parallel,
                     const FoldConstraint & constraint, EvaluationBackend & backend, const GomeaOptions & options)
  : m_Base(base)
  , m_Topology(topology)
  , m_Parallel(parallel)
  , m_Constraint(constraint)
  , m_Backend(backend)
  , m_Options(options)
  , m_SteeringLimit(std::numeric_limits<double>::infinity())
{
  options.Check();
  if (parallel.elements.empty())
    throw Error("optimiser: the mesh has no FOS elements");
  m_Archive = std::make_unique<ElitistArchive>(options.archiveCapacity);
  m_Pool = ThreadPool::Shared(options.threads);
  m_TetElementStart.assign(topology.NumberOfTetrahedra() + 1, 0);
  for (const FosElement & element : parallel.elements)
    for (std::uint32_t t : element.dependentTetrahedra)
    {
      if (t >= topology.NumberOfTetrahedra())
        throw Error("optimiser: an element's dependent tetrahedron is not in the mesh");
      ++m_TetElementStart[t + 1];
    }
  std::partial_sum(m_TetElementStart.begin(), m_TetElementStart.end(), m_TetElementStart.begin());
  m_TetElements.resize(m_TetElementStart.back());
  {
    std::vector<std::uint32_t> fill(m_TetElementStart.begin(), m_TetElementStart.end() - 1);
    for (std::size_t e = 0; e < parallel.elements.size(); ++e)
      for (std::uint32_t t : parallel.elements[e].dependentTetrahedra)
        m_TetElements[fill[t]++] = static_cast<std::uint32_t>(e);
  }
  for (auto & batch : m_Batches)
    batch = std::make_unique<CandidateBatch>();
  std::size_t drawAhead = options.drawAheadThreads;
  if (drawAhead == GomeaOptions::DrawAheadAutomatic)
    drawAhead = backend.EvaluatesBesideHost() && m_Pool->NumberOfThreads() >= 8 ? m_Pool->NumberOfThreads() - 2 : 0;
  if (drawAhead > 0)
  {
    // At idle priority: they take the cores the pool leaves while this
    // thread works alone, and never delay the pool's calls, which wait for
    // their slowest worker. Late in a paper-scale run on an H100 host (16
    // cores), 30 generations from one checkpoint, three rounds: 0.0968-0.1009
    // s per generation with 14 such threads, 0.1003-0.1022 with 8, and
    // 0.1080-0.1116 s drawing on the pool in the meanwhile. At normal
    // priority, 4 of them cost the pool's calls more than they saved.
    m_DrawPool = std::make_unique<ThreadPool>(drawAhead, WorkerPriority::Idle);
    m_Drawer = std::make_unique<BackgroundWorker>(WorkerPriority::Idle);
  }
  FoldHandling folds;
  folds.constraint = &m_Constraint;
  folds.base = &m_Base;
  folds.repair = options.repair;
  m_Backend.SetFoldHandling(folds);
}

MoRvGomea::~MoRvGomea() = default;

std::size_t
MoRvGomea::DrawAheadThreads() const
{
  return m_DrawPool ? m_DrawPool->NumberOfThreads() : 0;
}

std::vector<Fitness>
MoRvGomea::PopulationFitness() const
{
  std::vector<Fitness> f(m_Population.size());
  for (std::size_t s = 0; s < f.size(); ++s)
    f[s] = CurrentFitness(s);
  return f;
}

void
MoRvGomea::EvaluatePopulationFully()
{
  std::vector<const DualMesh *>                 solutions;
  std::vector<std::vector<TetrahedronValues> *> values;
  for (std::size_t s = 0; s < m_Population.size(); ++s)
  {
    solutions.push_back(&m_Population[s]);
    values.push_back(&m_TetValues[s]);
  }
  m_Backend.EvaluateSolutions(solutions, values);
  for (std::size_t s = 0; s < m_Population.size(); ++s)
  {
    m_Totals[s] = ObjectiveTotals{};
    for (const auto & v : m_TetValues[s])
      m_Totals[s].Add(v);
    InvalidateElementSums(s);
  }
}

void
MoRvGomea::InvalidateElementSums(std::size_t s)
{
  const std::size_t elements = m_Parallel.elements.size();
  if (m_ElementSums.size() != m_Population.size() * elements)
  {
    m_ElementSums.assign(m_Population.size() * elements, TetrahedronValues{});
    m_ElementSumStale.assign(m_Population.size() * elements, 1);
  }
  std::fill_n(m_ElementSumStale.begin() + static_cast<std::ptrdiff_t>(s * elements), elements, std::uint8_t{ 1 });
}

Fitness
MoRvGomea::EvaluateFully(const DualMesh & solution)
{
  std::vector<TetrahedronValues> values;
  m_Backend.EvaluateSolutions({ &solution }, { &values });
  ObjectiveTotals totals;
  for (const auto & v : values)
    totals.Add(v);
  return totals.ToFitness(m_Topology.NumberOfTetrahedra());
}

bool
MoRvGomea::InsertIntoArchive(std::size_t s, const Fitness & fitness)
{
  return m_Archive->Insert(fitness, m_Population[s], m_Ids[s]); // it asks Accepts() itself
}

void
MoRvGomea::RenewKeySalt()
{
  // Distinct in this process: ids of two populations never share a key.
  static std::atomic<std::uint64_t> populations{ 0 };
  m_KeySalt = HashCombine(0x70617265ULL, ++populations);
}

void
MoRvGomea::Initialize(std::vector<DualMesh> population, const std::vector<DualMesh> & archived)
{
  if (population.size() != m_Options.populationSize)
    throw Error("optimiser: expected " + std::to_string(m_Options.populationSize) + " initial solutions, got " +
                std::to_string(population.size()));
  RandomGenerator random(HashCombine(m_Options.seed, 0x1417));
  for (auto & solution : population)
  {
    if (solution.source.size() != m_Topology.NumberOfPoints() || solution.target.size() != m_Topology.NumberOfPoints())
      throw Error("optimiser: an initial solution does not match the mesh");
    if (m_Options.repair && !m_Constraint.Evaluate(solution).Feasible())
      RepairFolds(solution, m_Base, m_Constraint, random);
  }
  m_Population = std::move(population);
  m_Ids.resize(m_Population.size());
  std::iota(m_Ids.begin(), m_Ids.end(), std::uint64_t{ 0 });
  m_NextId = m_Population.size();
  RenewKeySalt();
  m_Totals.assign(m_Population.size(), ObjectiveTotals{});
  m_TetValues.assign(m_Population.size(), {});
  m_NoImprovement.assign(m_Population.size(), 0);
  m_Generation = m_Options.firstGeneration;
  m_History.clear();
  m_ClusterMeans.clear();
  m_Distributions.clear();
  m_SteeringLimit = std::numeric_limits<double>::infinity();
  EvaluatePopulationFully();

  // The hypervolume's scales: 1.1 times the worst initial feasible value,
  // fixed for the run so that generations compare (BoundedHypervolume: a
  // front beyond them, such as the large deformations adaptive steering
  // keeps, still counts).
  ObjectiveVector worst{ { 0.0, 0.0, 0.0 } };
  for (std::size_t s = 0; s < m_Population.size(); ++s)
  {
    const Fitness f = CurrentFitness(s);
    if (f.feasible)
      for (std::size_t m = 0; m < NumberOfObjectives; ++m)
        worst[m] = std::max(worst[m], f.objectives[m]);
    InsertIntoArchive(s, f);
  }
  // With no feasible solution yet (a rigid strain limit the initial
  // deformations exceed, say), the whole population sets the scales.
  ObjectiveVector worstOfAll{ { 0.0, 0.0, 0.0 } };
  for (std::size_t s = 0; s < m_Population.size(); ++s)
    for (std::size_t m = 0; m < NumberOfObjectives; ++m)
      worstOfAll[m] = std::max(worstOfAll[m], CurrentFitness(s).objectives[m]);
  for (std::size_t m = 0; m < NumberOfObjectives; ++m)
  {
    const double w = worst[m] > 0.0 ? worst[m] : worstOfAll[m];
    m_Reference[m] = w > 0.0 && std::isfinite(w) ? 1.1 * w : 1.0;
  }
  // In batches: the per-tetrahedron values of a whole carried archive on a
  // fine mesh would take gigabytes at once.
  constexpr std::size_t batch = 256;
  for (std::size_t begin = 0; begin < archived.size(); begin += batch)
  {
    const std::size_t                             end = std::min(archived.size(), begin + batch);
    std::vector<const DualMesh *>                 solutions;
    std::vector<std::vector<TetrahedronValues>>   values(end - begin);
    std::vector<std::vector<TetrahedronValues> *> outputs;
    for (std::size_t a = begin; a < end; ++a)
    {
      if (archived[a].source.size() != m_Topology.NumberOfPoints() ||
          archived[a].target.size() != m_Topology.NumberOfPoints())
        throw Error("optimiser: an archived solution does not match the mesh");
      solutions.push_back(&archived[a]);
      outputs.push_back(&values[a - begin]);
    }
    m_Backend.EvaluateSolutions(solutions, outputs);
    for (std::size_t a = begin; a < end; ++a)
    {
      ObjectiveTotals totals;
      for (const auto & v : values[a - begin])
        totals.Add(v);
      const Fitness f = totals.ToFitness(m_Topology.NumberOfTetrahedra());
      if (f.feasible)
        m_Archive->Insert(f, archived[a], m_NextId++);
    }
  }
  m_History.push_back(Summarise(m_Generation, GenerationRecord{}));
}

GenerationRecord
MoRvGomea::Summarise(std::size_t generation, GenerationRecord r) const
{
  r.generation = generation;
  r.archiveSize = m_Archive->Size();
  std::vector<ObjectiveVector> points;
  r.bestGuidance = std::numeric_limits<double>::infinity();
  for (const auto & e : m_Archive->Entries())
  {
    points.push_back(e.fitness.objectives);
    r.bestGuidance = std::min(r.bestGuidance, Value(e.fitness.objectives, Objective::Guidance));
  }
  if (points.empty())
    r.bestGuidance = 0.0;
  r.hypervolume = BoundedHypervolume(points, m_Reference);
  for (std::size_t s = 0; s < m_Population.size(); ++s)
    if (std::llround(m_Totals[s].sum.folded) == 0)
      ++r.feasible;
  double      sum = 0.0;
  std::size_t n = 0;
  for (const auto & cluster : m_Distributions)
    for (const auto & d : cluster)
    {
      sum += d.multiplier;
      ++n;
    }
  r.meanMultiplier = n ? sum / static_cast<double>(n) : 1.0;
  return r;
}

void
MoRvGomea::RunGeneration()
{
  if (m_Population.empty())
    throw Error("optimiser: Initialize() must come before RunGeneration()");
  if (Finished())
    throw Error("optimiser: all " + std::to_string(m_Options.generations) + " generations have run");
  const auto              start = std::chrono::steady_clock::now();
  const BackendStatistics backendBefore = m_Backend.Statistics();
  GenerationRecord        record;
  RandomGenerator         random(HashCombine(m_Options.seed, static_cast<std::uint64_t>(m_Generation) + 1));

  // Adaptive steering: after the exploration period only guidance values up
  // to threshold x the archive's best are kept (a hard constraint).
  if (m_Options.steeringEnabled && m_Generation >= m_Options.steeringStart && m_Archive->Size() > 0)
  {
    double best = std::numeric_limits<double>::infinity();
    for (const auto & e : m_Archive->Entries())
      best = std::min(best, Value(e.fitness.objectives, Objective::Guidance));
    m_SteeringLimit = m_Options.steeringThreshold * best;
    const double limit = m_SteeringLimit;
    m_Archive->RemoveIf(
      [limit](const ArchiveEntry & e) { return Value(e.fitness.objectives, Objective::Guidance) > limit; });
  }

  const std::vector<Fitness>     fitness = PopulationFitness();
  const std::vector<std::size_t> selection = Select(fitness, random);
  std::vector<ClusterModel>      clusters = BuildClusters(selection, fitness, random);

  std::vector<std::size_t> groupOrder(m_Parallel.groups.size());
  std::iota(groupOrder.begin(), groupOrder.end(), std::size_t{ 0 });
  for (std::size_t i = groupOrder.size(); i > 1; --i)
    std::swap(groupOrder[i - 1], groupOrder[static_cast<std::size_t>(random.Uniform() * static_cast<double>(i))]);
  // The distributions of the first group's elements now; the others' (most
  // of the estimation) while the backend evaluates the first batch, before
  // a batch of another group is drawn (laterModels): the device then waits
  // at the generation's start for one group's models only. (Estimation was
  // a fifth of the main thread's work while the device waited there, late
  // in a paper-scale run on an H100 host: about 1.3 ms a generation.)
  const std::vector<std::uint32_t> firstGroup =
    groupOrder.empty() ? std::vector<std::uint32_t>{} : m_Parallel.groups[groupOrder.front()];
  std::vector<std::uint32_t> otherElements;
  {
    std::vector<bool> first(m_Parallel.elements.size(), false);
    for (std::uint32_t e : firstGroup)
      first[e] = true;
    for (std::uint32_t e = 0; e < m_Parallel.elements.size(); ++e)
      if (!first[e])
        otherElements.push_back(e);
  }
  EstimateDistributions(clusters, firstGroup, *m_Pool);
  record.phaseSeconds.modelling = SecondsSince(start);

  const std::size_t elements = m_Parallel.elements.size();
  std::vector<bool> improved(m_Population.size(), false);
  std::vector<int>  solutionCluster(m_Population.size(), -1);
  // Per cluster and element: sum of accepted samples, for the ratio test.
  std::vector<std::vector<std::vector<double>>> acceptedSum(clusters.size(), std::vector<std::vector<double>>(elements));
  std::vector<std::vector<std::size_t>>         acceptedCount(clusters.size(), std::vector<std::size_t>(elements, 0));
  const double n = static_cast<double>(m_Population.size());
  const double amsFraction = 0.5 * m_Options.selectionFraction * n / std::max(1.0, n - 1.0);

  // Each solution belongs to one cluster, so one batch can hold a parallel
  // group's candidates for the whole population: the backend sees a few large
  // batches per generation rather than one per cluster and group. Acceptance
  // still runs cluster by cluster within each batch.
  struct Member
  {
    std::size_t solution;
    std::size_t cluster;
    bool        anticipate;
  };
  std::vector<Member> members;
  members.reserve(m_Population.size());
  for (std::size_t c = 0; c < clusters.size(); ++c)
  {
    const ClusterModel & cluster = clusters[c];
    if (cluster.population.empty() || cluster.means.empty())
      continue;
    std::vector<std::size_t> order = cluster.population;
    for (std::size_t i = order.size(); i > 1; --i)
      std::swap(order[i - 1], order[static_cast<std::size_t>(random.Uniform() * static_cast<double>(i))]);
    const auto amsCount = static_cast<std::size_t>(amsFraction * static_cast<double>(order.size()));
    for (std::size_t j = 0; j < order.size(); ++j)
    {
      members.push_back({ order[j], c, j < amsCount });
      solutionCluster[order[j]] = cluster.singleObjective;
    }
  }

  // A batch: one parallel group's candidates of members [firstMember,
  // endMember). The generation's first group goes in two batches of half
  // the members each: the device then waits at the generation's start only
  // for the first half to be drawn and packed, and the second half, drawn
  // meanwhile, starts as a whole behind it (no solution is in both). The
  // order of the candidates, their seeds and the acceptance are those of
  // one batch.
  struct BatchSpan
  {
    std::size_t group, firstMember, endMember;
  };
  std::vector<BatchSpan> spans;
  for (std::size_t i = 0; i < groupOrder.size(); ++i)
  {
    const std::size_t split =
      i == 0 && m_Options.firstBatchSplit > 0 && members.size() >= m_Options.firstBatchSplit ? members.size() / 2 : 0;
    if (split > 0)
      spans.push_back({ groupOrder[i], 0, split });
    spans.push_back({ groupOrder[i], split, members.size() });
  }

  // Each batch's candidates are drawn while the backend evaluates the one
  // before (their samples depend on the cluster models only, not on what
  // that batch accepts). Their seeds come from `random` here, batch by
  // batch in order, as if each were drawn just before its evaluation; the
  // rest may run on the draw-ahead threads (m_Drawer), which draw the batch
  // after next while this thread feeds the backend and accepts. Batch i
  // lives in m_Batches[i % 3].
  const auto slot = [this](std::size_t i) -> CandidateBatch & { return *m_Batches[i % m_Batches.size()]; };
  const auto seedBatch = [&](const BatchSpan & span, CandidateBatch & next) {
    // Member by member, each one's elements in group order.
    next.candidates.resize((span.endMember - span.firstMember) * m_Parallel.groups[span.group].size());
    for (Candidate & cand : next.candidates)
      cand.seed = random.NextU64();
  };
  const auto drawBatch = [&](const BatchSpan & span, CandidateBatch & next, ThreadPool & pool) {
    std::vector<Candidate> &           candidates = next.candidates;
    const std::vector<std::uint32_t> & group = m_Parallel.groups[span.group];
    pool.ParallelFor(span.endMember - span.firstMember, [&](std::size_t m) {
      const Member & member = members[span.firstMember + m];
      for (std::size_t k = 0; k < group.size(); ++k)
      {
        Candidate &         cand = candidates[m * group.size() + k];
        const std::uint64_t seed = cand.seed;
        cand = Candidate{};
        cand.solution = member.solution;
        cand.element = group[k];
        cand.cluster = member.cluster;
        cand.singleObjective = clusters[member.cluster].singleObjective;
        cand.seed = seed;
        cand.anticipate = member.anticipate;
      }
    });
    SampleCandidates(next, clusters, pool);
  };
  // Whether the other elements' distributions are estimated, or are being
  // estimated ahead of the batch drawn ahead that first needs them.
  bool       laterModels = otherElements.empty();
  const auto needsLaterModels = [&](std::size_t i) { return !laterModels && spans[i].group != groupOrder.front(); };
  // The span the draw-ahead threads draw or have drawn (none: spans.size()).
  std::size_t drawnAhead = spans.size();
  const auto  drawAhead = [&](std::size_t i) {
    seedBatch(spans[i], slot(i));
    drawnAhead = i;
    const bool estimate = needsLaterModels(i);
    laterModels = laterModels || estimate;
    m_Drawer->Start([&, i, estimate] {
      if (estimate)
        EstimateDistributions(clusters, otherElements, *m_DrawPool);
      drawBatch(spans[i], slot(i), *m_DrawPool);
      BuildPartials(slot(i), *m_DrawPool);
    });
  };
  // A job under way reads this generation's models: it ends before they go.
  struct DrawerWait
  {
    BackgroundWorker * drawer;
    ~DrawerWait()
    {
      if (drawer)
        try
        {
          drawer->Wait();
        }
        catch (...) // an error on the way out already
        {
        }
    }
  } drawerWait{ m_Drawer.get() };
  // The accepted candidates' samples, summed per cluster and element for the
  // multipliers, batch by batch in order: a batch's in the meanwhile of the
  // next, while the device works and before the draw-ahead threads draw
  // into its slot, the last one's after it. (Each batch's pass over its
  // tens of thousands of candidates took 0.1-0.15 ms on the 2-core
  // development machine, between one batch's acceptance and the next's.)
  std::size_t unsummed = spans.size(); // the batch whose samples are not yet added (none: spans.size())
  const auto  addAccepted = [&] {
    if (unsummed == spans.size())
      return;
    CandidateBatch & batch = slot(unsummed);
    unsummed = spans.size();
    for (const Candidate & cand : batch.candidates)
      if (cand.accepted)
      {
        improved[cand.solution] = true;
        auto &         sum = acceptedSum[cand.cluster][cand.element];
        const double * sample = batch.Sample(cand);
        sum.resize(6 * m_Parallel.elements[cand.element].points.size(), 0.0);
        for (std::size_t a = 0; a < sum.size(); ++a)
          sum[a] += sample[a];
        ++acceptedCount[cand.cluster][cand.element];
      }
  };
  // The generation's first batch, and in its meanwhile the second, are
  // drawn here on the pool: the models are new, so nothing was drawn ahead.
  if (!spans.empty())
  {
    const auto sampling = std::chrono::steady_clock::now();
    seedBatch(spans.front(), slot(0));
    drawBatch(spans.front(), slot(0), *m_Pool);
    record.phaseSeconds.sampling += SecondsSince(sampling);
  }
  for (std::size_t i = 0; i < spans.size(); ++i)
  {
    CandidateBatch &             batch = slot(i);
    EvaluationBackend::Meanwhile drawNext;
    if (i + 1 < spans.size())
      drawNext = [&, i] {
        CandidateBatch & next = slot(i + 1);
        const bool       drawn = drawnAhead == i + 1;
        if (!drawn && needsLaterModels(i + 1))
        {
          const auto modelling = std::chrono::steady_clock::now();
          EstimateDistributions(clusters, otherElements, *m_Pool);
          laterModels = true;
          record.phaseSeconds.modelling += SecondsSince(modelling);
        }
        addAccepted(); // before the draw-ahead threads draw into its slot
        const auto sampling = std::chrono::steady_clock::now();
        if (drawn)
          m_Drawer->Wait();
        else
        {
          seedBatch(spans[i + 1], next);
          drawBatch(spans[i + 1], next, *m_Pool);
        }
        record.phaseSeconds.sampling += SecondsSince(sampling);
        if (m_Drawer && i + 2 < spans.size())
          drawAhead(i + 2);
        // The backend packs what it can of the next batch now: what this
        // batch's acceptance changes (parents, their keys) comes later.
        const auto staging = std::chrono::steady_clock::now();
        if (!drawn)
          BuildPartials(next, *m_Pool);
        m_Backend.PrepareNextPartials(next.partials);
        record.phaseSeconds.evaluation += SecondsSince(staging);
      };
    ProcessCandidates(batch, record, drawNext, i + 1 < spans.size() ? &slot(i + 1) : nullptr);
    addAccepted(); // the batch before, where no meanwhile took it
    unsummed = i;
  }
  addAccepted();
  const auto bookkeeping = std::chrono::steady_clock::now();
  double     forcedSeconds = 0.0;

  UpdateDistributionStates(clusters, acceptedSum, acceptedCount);

  // Forced improvements for solutions stalled too long.
  const std::size_t maxStretch = NoImprovementStretchBase + 12;
  for (std::size_t s = 0; s < m_Population.size(); ++s)
  {
    m_NoImprovement[s] = improved[s] ? 0 : m_NoImprovement[s] + 1;
    if (m_NoImprovement[s] > maxStretch)
    {
      const auto forced = std::chrono::steady_clock::now();
      ForcedImprovement(s, solutionCluster[s], random, record);
      const double seconds = SecondsSince(forced);
      record.phaseSeconds.forcedImprovements += seconds;
      forcedSeconds += seconds;
      m_NoImprovement[s] = 0;
    }
  }

  ++m_Generation;
  if (m_Options.fullEvaluationInterval > 0 && m_Generation % m_Options.fullEvaluationInterval == 0)
  {
    EvaluatePopulationFully();
    record.tetrahedronEvaluations += n * static_cast<double>(m_Topology.NumberOfTetrahedra());
  }
  GenerationRecord summary = Summarise(m_Generation, record);
  summary.phaseSeconds.bookkeeping = SecondsSince(bookkeeping) - forcedSeconds;
  summary.seconds = SecondsSince(start);
  summary.deviceKernelSeconds = m_Backend.Statistics().kernelSeconds - backendBefore.kernelSeconds;
  summary.deviceSpanSeconds = m_Backend.Statistics().BatchSpanSeconds() - backendBefore.BatchSpanSeconds();
  summary.samples = m_Backend.Statistics().samples - backendBefore.samples;
  summary.boundSkipped = m_Backend.Statistics().boundSkipped - backendBefore.boundSkipped;
  summary.boundSkippedSamples = m_Backend.Statistics().boundSkippedSamples - backendBefore.boundSkippedSamples;
  summary.boundSampledLater = m_Backend.Statistics().boundSampledLater - backendBefore.boundSampledLater;
  summary.boundSampleLaterCalls = m_Backend.Statistics().boundSampleLaterCalls - backendBefore.boundSampleLaterCalls;
  summary.boundSampleLaterSeconds =
    m_Backend.Statistics().boundSampleLaterSeconds - backendBefore.boundSampleLaterSeconds;
  m_History.push_back(summary);
}

void
MoRvGomea::Run(const std::function<void(const GenerationRecord &)> & onGeneration)
{
  while (!Finished())
  {
    RunGeneration();
    if (onGeneration)
      onGeneration(m_History.back());
  }
}
} // namespace morea_core
