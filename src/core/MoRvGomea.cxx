#include "morea/MoRvGomea.h"

#include "morea/Error.h"
#include "morea/MeshRepair.h"
#include "morea/ParameterSet.h"
#include "morea/RefusalBound.h"
#include "morea/ThreadPool.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

namespace morea
{
namespace
{
// Settings of AMaLGaM / RV-GOMEA that MO-RV-GOMEA inherits.
constexpr double      MultiplierDecrease = 0.9;
constexpr double      MultiplierIncrease = 1.0 / 0.9;
constexpr double      MultiplierMaximum = 10.0;
constexpr double      StandardDeviationRatioThreshold = 1.0;
constexpr double      AmsDelta = 2.0;
constexpr std::size_t KMeansIterations = 3;
// Generations without improvement tolerated: 25 + the number of variables
// (per distribution; per solution that of an edge element, 12).
constexpr std::size_t NoImprovementStretchBase = 25;
double
SecondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Random streams derived from a candidate's seed (the repair uses 0 and 1: the side).
constexpr std::uint64_t SamplingStream = 2;

double
Normalised(double v, double low, double high)
{
  return high > low ? (v - low) / (high - low) : 0.0;
}

double
SquaredDistance(const ObjectiveVector & a, const ObjectiveVector & b)
{
  double s = 0.0;
  for (std::size_t m = 0; m < NumberOfObjectives; ++m)
    s += (a[m] - b[m]) * (a[m] - b[m]);
  return s;
}

/** Per-objective range of a set of solutions, mapping objectives to [0, 1]. */
struct ObjectiveRange
{
  ObjectiveVector low, high;

