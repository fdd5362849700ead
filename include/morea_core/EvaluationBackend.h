// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the evaluation backend interface (SPEC 6).
// The optimiser hands a backend whole batches: all solutions to evaluate in
// full, or all partial candidates of one parallel group for all solutions of
// a cluster. Candidates of one batch never share a tetrahedron of the same
// solution, so a backend may evaluate them in any order and at once.
#ifndef morea_EvaluationBackend_h
#define morea_EvaluationBackend_h

#include "morea_core/MemoryEstimate.h"
#include "morea_core/MeshRepair.h"
#include "morea_core/ParallelStructure.h"
#include "morea_core/RefusalBound.h"
#include "morea_core/TetrahedronObjectives.h"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace morea_core
{
/** What the fold check found on a candidate's two sides (source, target). */
struct CandidateFolds
{
  std::uint8_t foldedSides{ 0 };   ///< sides folded as sampled
  std::uint8_t repairedSides{ 0 }; ///< of those, fold-free after the repair

  bool
  Folded() const
  {
    return repairedSides < foldedSides;
  }
};

/** A parent solution with the points of one FOS element moved. */
struct PartialCandidate
{
  const DualMesh *   parent{ nullptr };
  const FosElement * element{ nullptr };
  /** New positions, one per element point; a fold repair rewrites them. */
  Vec3 * source{ nullptr };
  Vec3 * target{ nullptr };
  /** Output: one entry per element->dependentTetrahedra, in that order.
   *  From the three-argument EvaluatePartials a backend may write them only
   *  once FetchValues asks (the CUDA backend reads every tetrahedron's
   *  values of a batch back, but unpacks them only for the candidates
   *  acceptance keeps: about 2 % late in a run). */
  TetrahedronValues * values{ nullptr };
  /** Output with `values`: their sum, added in that order from 0
   *  (ObjectiveTotals::Add), which is all that acceptance needs; null: not
   *  wanted. */
  TetrahedronValues * sum{ nullptr };
  /** Output of the fold check (see FoldHandling); null: no check. */
  CandidateFolds * folds{ nullptr };
  /** Seeds the repair's moves (RepairSeed gives each side's). */
  std::uint64_t seed{ 0 };
  /** False: a candidate still folded after its repair gets no values (its
   *  parent is fold-free, so it cannot replace it). */
  bool evaluateFolded{ true };
  /** Names the parent's points: parents with one nonzero key have equal
   *  points, in this call and in later ones, so a backend may keep them
   *  between calls (the CUDA backend keeps them on the device and uploads
   *  only parents with keys it does not hold). 0: no such promise. */
  std::uint64_t parentKey{ 0 };
  /** In and out: lets the backend skip sampling the candidate when its bound
   *  is refused against the screen (EvaluationBackend::SetRefusalScreen);
   *  null: always sampled. */
  RefusalBound * bound{ nullptr };
};

/** Whether EvaluatePartials gives candidate `c` values: not when it is left
 *  folded and needs none (`evaluateFolded` off). */
inline bool
HasValues(const PartialCandidate & c)
{
  return !(c.folds && c.folds->Folded() && !c.evaluateFolded);
}

/** Writes c.sum (where wanted) from c.values as PartialCandidate::sum says. */
inline void
SumCandidateValues(const PartialCandidate & c)
{
  if (c.sum == nullptr)
    return;
  ObjectiveTotals sum;
  for (std::size_t k = 0; k < c.element->dependentTetrahedra.size(); ++k)
    sum.Add(c.values[k]);
  *c.sum = sum.sum;
}

/** How EvaluatePartials treats folds (SPEC 5). Each side of a candidate with
 *  `folds` set is checked over the element's dependent tetrahedra before it is
 *  evaluated; with `repair`, a folded side is repaired as RepairPoints does
 *  (only the element's points move), in place. Done by the backend so that a
 *  GPU checks and repairs the batch where its points already are. */
struct FoldHandling
{
  const FoldConstraint *  constraint{ nullptr }; ///< null: no checks
  const TetrahedralMesh * base{ nullptr };       ///< pins and domain of the repair's moves
  bool                    repair{ false };
  RepairOptions           options;
};

/** Work a backend has done since it was made (for benchmarks and logs). */
struct BackendStatistics
{
  std::uint64_t batches{ 0 };       ///< EvaluateSolutions and EvaluatePartials calls
  std::uint64_t tetrahedra{ 0 };    ///< tetrahedra evaluated (both directions each)
  double        samples{ 0.0 };     ///< sample points drawn, both directions
  double        seconds{ 0.0 };     ///< wall time inside the calls
  double        kernelSeconds{ 0.0 }; ///< device time of the sampling kernels, set-up included (CUDA only)
  double        setUpKernelSeconds{ 0.0 }; ///< of kernelSeconds, the texture path's per-tetrahedron set-up
  double        foldSeconds{ 0.0 };   ///< of the calls' time, fold checks and repair (CUDA: device time they cover)
  // CUDA only, host time of the partial evaluations: packing and uploading a
  // batch, waiting for the device, handing the results back.
  double stagingSeconds{ 0.0 };
  double waitSeconds{ 0.0 };
  double unpackSeconds{ 0.0 };
  /** CUDA only: parents uploaded by EvaluatePartials (those whose key it
   *  did not hold, see PartialCandidate::parentKey). */
  std::uint64_t parentsUploaded{ 0 };
  /** CUDA only: candidates evaluated after their upload and fold checks had
   *  started early (StartNextPartials). */
  std::uint64_t startedCandidates{ 0 };
  /** CUDA only: parts sampled a second time, having more chunks than the
   *  room guessed for them. */
  std::uint64_t partsSampledAgain{ 0 };
  /** Candidates whose refusal bound spared their sampling, the samples they
   *  would have drawn (not in `samples`), and those sampled later after all
   *  (SampleSkipped: their samples are in `samples`). */
  std::uint64_t boundSkipped{ 0 };
  double        boundSkippedSamples{ 0.0 };
  std::uint64_t boundSampledLater{ 0 };
  double        boundSampledLaterSamples{ 0.0 }; ///< their samples (in `samples`)
  std::uint64_t boundSampleLaterCalls{ 0 }; ///< SampleSkipped calls
  double        boundSampleLaterSeconds{ 0.0 }; ///< wall time inside them
  /** CUDA only: where the device time of the EvaluatePartials batches goes,
   *  between events on its stream. A phase in which the stream is empty
   *  counts the host's time: `betweenBatches` and `staging` are the device
   *  waiting for the host. */
  struct DevicePhases
  {
    double betweenBatches{ 0.0 }; ///< a batch's end to the next one's start
    double staging{ 0.0 };        ///< start to the first upload: the host packing the batch
    double uploads{ 0.0 };        ///< fold-check staging, candidates and parents to the device
    double foldChecks{ 0.0 };     ///< checks and repair (the time they cover: parts' checks overlap)
    double preparation{ 0.0 };    ///< corners, screen, sampling set-up, waits between ranges (what the rest leave)
    double chunkCounts{ 0.0 };    ///< 0: the sampling is sized on the device (once the host read chunk counts)
    double sampling{ 0.0 };       ///< the parts' sampling kernels
  } devicePhases;

  /** CUDA only: device time from each EvaluatePartials batch's start to its
   *  last kernel's end (every phase but `betweenBatches`); the rest of the
   *  wall time the device waited for the host between batches. */
  double
  BatchSpanSeconds() const
  {
    const DevicePhases & p = devicePhases;
    return p.staging + p.uploads + p.foldChecks + p.preparation + p.chunkCounts + p.sampling;
  }
};

class EvaluationBackend
{
public:
  virtual ~EvaluationBackend() = default;

  const BackendStatistics &
  Statistics() const
  {
    return m_Statistics;
  }

  /** "cpu", "cuda" or "cuda-texture": the path that runs. */
  virtual std::string
  Name() const = 0;

  /** "" when the path asked for runs; else one sentence naming the path
   *  used instead and why (e.g. the CUDA texture path asked for with more
   *  guidance structures than it reads), for logs and reports. */
  virtual std::string
  PathNote() const
  {
    return {};
  }

  /** Per-tetrahedron values of whole solutions: values[i] gets one entry per
   *  tetrahedron of solutions[i]. */
  virtual void
  EvaluateSolutions(const std::vector<const DualMesh *> & solutions,
                    const std::vector<std::vector<TetrahedronValues> *> & values) = 0;

  /** Told that candidates [begin, end) of an EvaluatePartials call have their
   *  values and fold outcomes. */
  using ReadyCandidates = std::function<void(std::size_t begin, std::size_t end)>;

  /** Work of the caller's that needs neither the batch nor its parents. */
  using Meanwhile = std::function<void()>;

  /** The dependent tetrahedra of every candidate, each with its moved points;
   *  fold checks first where asked for (SetFoldHandling). Every candidate
   *  that gets values (HasValues) gets its `values` and `sum`. */
  void
  EvaluatePartials(const std::vector<PartialCandidate> & candidates)
  {
    EvaluatePartials(candidates, ReadyCandidates{});
  }

  /** As above, calling `ready` (if set) for consecutive ranges that cover all
   *  candidates, in order, before returning. A backend that evaluates in
   *  parts (CUDA) calls it as each part is done, so the caller works on the
   *  first candidates while the device computes the rest. */
  void
  EvaluatePartials(const std::vector<PartialCandidate> & candidates, const ReadyCandidates & ready)
  {
    EvaluatePartials(
      candidates,
      [this, &candidates, &ready](std::size_t begin, std::size_t end) {
        std::vector<std::size_t> which;
        for (std::size_t i = begin; i < end; ++i)
          if (HasValues(candidates[i]))
            which.push_back(i);
        FetchValues(candidates, which);
        if (ready)
          ready(begin, end);
      },
      Meanwhile{});
  }

  /** As above, but a candidate's `values` may wait for FetchValues (its
   *  `sum` does not), and `meanwhile` (if set) is called once, on the
   *  calling thread, before the first `ready`: the CUDA backend calls it
   *  once the device has work queued, so the caller prepares its next batch
   *  while the device computes this one. It must not touch the candidates,
   *  their points or their parents. */
  virtual void
  EvaluatePartials(const std::vector<PartialCandidate> & candidates, const ReadyCandidates & ready,
                   const Meanwhile & meanwhile) = 0;

  /** Lets the backend pack, while it evaluates the current batch, what of
   *  the next EvaluatePartials call depends neither on the parents' points
   *  nor on their keys: elements, moved points, seeds and which candidates
   *  are checked. For `meanwhile`. The call it prepares must pass candidates
   *  with the same parents, elements, point and output arrays and seeds, in
   *  the same order; their keys and `evaluateFolded` may change until then.
   *  A backend finding the call different packs it afresh. Does nothing by
   *  default. */
  virtual void
  PrepareNextPartials(const std::vector<PartialCandidate> & next)
  {
    static_cast<void>(next);
  }

  /** Lets the backend start on the first `head` candidates of the next
   *  EvaluatePartials call (prepared with PrepareNextPartials) before the
   *  current call returns, when the current batch's acceptance can no longer
   *  change them: their parents' points, keys and `evaluateFolded` are
   *  final, and so are the bounds `screen` fills for them. Heeded only from
   *  `ready` for the current call's next-to-last range (the CUDA backend
   *  then checks their folds, builds, screens and samples them while the
   *  caller accepts the last part); ignored otherwise and by
   *  default. A started call screens all its candidates with `screen` (null:
   *  none), not with the screen set when it is made. */
  virtual void
  StartNextPartials(const std::vector<PartialCandidate> & next, std::size_t head, const RefusalScreen * screen)
  {
    static_cast<void>(next);
    static_cast<void>(head);
    static_cast<void>(screen);
  }

  /** Writes `values` of candidates `which` of the current EvaluatePartials
   *  call, from `ready` for a part holding them; those written already
   *  (SampleSkipped) stay as they are. Does nothing by default (values
   *  written with the sums). */
  virtual void
  FetchValues(const std::vector<PartialCandidate> & candidates, const std::vector<std::size_t> & which)
  {
    static_cast<void>(candidates);
    static_cast<void>(which);
  }

  /** Whether StartNextPartials would start a head now (from `ready`): the
   *  caller works out the head only then. False by default. */
  virtual bool
  WantsNextPartials() const
  {
    return false;
  }

  /** Samples candidates `which` of the current EvaluatePartials call that
   *  their bound skipped (RefusalBound::skipped), completing their values
   *  and sums and clearing the flag; for the optimiser's exact check, when a bound
   *  computed before the call no longer refuses one. Only from `ready`,
   *  for candidates already handed over; synchronous. */
  virtual void
  SampleSkipped(const std::vector<PartialCandidate> & candidates, const std::vector<std::size_t> & which) = 0;

  /** Whether EvaluatePartials works beside the calling thread (a device)
   *  rather than on the host's cores: the optimiser then draws its batches
   *  ahead on threads of their own (GomeaOptions::drawAheadThreads). */
  virtual bool
  EvaluatesBesideHost() const
  {
    return false;
  }

  /** Whether skipping candidates by their refusal bound makes runs faster
   *  here (RefusalBoundChoice::Auto): true where sampling is the work that
   *  limits a generation. */
  virtual bool
  GainsFromRefusalBounds() const
  {
    return true;
  }

  /** The archive and steering limit that bound the candidates of later
   *  EvaluatePartials calls (those with PartialCandidate::bound set); set
   *  anew before each call that uses it. Copied by the call. */
  void
  SetRefusalScreen(const RefusalScreen & screen)
  {
    m_RefusalScreen = screen;
    m_HasRefusalScreen = true;
  }
  void
  ClearRefusalScreen()
  {
    m_HasRefusalScreen = false;
  }

  /** What this backend allocates for a run of `shape` beyond what it holds
   *  when made (MemoryEstimate.h): the CUDA backend's device and pinned
   *  buffers for whole evaluations and batches. Nothing by default. */
  virtual MemoryEstimate
  MemoryFor(const RunShape & shape) const
  {
    static_cast<void>(shape);
    return {};
  }
  /** Bytes free on the backend's device now; empty: it has none. */
  virtual std::optional<double>
  FreeDeviceMemory() const
  {
    return std::nullopt;
  }

  /** Fold checks and repair of later EvaluatePartials calls; the constraint
   *  and base mesh must outlive them. */
  virtual void
  SetFoldHandling(const FoldHandling & handling)
  {
    m_FoldHandling = handling;
  }
  const FoldHandling &
  GetFoldHandling() const
  {
    return m_FoldHandling;
  }

protected:
  BackendStatistics m_Statistics;
  FoldHandling      m_FoldHandling;
  RefusalScreen     m_RefusalScreen;
  bool              m_HasRefusalScreen{ false };
};

/** The seed of the repair of side `side` (0 source, 1 target) of a
 *  candidate seeded with `candidateSeed`; every backend draws the same. */
std::uint64_t
RepairSeed(std::uint64_t candidateSeed, int side);

/** The fold check (and repair) of one candidate, as the CPU backend does it:
 *  the reference for other backends. Rewrites the candidate's points where a
 *  side is repaired. */
CandidateFolds
CheckCandidateFolds(const PartialCandidate & candidate, const FoldHandling & handling);

/** The CPU backend over `threads` threads (0: all hardware threads). */
std::unique_ptr<EvaluationBackend>
CreateCpuEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads = 0);

