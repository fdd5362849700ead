// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: MO-RV-GOMEA (SPEC 5), the multi-objective
// real-valued gene-pool optimal mixing evolutionary algorithm, specialised to
// the dual-dynamic mesh: FOS elements are mesh edges (6 variables per point),
// partial evaluations touch only an element's dependent tetrahedra, and the
// elements of one parallel group are varied and evaluated together.
//
// One generation: rank the population (constraint domination), select the
// best tau*P, cluster the selection in normalised objective space
// (k-leader-means plus one single-objective cluster per objective), estimate
// per cluster and FOS element a normal distribution, then let every solution
// sample each element of its cluster (parallel group by parallel group),
// repair folds, evaluate, and accept a partial change when the result
// dominates the parent or enters the elitist archive. Distribution
// multipliers adapt, stalled solutions get forced improvements, the
// population is re-evaluated in full every 50 generations, and after the
// exploration period adaptive steering keeps the front near the best guidance.
//
// Randomness: generation g draws from a generator seeded by (seed, g) only,
// so a checkpoint needs no generator state and any thread count gives the
// same result.
#ifndef morea_MoRvGomea_h
#define morea_MoRvGomea_h

#include "morea_core/ElitistArchive.h"
#include "morea_core/EvaluationBackend.h"
#include "morea_core/FoldConstraint.h"
#include "morea_core/MemoryEstimate.h"
#include "morea_core/ParallelStructure.h"
#include "morea_core/Random.h"
#include "morea_core/RunFingerprint.h"
#include "morea_core/TetrahedralMesh.h"

#include <array>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

namespace morea_core
{
class BackgroundWorker;
class ParameterSet;
class ThreadPool;

struct GomeaOptions
{
  std::size_t   populationSize{ 700 };
  std::size_t   numberOfClusters{ 10 };
  std::size_t   archiveCapacity{ 2000 };
  std::size_t   generations{ 500 }; ///< the generation the run (or this mesh level) ends at
  /** The generation this optimiser starts at: 0, or where a mesh level
   *  begins, so that a multi-level run numbers its generations (and seeds
   *  their random streams, starts steering) as one run. */
  std::size_t   firstGeneration{ 0 };
  double        selectionFraction{ 0.35 }; ///< tau
  bool          steeringEnabled{ true };
  std::size_t   steeringStart{ 100 };
  double        steeringThreshold{ 1.5 };
  bool          repair{ true };
  std::size_t   fullEvaluationInterval{ 50 };
  std::uint64_t seed{ 0 };
  /** Host threads that sample candidates and check them for folds (0: one per
   *  hardware thread). The result does not depend on it. */
  std::size_t threads{ 0 };
  /** Lets the backend skip sampling candidates that a bound shows refused
   *  (RefusalBound.h). The result does not depend on it; whether it saves
   *  time depends on the backend (UsesRefusalBounds decides for `morea`). */
  bool boundRefusals{ true };
  /** The generation's first parallel group goes to the backend in two
   *  batches of half the population each when the population has at least
   *  this many members (0: never), so that the device waits at the
   *  generation's start only for the first half. The result does not depend
   *  on it. */
  std::size_t firstBatchSplit{ 64 };
  /** Threads of their own, at idle priority beside the optimiser's pool,
   *  that draw a generation's third and later batches of candidates while
   *  the batch two before is evaluated and accepted, so that the
   *  optimiser's own thread, which feeds the backend and accepts, does not
   *  draw them. 0: the optimiser's thread draws the next batch on its pool
   *  while the backend evaluates the current one (as it always draws the
   *  first two, which need the generation's new models). DrawAheadAutomatic:
   *  the pool's threads less 2 where the backend evaluates beside the host
   *  (EvaluationBackend::EvaluatesBesideHost) and the pool has at least 8,
   *  otherwise 0. The result does not depend on it. */
  static constexpr std::size_t DrawAheadAutomatic = ~std::size_t{ 0 };
  std::size_t                  drawAheadThreads{ DrawAheadAutomatic };
  /** What the front depends on beyond these options (inputs, preprocessing
   *  and objective parameters; the caller knows them): stored in checkpoints,
   *  and a checkpoint with another is refused. The optimiser adds the mesh. */
  RunFingerprint fingerprint;

  /** ea_* keys, morea_repair_method and seed; checked (Check). */
  static GomeaOptions
  FromParameters(const ParameterSet & parameters);