  ObjectiveRange(const std::vector<std::size_t> & members, const std::vector<Fitness> & fitness)
  {
    low.fill(std::numeric_limits<double>::infinity());
    high.fill(-std::numeric_limits<double>::infinity());
    for (std::size_t s : members)
      for (std::size_t m = 0; m < NumberOfObjectives; ++m)
      {
        low[m] = std::min(low[m], fitness[s].objectives[m]);
        high[m] = std::max(high[m], fitness[s].objectives[m]);
      }
  }
  ObjectiveVector
  Normalise(const Fitness & f) const
  {
    ObjectiveVector v;
    for (std::size_t m = 0; m < NumberOfObjectives; ++m)
      v[m] = Normalised(f.objectives[m], low[m], high[m]);
    return v;
  }
};

/** Lower Cholesky factor of the n x n matrix `a` (row-major), regularised
 *  on the diagonal until it exists (pinned coordinates have zero variance). */
std::vector<double>
RegularisedCholesky(std::vector<double> a, std::size_t n)
{
  double scale = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    scale = std::max(scale, a[i * n + i]);
  double jitter = std::max(scale, 1e-12) * 1e-10;
  for (int attempt = 0; attempt < 40; ++attempt)
  {
    std::vector<double> l(n * n, 0.0);
    bool                ok = true;
    for (std::size_t i = 0; i < n && ok; ++i)
      for (std::size_t j = 0; j <= i; ++j)
      {
        double s = a[i * n + j] + (i == j ? jitter : 0.0);
        for (std::size_t k = 0; k < j; ++k)
          s -= l[i * n + k] * l[j * n + k];
        if (i == j)
        {
          if (!(s > 0.0))
          {
            ok = false;
            break;
          }
          l[i * n + i] = std::sqrt(s);
        }
        else
          l[i * n + j] = s / l[j * n + j];
      }
    if (ok)
      return l;
    jitter *= 10.0;
  }
  throw Error("optimiser: a distribution's covariance has no Cholesky factor");
}

void
Gather(const DualMesh & solution, const FosElement & element, double * x)
{
  for (std::size_t k = 0; k < element.points.size(); ++k)
    for (int a = 0; a < 3; ++a)
    {
      x[6 * k + a] = solution.source[element.points[k]][a];
      x[6 * k + 3 + a] = solution.target[element.points[k]][a];
    }
}
} // namespace

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
  return o;
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
  if (options.populationSize < 2)
    throw Error("optimiser: the population needs at least 2 solutions");
  if (options.numberOfClusters < 1 || options.archiveCapacity < 1)
    throw Error("optimiser: at least one cluster and an archive of at least 1 are needed");
  if (!(options.selectionFraction > 0.0 && options.selectionFraction <= 1.0))
    throw Error("optimiser: the selection fraction must be in (0, 1]");
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
MoRvGomea::Initialize(std::vector<DualMesh> population)
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
  m_Generation = 0;
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
  for (std::size_t m = 0; m < NumberOfObjectives; ++m)
    m_Reference[m] = worst[m] > 0.0 ? 1.1 * worst[m] : 1.0;
  m_History.push_back(Summarise(0, GenerationRecord{}));
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

std::vector<std::size_t>
MoRvGomea::Select(const std::vector<Fitness> & fitness, RandomGenerator & random) const
{
  const std::size_t n = fitness.size();
  const std::size_t wanted = std::min(
    n, std::max<std::size_t>(m_Options.numberOfClusters,
                             static_cast<std::size_t>(std::ceil(m_Options.selectionFraction * static_cast<double>(n)))));
  const std::vector<std::size_t> ranks = NonDominatedRanks(fitness, m_Pool.get());
  std::vector<std::size_t>       order(n);
  std::iota(order.begin(), order.end(), std::size_t{ 0 });
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return ranks[a] < ranks[b]; });
  std::vector<std::size_t> selection;
  std::size_t              i = 0;
  while (i < n && selection.size() + std::count(ranks.begin(), ranks.end(), ranks[order[i]]) <= wanted)
  {
    const std::size_t rank = ranks[order[i]];
    while (i < n && ranks[order[i]] == rank)
      selection.push_back(order[i++]);
  }
  if (selection.size() < wanted && i < n)
  {
    // The front that does not fit: a spread-out subset in normalised objective
    // space, greedily farthest from what is already selected.
    std::vector<std::size_t> front;
    for (std::size_t j = i; j < n && ranks[order[j]] == ranks[order[i]]; ++j)
      front.push_back(order[j]);
    const ObjectiveRange range(front, fitness);
    auto                 norm = [&](std::size_t s) { return range.Normalise(fitness[s]); };
    std::vector<double> nearest(front.size(), std::numeric_limits<double>::infinity());
    std::vector<bool>   taken(front.size(), false);
    std::size_t         pick = static_cast<std::size_t>(random.Uniform() * static_cast<double>(front.size()));
    while (selection.size() < wanted)
    {
      taken[pick] = true;
      selection.push_back(front[pick]);
      const ObjectiveVector p = norm(front[pick]);
      double                far = -1.0;
      for (std::size_t j = 0; j < front.size(); ++j)
        if (!taken[j])
        {
          nearest[j] = std::min(nearest[j], SquaredDistance(p, norm(front[j])));
          if (nearest[j] > far)
          {
            far = nearest[j];
            pick = j;
          }
        }
      if (far < 0.0)
        break;
    }
  }
  return selection;
}