/** How the CUDA backend interpolates the images (Texture: for at most
 *  cuda::MaxTextureStructures guidance structures; with more, Exact). */
enum class CudaInterpolation
{
  Exact,  ///< software trilinear: agrees with the CPU backend to rounding (the default)
  Texture ///< the texture units' filtering (9-bit weights): faster, agrees less closely
};

/** The CUDA backend on device `device` (`threads` host threads pack and
 *  unpack the batches). Throws morea_core::Error when the build has no CUDA, no
 *  such device is present, and names out-of-memory as such. */
std::unique_ptr<EvaluationBackend>
CreateCudaEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads = 0,
                            CudaInterpolation interpolation = CudaInterpolation::Exact, int device = 0);

/** For tests: queues on the CUDA backend's evaluation stream a wait until
 *  `release` is set, so that the work queued after it waits while the host
 *  goes on, as when other processes share the device. `release` must
 *  outlive the wait. Throws morea_core::Error for another backend or
 *  without CUDA. */
void
HoldCudaEvaluationStream(EvaluationBackend & backend, const std::atomic<bool> & release);

enum class BackendChoice
{
  Cpu,
  CudaTexture, ///< "cuda": hardware-filtered interpolation, the fast path; within about 1e-4 of the CPU
  CudaExact,   ///< "cuda-exact": software trilinear interpolation as on the CPU, for verification
  Auto         ///< the texture path when a usable device is present, else the CPU
};