  /** Throws morea_core::Error for options no run can use: fewer than 2
   *  solutions, more clusters than solutions, no archive, a selection
   *  fraction outside (0, 1]. Needs no mesh: callers check before meshing,
   *  and the optimiser checks again. */
  void
  Check() const;
};

/** What one generation achieved (the per-generation log). */
struct GenerationRecord
{
  std::size_t generation{ 0 };
  double      hypervolume{ 0.0 };  ///< of the archive (BoundedHypervolume, scaled by the reference point)
  double      bestGuidance{ 0.0 }; ///< in the archive
  std::size_t archiveSize{ 0 };
  std::size_t feasible{ 0 };            ///< fold-free solutions in the population
  std::size_t accepted{ 0 };            ///< partial changes accepted this generation
  std::size_t candidates{ 0 };          ///< partial changes sampled this generation
  std::size_t folded{ 0 };              ///< of which folded a tetrahedron (before repair)
  std::size_t repaired{ 0 };            ///< candidates whose folds the repair removed
  std::size_t forcedImprovements{ 0 };
  double      meanMultiplier{ 0.0 };    ///< over clusters and elements
  double      tetrahedronEvaluations{ 0.0 }; ///< this generation
  double      seconds{ 0.0 };           ///< wall time of this generation
  /** Where the generation's wall time went (host timers; evaluation is the
   *  backend's calls, incl. transfers and waiting for the GPU). */
  struct Phases
  {
    double sampling{ 0.0 };   ///< drawing candidates here, or waiting for the draw-ahead threads
    double foldChecks{ 0.0 }; ///< incl. repair
    double evaluation{ 0.0 };
    double acceptance{ 0.0 };
    double forcedImprovements{ 0.0 }; ///< all of it, its own phases included
    double modelling{ 0.0 };   ///< steering, selection, clustering and estimation
    double bookkeeping{ 0.0 }; ///< multipliers, periodic full evaluation and the summary
    double parentState{ 0.0 }; ///< parents' keys and refusal bounds before each batch's evaluation
  } phaseSeconds;
  /** The backend's device time in this generation (the evaluation kernels;
   *  0 on the CPU backend) and its sample points, both directions: the
   *  kernels' share of the generation and their throughput. */
  double deviceKernelSeconds{ 0.0 };
  /** The device time from the first upload to the last kernel of each
   *  partial-evaluation batch (0 on the CPU backend): the generation's time
   *  beyond it the device waited for the host. */
  double deviceSpanSeconds{ 0.0 };
  double samples{ 0.0 };
  /** Candidates whose refusal bound spared their sampling (RefusalBound.h),
   *  the samples spared, and those sampled later after all. */
  std::size_t boundSkipped{ 0 };
  double      boundSkippedSamples{ 0.0 };
  std::size_t boundSampledLater{ 0 };
  std::size_t boundSampleLaterCalls{ 0 };
  double      boundSampleLaterSeconds{ 0.0 };
};

/** Per cluster and FOS element: what carries over between generations. */
struct DistributionState
{
  std::vector<double> previousMean; ///< empty before the first estimate
  double              multiplier{ 1.0 };
  std::size_t         noImprovementStretch{ 0 };
};

class MoRvGomea
{
public:
  /** All references must outlive the optimiser. */
  MoRvGomea(const TetrahedralMesh & base, const MeshTopology & topology, const ParallelStructure & parallel,
            const FoldConstraint & constraint, EvaluationBackend & backend, const GomeaOptions & options);
  ~MoRvGomea();

  /** The host memory a run of `shape` keeps (MemoryEstimate.h): the
   *  population with its tetrahedra's values and element sums, three
   *  batches of candidates, the archive, the distributions and, with
   *  checkpoints, their buffers. */
  static MemoryEstimate
  MemoryFor(const RunShape & shape);

  /** Evaluates `population` (size populationSize; folded solutions are
   *  repaired first) and seeds the archive with it and with `archived`
   *  (e.g. a coarser mesh level's archive carried over; folded ones are
   *  left out). */
  void
  Initialize(std::vector<DualMesh> population, const std::vector<DualMesh> & archived = {});

  /** One generation; throws when called after the last. */
  void
  RunGeneration();

  /** Generations until Finished(), calling `onGeneration` after each (it may
   *  throw to abort). */
  void
  Run(const std::function<void(const GenerationRecord &)> & onGeneration = {});

  bool
  Finished() const
  {
    return m_Generation >= m_Options.generations;
  }
  std::size_t
  Generation() const
  {
    return m_Generation;
  }
  const ElitistArchive &
  Archive() const
  {
    return *m_Archive;
  }
  const std::vector<GenerationRecord> &
  History() const
  {
    return m_History;
  }
  const GomeaOptions &
  Options() const
  {
    return m_Options;
  }
  /** The threads that draw batches ahead (GomeaOptions::drawAheadThreads as
   *  resolved; 0: none). */
  std::size_t
  DrawAheadThreads() const;
  /** Current population and its fitness (after any steering). */
  const std::vector<DualMesh> &
  Population() const
  {
    return m_Population;
  }
  std::vector<Fitness>
  PopulationFitness() const;
  /** The raw (unsteered) fitness of any solution, evaluated in full. */
  Fitness
  EvaluateFully(const DualMesh & solution);