std::vector<MoRvGomea::ClusterModel>
MoRvGomea::BuildClusters(const std::vector<std::size_t> & selection, const std::vector<Fitness> & fitness,
                         RandomGenerator & random)
{
  // Normalised objective space of the selection.
  const ObjectiveRange range(selection, fitness);
  const ObjectiveVector & low = range.low;
  const ObjectiveVector & high = range.high;
  auto norm = [&](std::size_t s) { return range.Normalise(fitness[s]); };
  std::vector<ObjectiveVector> points;
  for (std::size_t s : selection)
    points.push_back(norm(s));

  const std::size_t k = std::min(m_Options.numberOfClusters, selection.size());
  const std::size_t clusterSize =
    std::min(selection.size(), std::max<std::size_t>(2, (2 * selection.size() + k - 1) / k));

  // k-leader-means: spread-out leaders, then a few k-means steps.
  std::vector<ObjectiveVector> means;
  std::vector<double>          nearest(points.size(), std::numeric_limits<double>::infinity());
  std::size_t leader = static_cast<std::size_t>(random.Uniform() * static_cast<double>(points.size()));
  while (means.size() < k)
  {
    means.push_back(points[leader]);
    double far = -1.0;
    for (std::size_t j = 0; j < points.size(); ++j)
    {
      nearest[j] = std::min(nearest[j], SquaredDistance(points[j], means.back()));
      if (nearest[j] > far)
      {
        far = nearest[j];
        leader = j;
      }
    }
  }
  for (std::size_t iteration = 0; iteration < KMeansIterations; ++iteration)
  {
    std::vector<ObjectiveVector> sums(k, ObjectiveVector{ { 0.0, 0.0, 0.0 } });
    std::vector<std::size_t>     counts(k, 0);
    for (const auto & p : points)
    {
      std::size_t best = 0;
      for (std::size_t c = 1; c < k; ++c)
        if (SquaredDistance(p, means[c]) < SquaredDistance(p, means[best]))
          best = c;
      for (std::size_t m = 0; m < NumberOfObjectives; ++m)
        sums[best][m] += p[m];
      ++counts[best];
    }
    for (std::size_t c = 0; c < k; ++c)
      if (counts[c])
        for (std::size_t m = 0; m < NumberOfObjectives; ++m)
          means[c][m] = sums[c][m] / static_cast<double>(counts[c]);
  }

  std::vector<ClusterModel> clusters(k + NumberOfObjectives);
  std::vector<std::size_t>  order(points.size());
  for (std::size_t c = 0; c < k; ++c)
  {
    // The clusterSize selected solutions nearest the mean (clusters overlap).
    std::iota(order.begin(), order.end(), std::size_t{ 0 });
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return SquaredDistance(points[a], means[c]) < SquaredDistance(points[b], means[c]);
    });
    clusters[c].mean = means[c];
    for (std::size_t j = 0; j < clusterSize; ++j)
      clusters[c].members.push_back(selection[order[j]]);
  }
  // Single-objective clusters: the best of the selection in one objective, to
  // push the extremes of the front outwards. Objectives without spread (e.g.
  // guidance when disabled) get none.
  for (std::size_t m = 0; m < NumberOfObjectives; ++m)
  {
    ClusterModel & cluster = clusters[k + m];
    cluster.singleObjective = static_cast<int>(m);
    if (!(high[m] > low[m]))
      continue;
    std::iota(order.begin(), order.end(), std::size_t{ 0 });
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      const Fitness & fa = fitness[selection[a]];
      const Fitness & fb = fitness[selection[b]];
      if (fa.feasible != fb.feasible)
        return fa.feasible;
      return fa.objectives[m] < fb.objectives[m];
    });
    const std::size_t size = std::min(clusterSize, std::max<std::size_t>(2, selection.size() / k));
    ObjectiveVector   mean{ { 0.0, 0.0, 0.0 } };
    for (std::size_t j = 0; j < size; ++j)
    {
      cluster.members.push_back(selection[order[j]]);
      for (std::size_t q = 0; q < NumberOfObjectives; ++q)
        mean[q] += points[order[j]][q] / static_cast<double>(size);
    }
    cluster.mean = mean;
  }

  // Carry the adaptive state over: regular clusters from the nearest previous
  // regular cluster, single-objective ones from their predecessor.
  const std::size_t                           elements = m_Parallel.elements.size();
  std::vector<std::vector<DistributionState>> states(clusters.size(),
                                                     std::vector<DistributionState>(elements));
  const std::size_t previousRegular =
    m_ClusterMeans.size() >= NumberOfObjectives ? m_ClusterMeans.size() - NumberOfObjectives : 0;
  for (std::size_t c = 0; c < clusters.size(); ++c)
  {
    if (m_Distributions.empty())
      break;
    std::size_t from = c;
    if (c < k)
    {
      if (previousRegular == 0)
        continue;
      from = 0;
      for (std::size_t p = 1; p < previousRegular; ++p)
        if (SquaredDistance(clusters[c].mean, m_ClusterMeans[p]) < SquaredDistance(clusters[c].mean, m_ClusterMeans[from]))
          from = p;
    }
    else
      from = previousRegular + (c - k);
    if (from < m_Distributions.size())
      states[c] = m_Distributions[from];
  }
  m_Distributions = std::move(states);
  m_ClusterMeans.clear();
  for (const auto & c : clusters)
    m_ClusterMeans.push_back(c.mean);

  // Every solution is varied with the model of the cluster whose mean is
  // nearest to it.
  for (std::size_t s = 0; s < m_Population.size(); ++s)
  {
    const ObjectiveVector p = norm(s);
    std::size_t           best = clusters.size();
    for (std::size_t c = 0; c < clusters.size(); ++c)
      if (!clusters[c].members.empty() &&
          (best == clusters.size() || SquaredDistance(p, clusters[c].mean) < SquaredDistance(p, clusters[best].mean)))
        best = c;
    clusters[best].population.push_back(s);
  }
  return clusters;
}