/** "cpu", "cuda" (also "cuda-texture"), "cuda-exact" or "auto"; anything
 *  else is an error naming the choices. */
BackendChoice
ParseBackendChoice(const std::string & name);

/** The name ParseBackendChoice reads back ("cpu", "cuda", "cuda-exact", "auto"). */
std::string
BackendChoiceName(BackendChoice choice);

/** Where a registration's evaluations run. */
struct BackendRequest
{
  BackendChoice choice{ BackendChoice::Auto };
  int           device{ 0 };  ///< CUDA device ordinal
  /** Lowest compute capability (major x 10 + minor) a device must have. */
  int           minimumComputeLevel{ 0 };
  std::size_t   threads{ 0 }; ///< host threads; 0: all
};

/** Why `request` runs where it does, found before any backend is made: ""
 *  when the device asked for by name is usable; for Auto, which platform it
 *  picks and why. Throws morea_core::Error when a CUDA backend asked for by name
 *  cannot be used (no CUDA in the build, no device, device index out of
 *  range, compute capability below the minimum). */
std::string
CheckBackendRequest(const BackendRequest & request, BackendChoice * resolved = nullptr);

/** The one place that picks the platform. Auto: the texture path on the
 *  requested device when it is usable, else the CPU. */
std::unique_ptr<EvaluationBackend>
CreateEvaluationBackend(BackendChoice choice, const TetrahedronEvaluator & evaluator, std::size_t threads = 0,
                        int device = 0);

/** CreateEvaluationBackend for a request; `note` (may be null) gets why it
 *  runs where it does: the platform Auto picked and any path the backend
 *  could not take (EvaluationBackend::PathNote). */
std::unique_ptr<EvaluationBackend>
CreateEvaluationBackend(const BackendRequest & request, const TetrahedronEvaluator & evaluator,
                        std::string * note = nullptr);

/** Whether a run on `backend` skips candidates by their bound. */
inline bool
UsesRefusalBounds(RefusalBoundChoice choice, const EvaluationBackend & backend)
{
  return choice == RefusalBoundChoice::On || (choice == RefusalBoundChoice::Auto && backend.GainsFromRefusalBounds());
}

/** Corners of tetrahedron `t` on one side of a mesh whose points `moved` are
 *  replaced by `replacements` (one per moved point, in the same order). */
Corners
CornersWithReplacedPoints(const Tetrahedron & t, const std::vector<Vec3> & points,
                          const std::vector<std::uint32_t> & moved, const Vec3 * replacements);

/** Corners of tetrahedron `t` in a parent whose element points are replaced. */
void
CandidateCorners(const PartialCandidate & candidate, const Tetrahedron & t, Corners & source, Corners & target);
} // namespace morea_core

#endif