  /** The whole optimiser state in a portable binary form, and back. The
   *  file carries a checksum of its contents and the run's fingerprint
   *  (GomeaOptions::fingerprint and the mesh). Load refuses, with a message
   *  saying why and leaving the optimiser as it was, a file that is damaged
   *  or truncated, of another fingerprint (naming the first key that
   *  differs), of another mesh size or options, or whose contents are out of
   *  range (a generation beyond ea_num_generations, counts that do not match
   *  the mesh or population, ids beyond those given out). */
  void
  Save(std::ostream & out) const;
  void
  Load(std::istream & in);
  /** Save's bytes, in memory (for a CheckpointWriter); the second form
   *  fills `bytes` afresh, keeping its room. */
  std::string
  CheckpointBytes() const;
  void
  CheckpointBytes(std::string & bytes) const;
  /** Atomic: written to a temporary name, synced, then renamed. */
  void
  SaveCheckpoint(const std::string & path) const;
  /** Load from a file; messages name it. */
  void
  LoadCheckpoint(const std::string & path);
  /** The run's fingerprint as checkpoints store it: GomeaOptions::fingerprint
   *  and the mesh. */
  RunFingerprint
  Fingerprint() const;

private:
  struct ClusterModel;
  struct Candidate;
  struct CandidateBatch;

  /** Everything but the header and the checksum (MoRvGomeaCheckpoint.cxx). */
  void
  WritePayload(std::ostream & out) const;
  /** A whole checkpoint file's bytes: checked, then loaded. */
  void
  LoadBytes(const std::string & bytes);

  /** Draws each candidate's variables (its solution, element, cluster and
   *  seed are set) from its cluster's distribution for its element, in
   *  parallel: each candidate has its own random stream. */
  void
  SampleCandidates(CandidateBatch & batch, const std::vector<ClusterModel> & clusters, ThreadPool & pool) const;

  Fitness
  Steered(const Fitness & raw) const;
  Fitness
  CurrentFitness(std::size_t solution) const;
  void
  EvaluatePopulationFully();
  std::vector<std::size_t>
  Select(const std::vector<Fitness> & fitness, RandomGenerator & random) const;
  std::vector<ClusterModel>
  BuildClusters(const std::vector<std::size_t> & selection, const std::vector<Fitness> & fitness,
                RandomGenerator & random);
  /** Each cluster's distributions for `elements`, on `pool`; the first call
   *  of a generation sizes the clusters' models for every element. */
  void
  EstimateDistributions(std::vector<ClusterModel> & clusters, const std::vector<std::uint32_t> & elements,
                        ThreadPool & pool) const;
  /** After a generation: each cluster's and element's multiplier and
   *  stall count from the mean of its accepted samples (sum and count). */
  void
  UpdateDistributionStates(const std::vector<ClusterModel> &                         clusters,
                           const std::vector<std::vector<std::vector<double>>> & acceptedSum,
                           const std::vector<std::vector<std::size_t>> &         acceptedCount);
  /** The backend's view of a drawn batch (PartialCandidate per candidate),
   *  but for what the batch before it may still change: parent keys and
   *  whether a folded candidate is evaluated (ProcessCandidates sets them). */
  void
  BuildPartials(CandidateBatch & batch, ThreadPool & pool) const;
  /** Repairs (when enabled) and evaluates `candidates`, then accepts them in
   *  order; returns how many were accepted. */
  std::size_t
  ProcessCandidates(CandidateBatch & batch, GenerationRecord & record,
                    const EvaluationBackend::Meanwhile & meanwhile = {}, CandidateBatch * next = nullptr);
  /** Sets what acceptance decides (parent keys, whether a folded candidate
   *  is evaluated) for candidates [begin, end) of `batch`'s partials. */
  void
  SetParentState(CandidateBatch & batch, std::size_t begin, std::size_t end) const;
  /** The acceptance step of ProcessCandidates for candidates [begin, end),
   *  which have their values. */
  std::size_t
  AcceptCandidates(CandidateBatch & candidateBatch, const std::vector<PartialCandidate> & batch,
                   const std::vector<CandidateFolds> & folds, std::size_t begin, std::size_t end,
                   GenerationRecord & record);
  /** Whether candidate `c` (fitness `next`) replaces its parent (fitness
   *  `now`): by its rule, or for Pareto candidates by constrained dominance
   *  or the archive's acceptance (brought up to date from `verdict`; no
   *  archive without one). */
  bool
  Accepted(const Candidate & c, const Fitness & next, const Fitness & now, ArchiveVerdict * verdict) const;
  /** The refusal screen of a batch: the archive now and its bounds' filling. */
  RefusalScreen
  ScreenFor(CandidateBatch & candidateBatch) const;
  /** Candidate i's refusal bound from its parent's state (RefusalScreen::fill). */
  void
  FillBound(CandidateBatch & candidateBatch, std::size_t i) const;
  /** How candidate `c` of solution `s` changes its totals, given the sum of
   *  its values (PartialCandidate::sum). */
  TetrahedronValues
  CandidateChange(std::size_t s, const Candidate & c, const TetrahedronValues & sum) const;
  /** Solution s's values summed over element e's dependent tetrahedra, kept
   *  per solution and element: a batch's bounds and changes read each once
   *  (rather than the tetrahedra's values twice). Brought up to date, where
   *  an accepted change or a full evaluation made it stale, by
   *  SetParentState before the candidates of (s, e) need it. */
  TetrahedronValues
  ElementSum(std::size_t s, std::size_t e) const;
  /** The same, summed afresh from the tetrahedra's values. */
  TetrahedronValues
  SumOverElement(std::size_t s, std::size_t e) const;
  /** Marks every element sum of solution s stale. */
  void
  InvalidateElementSums(std::size_t s);
  void
  ForcedImprovement(std::size_t solution, int singleObjective, RandomGenerator & random, GenerationRecord & record);
  bool
  InsertIntoArchive(std::size_t solution, const Fitness & fitness);
  /** A fresh m_KeySalt (the ids start again). */
  void
  RenewKeySalt();
  /** `counters` (accepted, repaired, ..., seconds) completed with the archive's state. */
  GenerationRecord
  Summarise(std::size_t generation, GenerationRecord counters) const;