void
MoRvGomea::EstimateDistributions(std::vector<ClusterModel> & clusters, const std::vector<std::uint32_t> & elements,
                                 ThreadPool & pool) const
{
  // Every (cluster, element) pair is independent: estimate them in parallel.
  std::vector<std::pair<std::size_t, std::size_t>> work;
  for (std::size_t c = 0; c < clusters.size(); ++c)
  {
    ClusterModel & cluster = clusters[c];
    if (cluster.members.empty() || cluster.population.empty())
      continue;
    if (cluster.means.size() != m_Parallel.elements.size()) // the first call sizes them
    {
      cluster.means.resize(m_Parallel.elements.size());
      cluster.cholesky.resize(m_Parallel.elements.size());
    }
    for (std::uint32_t e : elements)
      work.emplace_back(c, e);
  }
  pool.ParallelFor(work.size(), [&](std::size_t w) {
    ClusterModel &      cluster = clusters[work[w].first];
    const std::size_t   e = work[w].second;
    const double        count = static_cast<double>(cluster.members.size());
    const FosElement &  element = m_Parallel.elements[e];
    const std::size_t   n = 6 * element.points.size();
    std::vector<double> mean(n, 0.0), covariance(n * n, 0.0);
    std::vector<double> all(n * cluster.members.size());
    for (std::size_t j = 0; j < cluster.members.size(); ++j)
    {
      Gather(m_Population[cluster.members[j]], element, all.data() + j * n);
      for (std::size_t i = 0; i < n; ++i)
        mean[i] += all[j * n + i] / count;
    }
    for (std::size_t j = 0; j < cluster.members.size(); ++j)
    {
      const double * v = all.data() + j * n;
      for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = 0; b <= a; ++b)
          covariance[a * n + b] += (v[a] - mean[a]) * (v[b] - mean[b]) / count;
    }
    // Few members for many variables give a singular estimate that only
    // samples the members' span: shrink the off-diagonal part towards 0 by
    // the ratio of variables to members (the full estimate for large clusters).
    const double shrink = std::min(1.0, static_cast<double>(n) / count);
    for (std::size_t a = 0; a < n; ++a)
      for (std::size_t b = 0; b < a; ++b)
        covariance[b * n + a] = covariance[a * n + b] *= (1.0 - shrink);
    cluster.means[e] = std::move(mean);
    cluster.cholesky[e] = RegularisedCholesky(std::move(covariance), n);
  });
}

void
MoRvGomea::SampleCandidates(CandidateBatch & batch, const std::vector<ClusterModel> & clusters,
                            ThreadPool & pool) const
{
  batch.Layout(m_Parallel);
  pool.ParallelFor(batch.candidates.size(), [&](std::size_t i) {
    Candidate &                 cand = batch.candidates[i];
    const ClusterModel &        cluster = clusters[cand.cluster];
    const FosElement &          element = m_Parallel.elements[cand.element];
    const std::size_t           dim = 6 * element.points.size();
    const std::vector<double> & mean = cluster.means[cand.element];
    const std::vector<double> & l = cluster.cholesky[cand.element];
    const DistributionState &   state = m_Distributions[cand.cluster][cand.element];
    RandomGenerator             random(HashCombine(cand.seed, SamplingStream));
    thread_local std::vector<double> z;
    z.resize(dim);
    double *                    x = batch.Sample(cand);
    for (auto & v : z)
      v = random.Normal();
    const double scale = std::sqrt(state.multiplier);
    for (std::size_t a = 0; a < dim; ++a)
    {
      double v = 0.0;
      for (std::size_t b = 0; b <= a; ++b)
        v += l[a * dim + b] * z[b];
      x[a] = mean[a] + scale * v;
    }
    if (cand.anticipate && state.previousMean.size() == dim)
      for (std::size_t a = 0; a < dim; ++a)
        x[a] += AmsDelta * state.multiplier * (mean[a] - state.previousMean[a]);
    Vec3 *                      source = batch.Source(cand);
    Vec3 *                      target = batch.Target(cand);
    for (std::size_t k = 0; k < element.points.size(); ++k)
    {
      const std::uint32_t p = element.points[k];
      source[k] = ProjectToDomain({ { x[6 * k], x[6 * k + 1], x[6 * k + 2] } }, m_Base.pins[p], m_Base.domain);
      target[k] =
        ProjectToDomain({ { x[6 * k + 3], x[6 * k + 4], x[6 * k + 5] } }, m_Base.pins[p], m_Base.domain);
    }
  });
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
  }
  const auto bookkeeping = std::chrono::steady_clock::now();
  double     forcedSeconds = 0.0;

  // Distribution multipliers (adaptive variance scaling with the
  // standard-deviation-ratio test and the no-improvement stretch).
  for (std::size_t c = 0; c < clusters.size(); ++c)
  {
    if (clusters[c].means.empty() || clusters[c].population.empty())
      continue;
    for (std::size_t e = 0; e < elements; ++e)
    {
      DistributionState & state = m_Distributions[c][e];
      const std::size_t   dim = clusters[c].means[e].size();
      const std::size_t   maxStretch = NoImprovementStretchBase + dim;
      if (acceptedCount[c][e] > 0)
      {
        // SDR: the accepted samples' mean in standard deviations of the model.
        std::vector<double> d(dim), y(dim);
        for (std::size_t a = 0; a < dim; ++a)
          d[a] = acceptedSum[c][e][a] / static_cast<double>(acceptedCount[c][e]) - clusters[c].means[e][a];
        const auto & l = clusters[c].cholesky[e];
        double       ratio = 0.0;
        for (std::size_t a = 0; a < dim; ++a)
        {
          double v = d[a];
          for (std::size_t b = 0; b < a; ++b)
            v -= l[a * dim + b] * y[b];
          y[a] = v / l[a * dim + a];
          ratio = std::max(ratio, std::abs(y[a]));
        }
        state.noImprovementStretch = 0;
        if (state.multiplier < 1.0)
          state.multiplier = 1.0;
        if (ratio > StandardDeviationRatioThreshold)
          state.multiplier = std::min(MultiplierMaximum, state.multiplier * MultiplierIncrease);
      }
      else
      {
        if (state.multiplier <= 1.0)
          ++state.noImprovementStretch;
        if (state.multiplier > 1.0 || state.noImprovementStretch >= maxStretch)
          state.multiplier *= MultiplierDecrease;
        if (state.multiplier < 1.0 && state.noImprovementStretch < maxStretch)
          state.multiplier = 1.0;
      }
      state.previousMean = clusters[c].means[e];
    }
  }

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
} // namespace morea