  const TetrahedralMesh &   m_Base;
  const MeshTopology &      m_Topology;
  const ParallelStructure & m_Parallel;
  const FoldConstraint &    m_Constraint;
  EvaluationBackend &       m_Backend;
  GomeaOptions              m_Options;
  std::shared_ptr<ThreadPool> m_Pool; ///< candidate sampling and acceptance (shared with the backend)
  /** A generation's batches take these in turn, kept from batch to batch:
   *  one evaluated, the next drawn (and packed) meanwhile, and with draw-ahead
   *  threads the one after drawn too. */
  std::array<std::unique_ptr<CandidateBatch>, 3> m_Batches;
  std::unique_ptr<ThreadPool>                    m_DrawPool; ///< the draw-ahead threads, with m_Drawer's
  std::unique_ptr<BackgroundWorker>              m_Drawer;   ///< draws ahead (GomeaOptions::drawAheadThreads)

  std::size_t                             m_Generation{ 0 };
  std::vector<DualMesh>                   m_Population;
  std::vector<std::uint64_t>              m_Ids;
  std::vector<ObjectiveTotals>            m_Totals;
  std::vector<std::vector<TetrahedronValues>> m_TetValues;
  // See ElementSum; per solution, per element. Written by SetParentState
  // (const: each candidate of a batch has its own solution and element).
  mutable std::vector<TetrahedronValues> m_ElementSums;
  mutable std::vector<std::uint8_t>      m_ElementSumStale;
  /** Per tetrahedron, the elements it is a dependent of (m_TetElements from
   *  m_TetElementStart[t] to m_TetElementStart[t + 1]). */
  std::vector<std::uint32_t> m_TetElementStart;
  std::vector<std::uint32_t> m_TetElements;
  std::vector<std::size_t>                m_NoImprovement; ///< per solution, generations without an accepted change
  std::uint64_t                           m_NextId{ 0 };
  /** Mixed with a solution's id into PartialCandidate::parentKey: unique to
   *  this optimiser's population since its last Initialize or checkpoint
   *  load, so that another population sharing the backend never matches. */
  std::uint64_t                           m_KeySalt{ 0 };
  std::unique_ptr<ElitistArchive>         m_Archive;
  ObjectiveVector                         m_Reference{ { 1.0, 1.0, 1.0 } }; ///< hypervolume reference
  std::vector<std::vector<DistributionState>> m_Distributions;   ///< per cluster (k + objectives), per element
  std::vector<ObjectiveVector>            m_ClusterMeans;   ///< previous generation's, for matching
  std::vector<GenerationRecord>           m_History;
  double                                  m_SteeringLimit; ///< guidance bound; infinity when inactive
};
} // namespace morea_core

#endif
