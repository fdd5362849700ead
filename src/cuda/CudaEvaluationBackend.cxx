// The CUDA evaluation backend: the same calls as the CPU backend
// (CpuEvaluationBackend.cxx), evaluated on the GPU. Images, distance maps,
// the mesh and per-tetrahedron constants are uploaded once. A batch of
// partial candidates (all candidates of a parallel group of a cluster) goes
// up as its parents' points, its elements and the moved points; the device
// builds every dependent tetrahedron's corners, evaluates them part by part
// and the values come back as each part is done. The next batch's candidates
// whose parents are final may start while the current one is handed over.
#include "morea/EvaluationBackend.h"

#include "DeviceMemory.h"
#include "FoldRepairKernels.h"
#include "RefusalScreenKernels.h"
#include "TetrahedronKernels.h"

#include "morea/ComputeDevices.h"
#include "morea/NearContourBlocks.h"
#include "morea/ParentSlots.h"
#include "morea/Error.h"
#include "morea/TetrahedronSampling.h"
#include "morea/ThreadPool.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <type_traits>
#include <unordered_map>
#include <vector>

namespace morea
{
namespace
{
using cuda::Check;

// A batch of partial candidates runs in parts of at least MinItemsPerPart
// tetrahedra, at most MaxParts: the caller accepts one part while the device
// samples the next. Smaller parts keep fewer solutions' copies of a
// tetrahedron together in the sorted schedule: on an H100, 4 parts of the
// paper configuration's batches made the kernels 4 % slower and each
// generation 10 % faster (2 parts: 1.5 % and 8 %).
// The last part's acceptance has nothing to overlap with, so that part is
// smaller: LastPartShare of the others'.
constexpr std::size_t MaxParts = 4;
constexpr std::size_t MinItemsPerPart = 100000;
constexpr double      LastPartShare = 0.5;
// Room for this many times the most chunks per item seen so far.
constexpr double ChunkRoomMargin = 1.25;

/** The texture path's textures of one image. */
struct VolumeTextures
{
  std::unique_ptr<cuda::Texture3D>                                     intensity;
  std::array<std::unique_ptr<cuda::Texture3D>, cuda::MaxTextureStructures> distances;
  cuda::DeviceArray<std::uint8_t>  nearBlocks; ///< see cuda::PackedVolumeView::nearBlocks
};

static_assert(NearContourBlocks::BlockSize == cuda::NearBlockSize, "the sampling kernel's blocks are the core's");
static_assert(sizeof(TetrahedronValues) == cuda::CandidateSumValues * sizeof(double) &&
                std::is_trivially_copyable_v<TetrahedronValues>,
              "a candidate's sum is copied as the device lays it out");

/** A batch of partial candidates packed on the host for the device, but for
 *  what depends on the parents' points and keys. Packed by
 *  PrepareNextPartials while the device works on the batch before (or by
 *  EvaluatePartials itself); two alternate, so that packing the next batch
 *  leaves alone the arrays of the one in flight (its first items, moved
 *  points and their offsets are read until it ends). */
struct HostCandidates
{
  /** What each candidate was packed from: a call with other candidates is packed afresh. */
  struct Signature
  {
    const DualMesh *       parent;
    const FosElement *     element;
    const Vec3 *           source;
    const Vec3 *           target;
    const CandidateFolds * folds;
    std::uint64_t          seed;

    bool
    operator==(const Signature & o) const
    {
      return parent == o.parent && element == o.element && source == o.source && target == o.target &&
             folds == o.folds && seed == o.seed;
    }
  };
  static Signature
  SignatureOf(const PartialCandidate & c)
  {
    return { c.parent, c.element, c.source, c.target, c.folds, c.seed };
  }

  /** On the pool, in blocks: a batch's tens of thousands of candidates lie
   *  far apart in memory, and comparing them on the main thread alone took
   *  about 4 ms of a late paper-scale generation on an H100 host (two or
   *  three calls per batch). */
  bool
  PackedFor(const std::vector<PartialCandidate> & candidates, ThreadPool & pool) const
  {
    if (!prepared || signatures.size() != candidates.size())
      return false;
    constexpr std::size_t block = 2048;
    std::atomic<bool>     same{ true };
    pool.ParallelFor((candidates.size() + block - 1) / block, [&](std::size_t b) {
      const std::size_t end = std::min(candidates.size(), (b + 1) * block);
      for (std::size_t i = b * block; i < end && same.load(std::memory_order_relaxed); ++i)
        if (!(signatures[i] == SignatureOf(candidates[i])))
          same.store(false, std::memory_order_relaxed);
    });
    return same.load();
  }

  bool                           prepared{ false }; ///< by PrepareNextPartials, not yet used
  std::vector<Signature>         signatures;
  std::vector<const DualMesh *>  parents;        ///< distinct, in order of first use
  std::vector<std::size_t>       parentFirstUse; ///< per parent: its first candidate
  std::vector<std::uint32_t>     pointOffsets, points, tetrahedronOffsets, dependent; ///< per element slot
  cuda::PinnedArray<std::uint32_t> candidateElement, candidateParent, candidateMoved; ///< slot, parent, first point
  cuda::PinnedArray<std::uint64_t> firstItem;                                          ///< per candidate, and the end
  cuda::PinnedArray<double>        moved; ///< 6 per moved point; the repaired ones come back here
  std::size_t                      movedPoints{ 0 };
  bool                             anyChecked{ false };     ///< some candidate asks for a fold check
  std::size_t                      largestChecked{ 0 };     ///< points of the largest checked element
  cuda::PinnedArray<std::uint8_t>  foldCheck;               ///< per candidate
  cuda::PinnedArray<std::uint64_t> sideSeeds;               ///< per candidate side
};

/** Device and pinned buffers of one EvaluatePartials batch, and how it runs.
 *  Two alternate, as HostCandidates do: the next batch's head fills one
 *  while the current batch's values, corners and screen outcome are still
 *  read from the other. A batch goes up in one or two candidate ranges (a
 *  head started early, then the rest), each range in parts. Needs a device
 *  (its events). */
struct BatchFlight
{
  cuda::DeviceArray<double>        corners, itemValues, directionValues;
  cuda::DeviceArray<std::uint32_t> tetrahedra;
  cuda::DeviceArray<std::uint8_t>  itemSkip; ///< per item: ItemSkip
  cuda::PinnedArray<double>        hostItemValues, hostDirectionValues;
  /** Per candidate: its items' values summed (LaunchSumCandidateValues),
   *  all the host unpacks of most candidates (see FetchValues). */
  cuda::DeviceArray<double>        candidateSums;
  cuda::PinnedArray<double>        hostCandidateSums;
  std::vector<std::uint8_t>        valuesWritten; ///< per candidate: its values are on the host (SampleSkipped)
  cuda::DeviceArray<std::uint8_t>  outcome; ///< per candidate side: the fold checks' outcome
  cuda::PinnedArray<std::uint8_t>  hostOutcome;
  cuda::PinnedArray<std::uint32_t> hostChunks; ///< per part: the texture set-up's number of chunks
  std::vector<std::unique_ptr<cuda::DeviceArray<unsigned char>>> workspaces, chunkWorkspaces; ///< per part

  /** The refusal screen of the whole batch, as it was when the batch began. */
  RefusalScreen                                screen;
  bool                                         hasScreen{ false };
  bool                                         screened{ false }; ///< hostRefusal holds every candidate's outcome
  bool                                         archiveUploaded{ false };
  cuda::PinnedArray<cuda::CandidateBoundInput> hostBounds;
  cuda::DeviceArray<cuda::CandidateBoundInput> bounds;
  cuda::PinnedArray<double>                    hostArchive;
  cuda::DeviceArray<double>                    archive;
  cuda::DeviceArray<std::uint32_t>             refusal; ///< see cuda::LaunchScreenCandidates
  cuda::PinnedArray<std::uint32_t>             hostRefusal;

  std::size_t items{ 0 };
  bool        checks{ false }; ///< the fold kernel runs
  /** The time the parts' fold checks (side by side) covered, and the end
   *  of the last one read so far, in seconds after `start`. */
  double      foldSeconds{ 0.0 }, foldCovered{ 0.0 };
  bool        skipItems{ false }; ///< itemSkip is set (not for whole solutions)
  // Ranges of candidates and parts of items; a range's parts follow it.
  static constexpr std::size_t MaxRanges = 2;
  std::size_t                  ranges{ 0 };
  std::size_t                  rangeFirstPart[MaxRanges]{};
  std::vector<std::size_t>     candidateBounds{ 0 }, itemBounds{ 0 }; ///< per part, and the end
  std::size_t                  sampledParts{ 0 };                      ///< parts whose sampling is queued
  std::vector<std::size_t>     chunkCapacity; ///< per part: room for chunks (texture path)

  cuda::Event start, staged, end;
  cuda::Event rangeStart[MaxRanges], rangeUploaded[MaxRanges];
  /** Per part, PartStep apart: its fold checks, its sampling's set-up and its sampling, each start and end;
   *  the end of its values. */
  std::vector<std::unique_ptr<cuda::Event>> partEvents;
  std::vector<std::unique_ptr<cuda::Event>> copiedEvents; ///< per part: its values on the host
  /** Per part: its candidates' sums on the host (and its fold outcome,
   *  copied before them), ahead of its values. */
  std::vector<std::unique_ptr<cuda::Event>> sumsCopiedEvents;
  std::size_t                               partsWithValues{ 0 }; ///< parts whose copiedEvents were waited for

  std::size_t
  Parts() const
  {
    return candidateBounds.size() - 1;
  }
  enum PartStep : std::size_t
  {
    FoldStart,
    FoldEnd,
    SetUpStart,
    SetUpEnd,
    SamplingStart,
    SamplingEnd,
    ValuesEnd, ///< the candidates' sums too: what the copy back waits for
    PartSteps
  };
  cudaEvent_t
  PartEvent(std::size_t p, PartStep step) const
  {
    return partEvents[PartSteps * p + step]->Get();
  }
};

/** Sets a flag for a scope, cleared however the scope is left. */
class AcceptHeadScope
{
public:
  AcceptHeadScope(bool & flag, bool value)
    : m_Flag(flag)
  {
    m_Flag = value;
  }
  ~AcceptHeadScope() { m_Flag = false; }
  AcceptHeadScope(const AcceptHeadScope &) = delete;
  AcceptHeadScope &
  operator=(const AcceptHeadScope &) = delete;

private:
  bool & m_Flag;
};

class CudaEvaluationBackend final : public EvaluationBackend
{
public:
  CudaEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads, CudaInterpolation interpolation)
    : m_Evaluator(evaluator)
    , m_Pool(ThreadPool::Shared(threads))
  {
    const std::string unavailable = CudaUnavailableReason();
    if (!unavailable.empty())
      throw Error("CUDA backend: " + unavailable);
    Check(cudaSetDevice(0), "selecting device 0");
    m_Stream = std::make_unique<cuda::Stream>();
    m_CopyStream = std::make_unique<cuda::Stream>();
    for (auto & stream : m_FoldStreams)
      stream = std::make_unique<cuda::Stream>();
    m_MovedCopied = std::make_unique<cuda::Event>();
    m_FallbackStream = std::make_unique<cuda::Stream>(cuda::Stream::HighPriority{});
    m_FallbackStart = std::make_unique<cuda::Event>();
    m_FallbackEnd = std::make_unique<cuda::Event>();
    for (auto & flight : m_Flights)
    {
      flight = std::make_unique<BatchFlight>();
      // Once: parts' counts arrive asynchronously, so it must never move.
      flight->hostChunks.Reserve(BatchFlight::MaxRanges * MaxParts);
    }
    cuda::UploadSobolDirections(SobolDirectionNumbers());

    const ObjectiveData & data = evaluator.Data();
    m_Constants.structures = static_cast<int>(data.NumberOfGuidanceStructures());
    m_Constants.guidanceWeights = Upload(data.guidanceWeights, m_GuidanceWeights);
    for (std::size_t g = 0; g < std::min<std::size_t>(3, data.guidanceWeights.size()); ++g)
      m_Constants.textureGuidanceWeights[g] = static_cast<float>(data.guidanceWeights[g]);
    m_Constants.guidanceRadius = data.guidanceRadius;
    m_Constants.samplingRate = data.samplingRate;
    m_Constants.voxelVolume = data.voxelVolume;
    m_Constants.elasticity = evaluator.Elasticity().empty() ? nullptr : Upload(evaluator.Elasticity(), m_Elasticity);
    m_Constants.referenceVolumes = Upload(evaluator.Constraint().ReferenceVolumes(), m_ReferenceVolumes);
    m_Constants.tetrahedra = static_cast<std::uint32_t>(evaluator.Constraint().ReferenceVolumes().size());
    m_Constants.volumeFraction = evaluator.Constraint().VolumeFraction();
    if (data.moving.channels <= 4)
    {
      // The fast kernels read 4 channels per voxel at once.
      m_Constants.packed = true;
      m_Constants.interpolation =
        interpolation == CudaInterpolation::Texture ? cuda::Interpolation::Texture : cuda::Interpolation::Exact;
      m_Constants.packedMoving = UploadPacked(data.moving, m_PackedMoving, m_MovingTextures, interpolation);
      m_Constants.packedFixed = UploadPacked(data.fixed, m_PackedFixed, m_FixedTextures, interpolation);
    }
    else
    {
      m_Constants.moving = Upload(data.moving, m_Moving);
      m_Constants.fixed = Upload(data.fixed, m_Fixed);
    }
    std::vector<std::uint32_t> mesh;
    for (const Tetrahedron & t : evaluator.Topology().Tetrahedra())
      mesh.insert(mesh.end(), t.begin(), t.end());
    m_Batch.tetrahedra = Upload(mesh, m_Mesh);
    m_Batch.points = static_cast<std::uint32_t>(evaluator.Topology().NumberOfPoints());
    Check(cudaStreamSynchronize(m_Stream->Get()), "uploading the images");
  }

  std::string
  Name() const override
  {
    return m_Constants.packed && m_Constants.interpolation == cuda::Interpolation::Texture ? "cuda-texture" : "cuda";
  }

  void
  EvaluateSolutions(const std::vector<const DualMesh *> & solutions,
                    const std::vector<std::vector<TetrahedronValues> *> & values) override
  {
    if (solutions.size() != values.size())
      throw Error("evaluation backend: as many value arrays as solutions are needed");
    const auto &      tets = m_Evaluator.Topology().Tetrahedra();
    const std::size_t n = tets.size();
    const std::size_t points = m_Evaluator.Topology().NumberOfPoints();
    for (const DualMesh * s : solutions)
      if (s->source.size() != points || s->target.size() != points)
        throw Error("evaluation backend: a solution does not match the mesh");
    const auto start = std::chrono::steady_clock::now();
    // The flight of the last batch, which is done: the other one may hold
    // a started head.
    BatchFlight &     f = *m_Flights[m_CurrentHost];
    const std::size_t items = solutions.size() * n;
    ReserveItems(f, items);
    // The solutions' points go up (6 doubles per point) and the device
    // builds every tetrahedron's 24 corners: for the paper's population
    // 20 MB instead of 500 MB packed and copied.
    const std::size_t perSolution = 6 * points;
    m_HostSolutionPoints.Reserve(std::max<std::size_t>(1, solutions.size() * perSolution));
    m_SolutionPoints.Reserve(std::max<std::size_t>(1, solutions.size() * perSolution));
    m_Pool->ParallelFor(solutions.size(), [&](std::size_t s) {
      double * out = m_HostSolutionPoints.Data() + s * perSolution;
      for (const auto * side : { &solutions[s]->source, &solutions[s]->target })
        for (const Vec3 & p : *side)
        {
          std::copy(p.begin(), p.end(), out);
          out += 3;
        }
    });
    if (items > 0)
    {
      cudaStream_t stream = m_Stream->Get();
      Check(cudaMemcpyAsync(m_SolutionPoints.Data(), m_HostSolutionPoints.Data(),
                            solutions.size() * perSolution * sizeof(double), cudaMemcpyHostToDevice, stream),
            "copying solutions to the device");
      cuda::LaunchGatherSolutionCorners(m_SolutionPoints.Data(), solutions.size(), m_Batch.tetrahedra, n, points,
                                        f.corners.Data(), f.tetrahedra.Data(), stream);
    }
    RunWhole(f, items);
    UnpackSolutions(f, n, values);
    m_Statistics.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  void
  SetFoldHandling(const FoldHandling & handling) override
  {
    if (handling.repair && !handling.base)
      throw Error("evaluation backend: the fold repair needs the base mesh");
    EvaluationBackend::SetFoldHandling(handling);
    if (!handling.constraint)
      return;
    const FoldConstraint & constraint = *handling.constraint;
    const MeshTopology &   topology = constraint.Topology();
    if (topology.NumberOfPoints() != m_Batch.points)
      throw Error("evaluation backend: the fold constraint's mesh is not the evaluator's");
    std::vector<std::uint32_t> offsets{ 0 }, pointTetrahedra;
    for (std::size_t p = 0; p < topology.NumberOfPoints(); ++p)
    {
      pointTetrahedra.insert(pointTetrahedra.end(), topology.TetrahedraOfPointBegin(p), topology.TetrahedraOfPointEnd(p));
      offsets.push_back(static_cast<std::uint32_t>(pointTetrahedra.size()));
    }
    std::vector<std::int8_t> pins(3 * topology.NumberOfPoints(), 0);
    if (handling.base)
    {
      if (handling.base->pins.size() != topology.NumberOfPoints())
        throw Error("evaluation backend: the base mesh does not match the fold constraint's");
      for (std::size_t p = 0; p < handling.base->pins.size(); ++p)
        std::copy(handling.base->pins[p].begin(), handling.base->pins[p].end(), pins.begin() + 3 * p);
      for (int a = 0; a < 3; ++a)
      {
        m_Folds.lower[a] = handling.base->domain.lower[a];
        m_Folds.upper[a] = handling.base->domain.upper[a];
      }
    }
    m_Folds.referenceVolumes = Upload(constraint.ReferenceVolumes(), m_FoldReferenceVolumes);
    m_Folds.volumeFraction = constraint.VolumeFraction();
    m_Folds.pointTetrahedronOffsets = Upload(offsets, m_PointTetrahedronOffsets);
    m_Folds.pointTetrahedra = Upload(pointTetrahedra, m_PointTetrahedra);
    m_Folds.pins = Upload(pins, m_Pins);
    m_Folds.repair = handling.repair;
    m_Folds.samplesPerPoint = static_cast<std::uint32_t>(handling.options.samplesPerPoint);
    m_Folds.maxRounds = static_cast<std::uint32_t>(handling.options.maxRounds);
    Check(cudaStreamSynchronize(m_Stream->Get()), "uploading the fold constraint");
  }

  using EvaluationBackend::EvaluatePartials;
  void
  EvaluatePartials(const std::vector<PartialCandidate> & candidates, const ReadyCandidates & ready,
                   const Meanwhile & meanwhile) override
  {
    const auto        start = std::chrono::steady_clock::now();
    const int         slot = 1 - m_CurrentHost;
    HostCandidates &  host = m_HostCandidates[slot];
    BatchFlight &     f = *m_Flights[slot];
    const std::size_t n = candidates.size();
    // Its first candidates may be on the device already (StartNextPartials).
    const bool started = m_Head.open && host.PackedFor(candidates, *m_Pool);
    if (m_Head.open && !started) // its queued work reads what is packed afresh now
      Synchronize("abandoning a started batch");
    m_Head.open = false;
    std::size_t head = 0;
    if (started)
    {
      head = m_Head.count;
      CheckStartedHead(candidates, host, f, head);
      m_Statistics.startedCandidates += head;
    }
    else
    {
      if (!host.PackedFor(candidates, *m_Pool))
        PackCandidates(candidates, host);
      BeginFlight(candidates, host, f, m_HasRefusalScreen ? &m_RefusalScreen : nullptr);
    }
    host.prepared = false;
    m_CurrentHost = slot;
    if (head < n || n == 0)
      QueueRange(candidates, host, f, head, n, true);
    QueueSampling(f);
    m_Statistics.stagingSeconds += SecondsSince(start);
    if (meanwhile)
      meanwhile();
    Deliver(candidates, host, f, ready);
    m_Statistics.seconds += SecondsSince(start);
  }

  void
  PrepareNextPartials(const std::vector<PartialCandidate> & next) override
  {
    const auto start = std::chrono::steady_clock::now();
    HostCandidates & host = m_HostCandidates[1 - m_CurrentHost];
    PackCandidates(next, host);
    host.prepared = true;
    m_Statistics.stagingSeconds += SecondsSince(start);
  }

  /** Starts the first `head` candidates of the prepared next batch, behind
   *  the current batch's last part: their parents go up, their folds are
   *  checked, their corners built and screened and they are sampled, while
   *  the caller accepts that part (only while the next-to-last part is
   *  handed over). */
  bool
  WantsNextPartials() const override
  {
    return m_AcceptHead && !m_Head.open;
  }

  void
  StartNextPartials(const std::vector<PartialCandidate> & next, std::size_t head,
                    const RefusalScreen * screen) override
  {
    if (!WantsNextPartials() || head == 0 || head > next.size())
      return;
    const int        slot = 1 - m_CurrentHost;
    HostCandidates & h = m_HostCandidates[slot];
    if (!h.PackedFor(next, *m_Pool) || h.firstItem[next.size()] == 0 || h.largestChecked > cuda::MaxRepairElementPoints)
      return;
    const auto    start = std::chrono::steady_clock::now();
    BatchFlight & f = *m_Flights[slot];
    BeginFlight(next, h, f, screen);
    QueueRange(next, h, f, 0, head, head == next.size());
    QueueSampling(f);
    m_Head.open = true;
    m_Head.count = head;
    m_Statistics.stagingSeconds += SecondsSince(start);
  }

  bool
  EvaluatesBesideHost() const override
  {
    return true;
  }

  /** Yes, since acceptance got cheaper (archive verdicts that last, values
   *  applied in parallel): on an H100, at the paper's scale, 500 generations
   *  took 71.4 s with the bound and 79.9 s without it in one lease, 67.7 s
   *  and 83.2 s in another, with the same front. Before, the host's extra
   *  acceptance work ate the kernels' gain (96.9 s against 93.2 s). */
  bool
  GainsFromRefusalBounds() const override
  {
    return true;
  }

  /** The batch's values were read back with its sums; here they are
   *  unpacked for the few candidates the caller keeps. */
  void
  FetchValues(const std::vector<PartialCandidate> & candidates, const std::vector<std::size_t> & which) override
  {
    const auto             start = std::chrono::steady_clock::now();
    const HostCandidates & h = m_HostCandidates[m_CurrentHost];
    BatchFlight &          f = *m_Flights[m_CurrentHost];
    for (std::size_t i : which)
      if (i >= candidates.size() || i >= f.valuesWritten.size() || Skipped(candidates[i]))
        throw Error("evaluation backend: values asked for a candidate without them");
    WaitForCandidateValues(f, which);
    m_Pool->ParallelFor(which.size(), [&](std::size_t w) {
      const std::size_t i = which[w];
      if (!f.valuesWritten[i])
        UnpackValues(f, h.firstItem.Data(), i, candidates[i]);
    });
    m_Statistics.unpackSeconds += SecondsSince(start);
  }

  void
  SampleSkipped(const std::vector<PartialCandidate> & candidates, const std::vector<std::size_t> & which) override
  {
    const auto                 start = std::chrono::steady_clock::now();
    const HostCandidates &     h = m_HostCandidates[m_CurrentHost];
    BatchFlight &              f = *m_Flights[m_CurrentHost];
    std::size_t                count = 0;
    for (std::size_t i : which)
    {
      if (i >= candidates.size() || !candidates[i].bound || !candidates[i].bound->skipped)
        throw Error("evaluation backend: only candidates the bound skipped can be sampled later");
      count += h.firstItem[i + 1] - h.firstItem[i];
    }
    // Their sample counts and the values other than intensity and guidance.
    WaitForCandidateValues(f, which);
    if (count == 0) // no tetrahedra: nothing to sample
    {
      for (std::size_t i : which)
        candidates[i].bound->skipped = false;
      return;
    }
    // The items' corners are still on the device, from the batch's gather.
    // They are sampled on a stream of their own, whose blocks go before the
    // later parts' sampling; the same arithmetic gives the same sums.
    cudaStream_t stream = m_FallbackStream->Get();
    m_HostFallbackDirectionValues.Reserve(count * 2 * cuda::DirectionValues);
    if (UsesTexturePath())
    {
      // Chunk by chunk, each set up in its warp: one kernel, no sort or scan.
      // A direction's sample count is in the batch's values already.
      const std::size_t chunkSamples = m_Constants.chunkSamples;
      std::vector<std::uint32_t> list;
      for (std::size_t i : which)
        for (std::uint64_t item = h.firstItem[i]; item < h.firstItem[i + 1]; ++item)
          for (std::uint32_t direction = 0; direction < 2; ++direction)
          {
            const double      n = f.hostDirectionValues[(2 * item + direction) * cuda::DirectionValues + 2];
            const std::size_t chunks = (static_cast<std::size_t>(n) + chunkSamples - 1) / chunkSamples;
            for (std::size_t local = 0; local < chunks; ++local)
              list.insert(list.end(), { static_cast<std::uint32_t>(item), direction, static_cast<std::uint32_t>(local), 0u });
          }
      const std::size_t entries = list.size() / 4;
      m_HostFallbackList.Reserve(std::max<std::size_t>(1, list.size()));
      std::copy(list.begin(), list.end(), m_HostFallbackList.Data());
      m_FallbackList.Reserve(std::max<std::size_t>(1, list.size()));
      m_FallbackChunkSums.Reserve(std::max<std::size_t>(1, 2 * entries));
      m_HostFallbackChunkSums.Reserve(std::max<std::size_t>(1, 2 * entries));
      Check(cudaMemcpyAsync(m_FallbackList.Data(), m_HostFallbackList.Data(), list.size() * sizeof(std::uint32_t),
                            cudaMemcpyHostToDevice, stream),
            "copying skipped candidates to the device");
      Check(cudaEventRecord(m_FallbackStart->Get(), stream), "recording an event");
      cuda::LaunchSampleListedChunks(m_Constants, f.corners.Data(), m_FallbackList.Data(), entries,
                                     m_FallbackChunkSums.Data(), stream);
      Check(cudaEventRecord(m_FallbackEnd->Get(), stream), "recording an event");
      Check(cudaMemcpyAsync(m_HostFallbackChunkSums.Data(), m_FallbackChunkSums.Data(), 2 * entries * sizeof(double),
                            cudaMemcpyDeviceToHost, stream),
            "copying values from the device");
      Check(cudaStreamSynchronize(stream), "sampling skipped candidates");
      // Each direction's chunks in order, as SumChunks adds them.
      double * out = m_HostFallbackDirectionValues.Data();
      for (std::size_t e = 0; e < entries; ++e)
      {
        if (e == 0 || list[4 * e] != list[4 * (e - 1)] || list[4 * e + 1] != list[4 * (e - 1) + 1])
        {
          if (e > 0)
            out += cuda::DirectionValues;
          out[0] = out[1] = 0.0;
        }
        out[0] += m_HostFallbackChunkSums[2 * e];
        out[1] += m_HostFallbackChunkSums[2 * e + 1];
      }
    }
    else
    {
      m_HostFallbackItems.Reserve(count);
      std::size_t at = 0;
      for (std::size_t i : which)
        for (std::uint64_t item = h.firstItem[i]; item < h.firstItem[i + 1]; ++item)
          m_HostFallbackItems[at++] = item;
      m_FallbackItems.Reserve(count);
      m_FallbackCorners.Reserve(count * cuda::ItemCorners);
      m_FallbackTetrahedra.Reserve(count);
      m_FallbackItemValues.Reserve(count * cuda::ItemValues);
      m_FallbackDirectionValues.Reserve(count * 2 * cuda::DirectionValues);
      Check(cudaMemcpyAsync(m_FallbackItems.Data(), m_HostFallbackItems.Data(), count * sizeof(std::uint64_t),
                            cudaMemcpyHostToDevice, stream),
            "copying skipped candidates to the device");
      cuda::LaunchGatherItems(f.corners.Data(), f.tetrahedra.Data(), m_FallbackItems.Data(), count,
                              m_FallbackCorners.Data(), m_FallbackTetrahedra.Data(), stream);
      Check(cudaEventRecord(m_FallbackStart->Get(), stream), "recording an event");
      cuda::LaunchEvaluateTetrahedra(m_Constants, m_FallbackCorners.Data(), m_FallbackTetrahedra.Data(), nullptr,
                                     count, m_FallbackItemValues.Data(), m_FallbackDirectionValues.Data(), stream);
      Check(cudaEventRecord(m_FallbackEnd->Get(), stream), "recording an event");
      Check(cudaMemcpyAsync(m_HostFallbackDirectionValues.Data(), m_FallbackDirectionValues.Data(),
                            count * 2 * cuda::DirectionValues * sizeof(double), cudaMemcpyDeviceToHost, stream),
            "copying values from the device");
      Check(cudaStreamSynchronize(stream), "sampling skipped candidates");
    }
    // Their samples count in `samples`, so their kernel's time counts too.
    m_Statistics.kernelSeconds += ElapsedSeconds(*m_FallbackStart, *m_FallbackEnd);
    // Intensity and guidance as Unpack() adds them; the rest is the bound's
    // (the batch's values of the candidate); then the sum of them all.
    std::size_t at = 0;
    for (std::size_t i : which)
    {
      const PartialCandidate & c = candidates[i];
      UnpackValues(f, h.firstItem.Data(), i, c);
      f.valuesWritten[i] = 1;
      double                   samples = 0.0;
      for (std::size_t k = 0; k < c.element->dependentTetrahedra.size(); ++k, ++at)
      {
        const double * d = m_HostFallbackDirectionValues.Data() + at * 2 * cuda::DirectionValues;
        c.values[k].intensity = d[0] + d[3];
        c.values[k].guidance = d[1] + d[4];
        samples += c.values[k].samples;
      }
      SumCandidateValues(c);
      c.bound->skipped = false;
      ++m_Statistics.boundSampledLater;
      m_Statistics.samples += samples;
      m_Statistics.boundSkippedSamples -= samples;
    }
    m_Statistics.seconds += SecondsSince(start);
    m_Statistics.boundSampleLaterSeconds += SecondsSince(start);
    ++m_Statistics.boundSampleLaterCalls;
  }

private:
  /** Queues the refusal screen of candidates [range.firstCandidate,
   *  range.candidates) of flight `f`, whose corners are queued, when the
   *  batch has a screen; its outcome reaches f.hostRefusal before the
   *  range's first part's values. */
  void
  ScreenRange(const std::vector<PartialCandidate> & candidates, BatchFlight & f, const cuda::CandidateBatch & range)
  {
    if (!f.hasScreen)
      return;
    const std::size_t begin = range.firstCandidate, end = range.candidates;
    // The bounds are filled here, while the device checks folds.
    std::atomic<bool> any{ false };
    m_Pool->ParallelFor(end - begin, [&](std::size_t k) {
      const std::size_t         i = begin + k;
      const PartialCandidate &  c = candidates[i];
      cuda::CandidateBoundInput in{};
      if (c.bound && f.screen.fill)
        f.screen.fill(i);
      if (c.bound && c.bound->screened)
      {
        const TetrahedronValues & r = c.bound->rest;
        const double              rest[6] = { r.magnitude, r.intensity, r.guidance, r.samples, r.foldValue, r.folded };
        std::copy(rest, rest + 6, in.rest);
        std::copy(c.bound->parent.objectives.begin(), c.bound->parent.objectives.end(), in.parent);
        in.parentConstraint = c.bound->parent.constraint;
        in.parentFeasible = c.bound->parent.feasible ? 1 : 0;
        in.screened = 1;
        // Read first: 16 threads storing to one cache line for every
        // candidate serialised on it (14 ms of a paper-scale generation).
        if (!any.load(std::memory_order_relaxed))
          any.store(true, std::memory_order_relaxed);
      }
      f.hostBounds[i] = in;
    });
    if (!any.load())
    {
      std::fill(f.hostRefusal.Data() + begin, f.hostRefusal.Data() + end, 0u);
      return;
    }
    cudaStream_t stream = m_Stream->Get();
    const std::vector<ObjectiveVector> & archive = f.screen.archive;
    if (!f.archiveUploaded)
    {
      f.hostArchive.Reserve(std::max<std::size_t>(1, 3 * archive.size()));
      for (std::size_t e = 0; e < archive.size(); ++e)
        std::copy(archive[e].begin(), archive[e].end(), f.hostArchive.Data() + 3 * e);
      UploadAsync(f.hostArchive.Data(), 3 * archive.size(), f.archive);
      f.archiveUploaded = true;
    }
    Check(cudaMemcpyAsync(f.bounds.Data() + begin, f.hostBounds.Data() + begin,
                          (end - begin) * sizeof(cuda::CandidateBoundInput), cudaMemcpyHostToDevice, stream),
          "copying bounds to the device");
    cuda::RefusalScreenView view;
    view.bounds = f.bounds.Data();
    view.archive = f.archive.Data();
    view.archiveSize = static_cast<std::uint32_t>(archive.size());
    view.tetrahedra = static_cast<double>(f.screen.tetrahedra);
    view.guidanceLimit = f.screen.guidanceLimit;
    view.foldOffset = FoldConstraintOffset;
    cuda::LaunchScreenCandidates(m_Constants, range, f.corners.Data(), f.tetrahedra.Data(), view, f.itemSkip.Data(),
                                 f.refusal.Data(), stream);
    Check(cudaMemcpyAsync(f.hostRefusal.Data() + begin, f.refusal.Data() + begin, (end - begin) * sizeof(std::uint32_t),
                          cudaMemcpyDeviceToHost, stream),
          "copying the refusal screen from the device");
    f.screened = true;
  }

  /** Left folded by the checks and needing no values: not sampled. */
  static bool
  Skipped(const PartialCandidate & c)
  {
    return !HasValues(c);
  }

  template <typename T>
  const T *
  Upload(const std::vector<T> & host, cuda::DeviceArray<T> & device)
  {
    device.Reserve(std::max<std::size_t>(1, host.size()));
    if (!host.empty())
      Check(cudaMemcpyAsync(device.Data(), host.data(), host.size() * sizeof(T), cudaMemcpyHostToDevice,
                            m_Stream->Get()),
            "uploading constants");
    return device.Data();
  }

  cuda::VolumeView
  Upload(const ChannelVolume & volume, cuda::DeviceArray<float> & device)
  {
    cuda::VolumeView view;
    view.data = Upload(volume.data, device);
    for (int a = 0; a < 3; ++a)
    {
      view.size[a] = static_cast<int>(volume.size[a]);
      view.origin[a] = volume.origin[a];
      view.spacing[a] = volume.spacing[a];
      view.inverseSpacing[a] = 1.0 / volume.spacing[a];
    }
    view.channels = static_cast<int>(volume.channels);
    return view;
  }

  cuda::PackedVolumeView
  UploadPacked(const ChannelVolume & volume, cuda::DeviceArray<float> & device, VolumeTextures & textures,
               CudaInterpolation interpolation)
  {
    const std::size_t      voxels = volume.size[0] * volume.size[1] * volume.size[2];
    cuda::PackedVolumeView view;
    for (int a = 0; a < 3; ++a)
    {
      view.size[a] = static_cast<int>(volume.size[a]);
      view.origin[a] = volume.origin[a];
      view.spacing[a] = volume.spacing[a];
      view.inverseSpacing[a] = 1.0 / volume.spacing[a];
    }
    if (interpolation == CudaInterpolation::Texture)
    {
      // Intensity in [0, 1] as 16-bit normalised texels; a foreground value
      // never rounds to the background's 0.
      std::vector<std::uint16_t> intensity(voxels);
      for (std::size_t v = 0; v < voxels; ++v)
      {
        const double x = std::clamp(static_cast<double>(volume.data[volume.channels * v]), 0.0, 1.0);
        intensity[v] = x > 0.0 ? static_cast<std::uint16_t>(std::max(1.0, std::round(x * 65535.0))) : 0;
      }
      // Slice pairs: layer l holds slices l - 1 and l (clamped to the image)
      // as two channels of one 32-bit texel, so that one bilinear fetch
      // gives both slices around a point and trilinear interpolation takes
      // one filtering pass instead of a 3D texture's two.
      const std::size_t          slice = volume.size[0] * volume.size[1];
      const int                  depth = view.size[2];
      int                        device = 0, maxLayers = 0, maxWidth = 0, maxHeight = 0;
      Check(cudaGetDevice(&device), "reading the current device");
      Check(cudaDeviceGetAttribute(&maxLayers, cudaDevAttrMaxTexture2DLayeredLayers, device),
            "reading the texture limits");
      Check(cudaDeviceGetAttribute(&maxWidth, cudaDevAttrMaxTexture2DLayeredWidth, device), "reading the texture limits");
      Check(cudaDeviceGetAttribute(&maxHeight, cudaDevAttrMaxTexture2DLayeredHeight, device),
            "reading the texture limits");
      if (depth + 1 > maxLayers || view.size[0] > maxWidth || view.size[1] > maxHeight)
        throw Error("CUDA backend: an image of " + std::to_string(view.size[0]) + " x " + std::to_string(view.size[1]) +
                    " x " + std::to_string(depth) + " voxels exceeds the texture path's limits on this device (" +
                    std::to_string(maxWidth) + " x " + std::to_string(maxHeight) + " per slice, " +
                    std::to_string(maxLayers - 1) + " slices); use --backend cuda, or a coarser preprocessing spacing");
      std::vector<std::uint16_t> pairs(2 * slice * (depth + 1));
      for (int l = 0; l <= depth; ++l)
      {
        const std::uint16_t * below = intensity.data() + std::max(l - 1, 0) * slice;
        const std::uint16_t * above = intensity.data() + std::min(l, depth - 1) * slice;
        std::uint16_t *       out = pairs.data() + 2 * slice * l;
        for (std::size_t v = 0; v < slice; ++v)
        {
          out[2 * v] = below[v];
          out[2 * v + 1] = above[v];
        }
      }
      const int layers[3] = { view.size[0], view.size[1], depth + 1 };
      textures.intensity = std::make_unique<cuda::Texture3D>(pairs.data(), 2 * sizeof(std::uint16_t),
                                                             cudaCreateChannelDesc<ushort2>(), layers,
                                                             cuda::TextureLayout::Layers);
      view.intensityTexture = static_cast<unsigned long long>(textures.intensity->Get());
      const std::size_t structures = volume.channels - 1;
      if (structures > 0)
      {
        // One float map per structure (the packed path holds at most
        // MaxTextureStructures). (16-bit normalised distance texels
        // measured 11 % slower on an H100.)
        std::vector<float> distance(voxels);
        for (std::size_t g = 0; g < structures; ++g)
        {
          for (std::size_t v = 0; v < voxels; ++v)
            distance[v] = volume.data[volume.channels * v + 1 + g];
          textures.distances[g] =
            std::make_unique<cuda::Texture3D>(distance.data(), sizeof(float), cudaCreateChannelDesc<float>(), view.size);
          view.distanceTextures[g] = static_cast<unsigned long long>(textures.distances[g]->Get());
        }
        view.distanceMaps = static_cast<int>(structures);
        const NearContourBlocks near = FindNearContourBlocks(volume, m_Constants.guidanceRadius);
        // Four bits per block (a structure each), so that the mask stays
        // small enough for L1.
        std::vector<std::uint8_t> bits((near.mask.size() + 1) / 2, 0);
        for (std::size_t b = 0; b < near.mask.size(); ++b)
          bits[b / 2] |= static_cast<std::uint8_t>((near.mask[b] & 0x0fu) << (4 * (b % 2)));
        textures.nearBlocks.Reserve(bits.size());
        Check(cudaMemcpy(textures.nearBlocks.Data(), bits.data(), bits.size(), cudaMemcpyHostToDevice),
              "uploading the near-contour blocks");
        view.nearBlocks = textures.nearBlocks.Data();
        for (int a = 0; a < 3; ++a)
          view.blocks[a] = near.blocks[a];
      }
      return view;
    }
    std::vector<float> packed(4 * voxels, 0.0f);
    for (std::size_t v = 0; v < voxels; ++v)
      for (std::size_t c = 0; c < volume.channels; ++c)
        packed[4 * v + c] = volume.data[volume.channels * v + c];
    device.Reserve(packed.size());
    Check(cudaMemcpy(device.Data(), packed.data(), packed.size() * sizeof(float), cudaMemcpyHostToDevice),
          "uploading an image");
    view.data = device.Data();
    return view;
  }

  /** Packs the candidate table, the elements (each once), the moved points
   *  and the fold checks' flags and seeds; the parents only by identity. */
  void
  PackCandidates(const std::vector<PartialCandidate> & candidates, HostCandidates & h)
  {
    // The table in one light serial pass (a batch holds each solution's
    // candidates one after another, so the parent lookup is mostly the
    // previous one); the bulk (coordinates) in parallel, straight into
    // pinned memory.
    std::unordered_map<const DualMesh *, std::uint32_t>   parentIndex;
    std::unordered_map<const FosElement *, std::uint32_t> elementSlot;
    std::vector<const FosElement *>                       slotElements; ///< per slot
    std::uint32_t                                         lastSlot = 0;
    const std::size_t                                     n = candidates.size();
    h.prepared = false;
    h.signatures.resize(n);
    h.parents.clear();
    h.parentFirstUse.clear();
    h.pointOffsets.assign(1, 0);
    h.points.clear();
    h.tetrahedronOffsets.assign(1, 0);
    h.dependent.clear();
    h.candidateElement.Reserve(std::max<std::size_t>(1, n));
    h.candidateParent.Reserve(std::max<std::size_t>(1, n));
    h.candidateMoved.Reserve(std::max<std::size_t>(1, n));
    h.firstItem.Reserve(n + 1);
    h.firstItem[0] = 0;
    h.anyChecked = false;
    h.largestChecked = 0;
    const DualMesh * lastParent = nullptr;
    std::uint32_t    lastIndex = 0;
    std::size_t      movedPoints = 0;
    for (std::size_t i = 0; i < n; ++i)
    {
      const PartialCandidate & c = candidates[i];
      h.signatures[i] = HostCandidates::SignatureOf(c);
      if (c.parent != lastParent)
      {
        const auto p = parentIndex.try_emplace(c.parent, static_cast<std::uint32_t>(h.parents.size()));
        if (p.second)
        {
          h.parents.push_back(c.parent);
          h.parentFirstUse.push_back(i);
        }
        lastParent = c.parent;
        lastIndex = p.first->second;
      }
      // Each solution's candidates mostly take the elements in the order of
      // the one before: try the slot after the last one before the map.
      const std::uint32_t slots = static_cast<std::uint32_t>(slotElements.size());
      std::uint32_t       slot = slots > 0 ? (lastSlot + 1) % slots : 0;
      if (slots == 0 || slotElements[slot] != c.element)
      {
        const auto e = elementSlot.try_emplace(c.element, slots);
        slot = e.first->second;
        if (e.second)
        {
          slotElements.push_back(c.element);
          h.points.insert(h.points.end(), c.element->points.begin(), c.element->points.end());
          h.pointOffsets.push_back(static_cast<std::uint32_t>(h.points.size()));
          h.dependent.insert(h.dependent.end(), c.element->dependentTetrahedra.begin(),
                             c.element->dependentTetrahedra.end());
          h.tetrahedronOffsets.push_back(static_cast<std::uint32_t>(h.dependent.size()));
        }
      }
      lastSlot = slot;
      h.candidateElement[i] = slot;
      h.candidateParent[i] = lastIndex;
      h.candidateMoved[i] = static_cast<std::uint32_t>(movedPoints);
      movedPoints += c.element->points.size();
      h.firstItem[i + 1] = h.firstItem[i] + c.element->dependentTetrahedra.size();
      if (c.folds)
      {
        h.anyChecked = true;
        h.largestChecked = std::max(h.largestChecked, c.element->points.size());
      }
    }
    h.movedPoints = movedPoints;
    h.moved.Reserve(std::max<std::size_t>(1, 6 * movedPoints));
    if (h.anyChecked)
    {
      h.foldCheck.Reserve(n);
      h.sideSeeds.Reserve(2 * n);
    }
    m_Pool->ParallelFor(n, [&](std::size_t i) {
      const PartialCandidate & c = candidates[i];
      double *                 out = h.moved.Data() + 6 * static_cast<std::size_t>(h.candidateMoved[i]);
      for (std::size_t k = 0; k < c.element->points.size(); ++k)
      {
        out = std::copy(c.source[k].begin(), c.source[k].end(), out);
        out = std::copy(c.target[k].begin(), c.target[k].end(), out);
      }
      if (h.anyChecked)
      {
        h.foldCheck[i] = c.folds ? 1 : 0;
        h.sideSeeds[2 * i] = c.folds ? RepairSeed(c.seed, 0) : 0;
        h.sideSeeds[2 * i + 1] = c.folds ? RepairSeed(c.seed, 1) : 0;
      }
    });
  }

  /** Queues the upload of what is the same for every candidate range of a
   *  packed batch (elements, candidate table, moved points, which
   *  candidates are checked and their seeds), `staged` first; true when the
   *  batch has fold checks. */
  bool
  UploadTables(const std::vector<PartialCandidate> & candidates, HostCandidates & h, cuda::Event & staged)
  {
    const std::size_t n = candidates.size();
    const bool        checks = m_FoldHandling.constraint && h.anyChecked;
    if (checks && h.largestChecked > cuda::MaxRepairElementPoints)
      throw Error("CUDA backend: fold checks handle elements of up to " + std::to_string(cuda::MaxRepairElementPoints) +
                  " points, not " + std::to_string(h.largestChecked));
    Check(cudaEventRecord(staged.Get(), m_Stream->Get()), "recording an event");
    m_ParentKeys.assign(h.parents.size(), 0);
    m_HostCandidateSlot.Reserve(n);
    m_CandidateParent.Reserve(n);
    m_Batch.candidateParent = m_CandidateParent.Data();
    m_Batch.elementPointOffsets = StageAndUpload(h.pointOffsets, m_HostElementPointOffsets, m_ElementPointOffsets);
    m_Batch.elementPoints = StageAndUpload(h.points, m_HostElementPoints, m_ElementPoints);
    m_Batch.elementTetrahedronOffsets =
      StageAndUpload(h.tetrahedronOffsets, m_HostElementTetrahedronOffsets, m_ElementTetrahedronOffsets);
    m_Batch.elementTetrahedra = StageAndUpload(h.dependent, m_HostElementTetrahedra, m_ElementTetrahedra);
    m_Batch.candidateElement = UploadAsync(h.candidateElement.Data(), n, m_CandidateElement);
    m_Batch.candidateMoved = UploadAsync(h.candidateMoved.Data(), n, m_CandidateMoved);
    m_Batch.candidateFirstItem = UploadAsync(h.firstItem.Data(), n + 1, m_FirstItem);
    // The next batch's moved points go up only once the last repaired
    // ones came back (on the copy stream, behind earlier parts' values).
    Check(cudaStreamWaitEvent(m_Stream->Get(), m_MovedCopied->Get(), 0), "ordering moved points after their copy back");
    m_Batch.moved = UploadAsync(h.moved.Data(), 6 * h.movedPoints, m_Moved);
    m_MovedCount = 6 * h.movedPoints;
    m_Batch.candidates = n;
    if (checks)
    {
      m_FoldCheck = UploadAsync(h.foldCheck.Data(), n, m_FoldCheckDevice);
      m_SideSeeds = UploadAsync(h.sideSeeds.Data(), 2 * n, m_SideSeedsDevice);
      m_HostSkipIfFolded.Reserve(n);
      m_SkipIfFoldedDevice.Reserve(n);
      m_SkipIfFolded = m_SkipIfFoldedDevice.Data();
    }
    return checks;
  }

  /** Candidates [begin, end) of a batch whose tables are queued: the slots
   *  of the parents they use first, those parents (the ones the device does
   *  not hold, see PartialCandidate::parentKey) and which of them need no
   *  values when left folded. The whole batch is one range, or a head [0, h)
   *  the first call and the rest the second (the store's slots are assigned
   *  in two steps then). */
  void
  UploadRange(const std::vector<PartialCandidate> & candidates, HostCandidates & h, BatchFlight & f,
              std::size_t begin, std::size_t end)
  {
    const bool checks = f.checks;
    // Parents are numbered by first use: those first used in the range are
    // consecutive.
    const auto        firstUse = h.parentFirstUse.begin();
    const std::size_t pBegin = static_cast<std::size_t>(std::lower_bound(firstUse, h.parentFirstUse.end(), begin) - firstUse);
    const std::size_t pEnd = static_cast<std::size_t>(std::lower_bound(firstUse, h.parentFirstUse.end(), end) - firstUse);
    std::vector<std::uint64_t> keys(pEnd - pBegin);
    for (std::size_t p = pBegin; p < pEnd; ++p)
      keys[p - pBegin] = m_ParentKeys[p] = candidates[h.parentFirstUse[p]].parentKey;
    for (std::size_t i = begin; i < end; ++i)
      if (candidates[i].parentKey != m_ParentKeys[h.candidateParent[i]])
        throw Error("evaluation backend: one parent with two keys in a batch");
    const ParentSlots::Assignment slots =
      begin == 0 ? m_ParentSlots.AssignFirst(keys, h.parents.size()) : m_ParentSlots.AssignRest(keys);
    m_ParentSlot.resize(h.parents.size());
    for (std::size_t p = pBegin; p < pEnd; ++p)
      m_ParentSlot[p] = slots.slot[p - pBegin];
    for (std::size_t i = begin; i < end; ++i)
      m_HostCandidateSlot[i] = m_ParentSlot[h.candidateParent[i]];
    const std::vector<const DualMesh *> parents(h.parents.begin() + static_cast<std::ptrdiff_t>(pBegin),
                                                h.parents.begin() + static_cast<std::ptrdiff_t>(pEnd));
    UploadParents(parents, slots, m_ParentStaging[begin == 0 ? 0 : 1]);
    cudaStream_t stream = m_Stream->Get();
    Check(cudaMemcpyAsync(m_CandidateParent.Data() + begin, m_HostCandidateSlot.Data() + begin,
                          (end - begin) * sizeof(std::uint32_t), cudaMemcpyHostToDevice, stream),
          "copying a batch to the device");
    if (!checks)
      return;
    m_Pool->ParallelFor(end - begin, [&](std::size_t k) {
      const PartialCandidate & c = candidates[begin + k];
      m_HostSkipIfFolded[begin + k] = c.folds && !c.evaluateFolded ? 1 : 0;
    });
    Check(cudaMemcpyAsync(m_SkipIfFoldedDevice.Data() + begin, m_HostSkipIfFolded.Data() + begin, end - begin,
                          cudaMemcpyHostToDevice, stream),
          "copying a batch to the device");
  }

  /** The fold checks (and repair) of part `p` of flight `f` in range `r`,
   *  between its fold events, on a fold stream after the range's uploads;
   *  their outcome and repaired points' copy back. Part by part, so that
   *  the first part's sampling and acceptance need not wait for the whole
   *  range's checks (one launch per part on the sampling stream, each
   *  waiting for its slowest sides, took the late generations' checks from
   *  0.038 to 0.051 s on an H100). */
  void
  CheckPartFolds(HostCandidates & h, BatchFlight & f, std::size_t r, std::size_t p)
  {
    cudaStream_t main = m_Stream->Get();
    cudaStream_t stream = f.checks ? m_FoldStreams[p % MaxParts]->Get() : main;
    if (f.checks)
      Check(cudaStreamWaitEvent(stream, f.rangeUploaded[r].Get(), 0), "ordering fold checks after their uploads");
    Check(cudaEventRecord(f.PartEvent(p, BatchFlight::FoldStart), stream), "recording an event");
    const std::size_t begin = f.candidateBounds[p], end = f.candidateBounds[p + 1];
    if (f.checks)
      cuda::LaunchCheckCandidateFolds(m_Batch, m_Folds, m_FoldCheck, m_SideSeeds, m_Moved.Data(), f.outcome.Data(),
                                      begin, end - begin, stream);
    Check(cudaEventRecord(f.PartEvent(p, BatchFlight::FoldEnd), stream), "recording an event");
    if (f.checks)
      CopyFoldChecksBack(h, f, p);
  }

  /** A started head must be what the call passes: the same parents' keys
   *  and the same candidates needing no values when left folded. */
  void
  CheckStartedHead(const std::vector<PartialCandidate> & candidates, const HostCandidates & h, const BatchFlight & f,
                   std::size_t head) const
  {
    for (std::size_t i = 0; i < head; ++i)
    {
      const PartialCandidate & c = candidates[i];
      if (c.parentKey != m_ParentKeys[h.candidateParent[i]] ||
          (f.checks && m_HostSkipIfFolded[i] != (c.folds && !c.evaluateFolded ? 1 : 0)))
        throw Error("evaluation backend: candidates started early changed before their evaluation");
    }
  }

  /** Host and device buffers that stage parents for the parent store; one
   *  per candidate range of a batch, so that a later range does not
   *  overwrite what an earlier one's queued copy still reads. */
  struct ParentStaging
  {
    cuda::PinnedArray<double>        host;
    cuda::PinnedArray<std::uint32_t> hostSlots;
    cuda::DeviceArray<double>        staged;
    cuda::DeviceArray<std::uint32_t> stagedSlots;
  };

  /** Stages the parents `slots` names for upload and scatters them into
   *  their slots of the device's parent store. */
  void
  UploadParents(const std::vector<const DualMesh *> & parents, const ParentSlots::Assignment & slots,
                ParentStaging & staging)
  {
    const std::size_t perParent = 6 * static_cast<std::size_t>(m_Batch.points);
    if (slots.grown)
      m_Parents.Reserve(slots.capacity * perParent);
    m_Batch.parents = m_Parents.Data();
    const std::size_t count = slots.upload.size();
    m_Statistics.parentsUploaded += count;
    if (count == 0)
      return;
    staging.host.Reserve(count * perParent);
    staging.hostSlots.Reserve(count);
    m_Pool->ParallelFor(count, [&](std::size_t u) {
      const DualMesh * parent = parents[slots.upload[u]];
      double *         out = staging.host.Data() + u * perParent;
      for (const Vec3 & v : parent->source)
        out = std::copy(v.begin(), v.end(), out);
      for (const Vec3 & v : parent->target)
        out = std::copy(v.begin(), v.end(), out);
      staging.hostSlots[u] = slots.slot[slots.upload[u]];
    });
    const double *        staged = UploadAsync(staging.host.Data(), count * perParent, staging.staged);
    const std::uint32_t * slotsOnDevice = UploadAsync(staging.hostSlots.Data(), count, staging.stagedSlots);
    cuda::LaunchScatterParents(staged, slotsOnDevice, count, perParent, m_Parents.Data(), m_Stream->Get());
  }

  /** The fold checks' outcome and the repaired points of part `p` back to
   *  the host, after them (read when the part is handed over). (An early
   *  version checked part p + 1 on one second stream beside part p's
   *  sampling; with the kernels of then, the two slowed each other down more
   *  than they overlapped: 192.9 s against 184.2 s for 500 generations on an
   *  H100.) */
  void
  CopyFoldChecksBack(HostCandidates & h, BatchFlight & f, std::size_t p)
  {
    // On the copy stream, so that the corners need not wait for the
    // transfer; it goes before the part's values on that stream.
    cudaStream_t      copies = m_CopyStream->Get();
    const std::size_t begin = f.candidateBounds[p], end = f.candidateBounds[p + 1];
    Check(cudaStreamWaitEvent(copies, f.PartEvent(p, BatchFlight::FoldEnd), 0),
          "ordering the fold checks' copy after them");
    Check(cudaMemcpyAsync(f.hostOutcome.Data() + 2 * begin, f.outcome.Data() + 2 * begin, 2 * (end - begin),
                          cudaMemcpyDeviceToHost, copies),
          "copying fold checks from the device");
    if (!m_Folds.repair)
      return;
    const std::size_t n = h.signatures.size();
    const std::size_t from = 6 * static_cast<std::size_t>(h.candidateMoved[begin]);
    const std::size_t to = 6 * (end < n ? static_cast<std::size_t>(h.candidateMoved[end]) : h.movedPoints);
    Check(cudaMemcpyAsync(h.moved.Data() + from, m_Moved.Data() + from, (to - from) * sizeof(double),
                          cudaMemcpyDeviceToHost, copies),
          "copying repaired points from the device");
    Check(cudaEventRecord(m_MovedCopied->Get(), copies), "recording an event");
  }

  /** The fold outcome of part `p`'s candidates, their repaired points in place. */
  void
  ReadFoldChecks(const std::vector<PartialCandidate> & candidates, const HostCandidates & h, BatchFlight & f,
                 std::size_t p)
  {
    const std::size_t begin = f.candidateBounds[p], end = f.candidateBounds[p + 1];
    if (!f.checks)
    {
      for (std::size_t i = begin; i < end; ++i)
        if (candidates[i].folds)
          *candidates[i].folds = CandidateFolds{}; // no dependent tetrahedra, nothing checked
      return;
    }
    // Parts' checks overlap: count the time they cover once.
    const double from = ElapsedSeconds(f.start.Get(), f.PartEvent(p, BatchFlight::FoldStart));
    const double to = ElapsedSeconds(f.start.Get(), f.PartEvent(p, BatchFlight::FoldEnd));
    const double covered = std::max(0.0, to - std::max(from, f.foldCovered));
    f.foldCovered = std::max(f.foldCovered, to);
    f.foldSeconds += covered;
    m_Statistics.foldSeconds += covered;
    // On the pool: most candidates of a late batch have a folded side to
    // copy back (serial, it took 10 ms of each paper-scale generation).
    m_Pool->ParallelFor(end - begin, [&](std::size_t j) {
      const std::size_t        i = begin + j;
      const PartialCandidate & c = candidates[i];
      if (!c.folds)
        return;
      CandidateFolds folds;
      for (int side = 0; side < 2; ++side)
      {
        const std::uint8_t outcome = f.hostOutcome[2 * i + side];
        if (!(outcome & cuda::SideFolded))
          continue;
        ++folds.foldedSides;
        folds.repairedSides += (outcome & cuda::SideRepaired) ? 1 : 0;
        if (!m_Folds.repair)
          continue;
        Vec3 *         out = side == 0 ? c.source : c.target;
        const double * in = h.moved.Data() + 6 * static_cast<std::size_t>(h.candidateMoved[i]) + 3 * side;
        for (std::size_t k = 0; k < c.element->points.size(); ++k)
          for (int a = 0; a < 3; ++a)
            out[k][a] = in[6 * k + a];
      }
      *c.folds = folds;
    });
  }

  /** Copies `count` elements from pinned host memory to `device` on the stream. */
  template <typename T>
  const T *
  UploadAsync(const T * pinned, std::size_t count, cuda::DeviceArray<T> & device)
  {
    device.Reserve(std::max<std::size_t>(1, count));
    Check(cudaMemcpyAsync(device.Data(), pinned, count * sizeof(T), cudaMemcpyHostToDevice, m_Stream->Get()),
          "copying a batch to the device");
    return device.Data();
  }

  /** Stages `host` in pinned memory (kept until the next call, which
   *  synchronises first) and uploads it asynchronously. */
  template <typename T>
  const T *
  StageAndUpload(const std::vector<T> & host, cuda::PinnedArray<T> & pinned, cuda::DeviceArray<T> & device)
  {
    pinned.Reserve(std::max<std::size_t>(1, host.size()));
    std::copy(host.begin(), host.end(), pinned.Data());
    return UploadAsync(pinned.Data(), host.size(), device);
  }

  bool
  UsesTexturePath() const
  {
    return m_Constants.packed && m_Constants.interpolation == cuda::Interpolation::Texture;
  }

  /** Room for `items` items in flight `f` (and for whole solutions' corners). */
  void
  ReserveItems(BatchFlight & f, std::size_t items)
  {
    f.corners.Reserve(items * cuda::ItemCorners);
    f.tetrahedra.Reserve(items);
    f.itemSkip.Reserve(items);
    f.itemValues.Reserve(items * cuda::ItemValues);
    f.directionValues.Reserve(items * 2 * cuda::DirectionValues);
    f.hostItemValues.Reserve(items * cuda::ItemValues);
    f.hostDirectionValues.Reserve(items * 2 * cuda::DirectionValues);
  }

  static TetrahedronValues
  Unpack(const BatchFlight & f, std::size_t item)
  {
    const double *    v = f.hostItemValues.Data() + item * cuda::ItemValues;
    const double *    d = f.hostDirectionValues.Data() + item * 2 * cuda::DirectionValues;
    TetrahedronValues out;
    out.magnitude = v[0];
    out.foldValue = v[1];
    out.folded = v[2];
    out.intensity = d[0] + d[3];
    out.guidance = d[1] + d[4];
    out.samples = d[2] + d[5];
    return out;
  }

  /** Candidate c's sum of flight `f` (LaunchSumCandidateValues' layout). */
  static TetrahedronValues
  SumOf(const BatchFlight & f, std::size_t c)
  {
    TetrahedronValues sum;
    std::memcpy(&sum, f.hostCandidateSums.Data() + c * cuda::CandidateSumValues, sizeof sum);
    return sum;
  }

  static void
  WriteSum(BatchFlight & f, std::size_t c, const TetrahedronValues & sum)
  {
    std::memcpy(f.hostCandidateSums.Data() + c * cuda::CandidateSumValues, &sum, sizeof sum);
  }

  /** Candidate i's values from flight `f`'s items (first[i] ...). */
  static void
  UnpackValues(const BatchFlight & f, const std::uint64_t * first, std::size_t i, const PartialCandidate & c)
  {
    TetrahedronValues * o = c.values;
    for (std::uint64_t item = first[i]; item < first[i + 1]; ++item)
      *o++ = Unpack(f, item);
  }

  static double
  ElapsedSeconds(const cuda::Event & from, const cuda::Event & to)
  {
    return ElapsedSeconds(from.Get(), to.Get());
  }

  static double
  ElapsedSeconds(cudaEvent_t from, cudaEvent_t to)
  {
    float milliseconds = 0.0f;
    Check(cudaEventElapsedTime(&milliseconds, from, to), "reading an event");
    return 1e-3 * milliseconds;
  }

  static double
  SecondsSince(std::chrono::steady_clock::time_point start)
  {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  /** Adds flight `f`'s phases to the statistics (see
   *  BackendStatistics::DevicePhases). */
  void
  AddDevicePhases(const BatchFlight & f)
  {
    auto &            phases = m_Statistics.devicePhases;
    const std::size_t parts = f.Parts();
    const double      folds = f.foldSeconds; // 0 without checks
    double            uploads = ElapsedSeconds(f.staged, f.rangeStart[0]);
    for (std::size_t r = 0; r < f.ranges; ++r)
      uploads += ElapsedSeconds(f.rangeStart[r], f.rangeUploaded[r]);
    const double span = ElapsedSeconds(f.start, f.end);
    const double staging = ElapsedSeconds(f.start, f.staged);
    double       sampling = 0.0;
    for (std::size_t p = 0; p < parts; ++p)
      sampling +=
        ElapsedSeconds(f.PartEvent(p, BatchFlight::SamplingStart), f.PartEvent(p, BatchFlight::SamplingEnd));
    phases.staging += staging;
    phases.uploads += uploads;
    phases.foldChecks += folds;
    phases.sampling += sampling;
    // Corners, screen and set-up, and whatever the device waited for between
    // the ranges: what the rest leave (fold checks overlap other parts' work).
    phases.preparation += std::max(0.0, span - staging - uploads - folds - sampling);
  }

  /** Waits for the stream, counting the host's waiting time. */
  void
  Synchronize(const char * what)
  {
    const auto start = std::chrono::steady_clock::now();
    Check(cudaStreamSynchronize(m_Stream->Get()), what);
    m_Statistics.waitSeconds += SecondsSince(start);
  }

  void
  WaitFor(cudaEvent_t event, const char * what)
  {
    const auto start = std::chrono::steady_clock::now();
    Check(cudaEventSynchronize(event), what);
    m_Statistics.waitSeconds += SecondsSince(start);
  }

  /** Starts a batch of partial candidates on flight `f`: its tables go up,
   *  after f.start and f.staged; `screen` (if any) screens all its ranges. */
  void
  BeginFlight(const std::vector<PartialCandidate> & candidates, HostCandidates & h, BatchFlight & f,
              const RefusalScreen * screen)
  {
    const std::size_t n = candidates.size();
    Check(cudaEventRecord(f.start.Get(), m_Stream->Get()), "recording an event");
    f.items = h.firstItem[n];
    f.checks = f.items > 0 && UploadTables(candidates, h, f.staged);
    f.foldSeconds = f.foldCovered = 0.0;
    if (f.items == 0)
      Check(cudaEventRecord(f.staged.Get(), m_Stream->Get()), "recording an event");
    f.skipItems = true;
    ReserveItems(f, f.items);
    f.candidateSums.Reserve(std::max<std::size_t>(1, n) * cuda::CandidateSumValues);
    f.hostCandidateSums.Reserve(std::max<std::size_t>(1, n) * cuda::CandidateSumValues);
    f.valuesWritten.assign(n, 0);
    f.partsWithValues = 0;
    if (f.checks)
    {
      f.outcome.Reserve(2 * n);
      f.hostOutcome.Reserve(2 * n);
    }
    f.ranges = 0;
    f.candidateBounds.assign(1, 0);
    f.itemBounds.assign(1, 0);
    f.sampledParts = 0;
    f.hasScreen = screen && std::any_of(candidates.begin(), candidates.end(),
                                        [](const PartialCandidate & c) { return c.bound; });
    f.screened = false;
    f.archiveUploaded = false;
    if (f.hasScreen)
    {
      f.screen = *screen;
      f.hostBounds.Reserve(std::max<std::size_t>(1, n));
      f.bounds.Reserve(std::max<std::size_t>(1, n));
      f.refusal.Reserve(std::max<std::size_t>(1, n));
      f.hostRefusal.Reserve(std::max<std::size_t>(1, n));
    }
  }

  /** Queues candidates [begin, end) of the batch begun on flight `f`: their
   *  parents, then part by part the fold checks (and the outcome's copy
   *  back), corners, screen, sampling set-up (texture path), sampling and
   *  the values' copy back. `last`: the batch's last range, whose last part
   *  is smaller. */
  void
  QueueRange(const std::vector<PartialCandidate> & candidates, HostCandidates & h, BatchFlight & f, std::size_t begin,
             std::size_t end, bool last)
  {
    if (f.ranges == BatchFlight::MaxRanges)
      throw Error("CUDA backend: a batch goes up in at most two ranges");
    cudaStream_t      stream = m_Stream->Get();
    const std::size_t r = f.ranges++;
    f.rangeFirstPart[r] = f.Parts();
    Check(cudaEventRecord(f.rangeStart[r].Get(), stream), "recording an event");
    if (f.items > 0)
      UploadRange(candidates, h, f, begin, end);
    Check(cudaEventRecord(f.rangeUploaded[r].Get(), stream), "recording an event");
    // Parts of whole candidates with about equal numbers of items, the
    // batch's last one smaller.
    const std::uint64_t * first = h.firstItem.Data();
    const std::uint64_t   from = first[begin], count = first[end] - from;
    const std::size_t     parts = std::clamp<std::size_t>(count / MinItemsPerPart, 1, MaxParts);
    const double          shares = static_cast<double>(parts - 1) + (last ? LastPartShare : 1.0);
    for (std::size_t p = 1; p < parts; ++p)
    {
      const auto bound = from + static_cast<std::uint64_t>(static_cast<double>(p) / shares * static_cast<double>(count));
      const auto c = static_cast<std::size_t>(std::lower_bound(first + begin, first + end + 1, bound) - first);
      if (c > f.candidateBounds.back() && c < end)
      {
        f.candidateBounds.push_back(c);
        f.itemBounds.push_back(first[c]);
      }
    }
    f.candidateBounds.push_back(end);
    f.itemBounds.push_back(first[end]);
    // Candidates left folded that need no values are not sampled (as on
    // the CPU): late in a run, about a third of a batch's tetrahedra.
    cuda::FoldedCandidateSkip skip;
    if (f.checks)
    {
      skip.skipIfFolded = m_SkipIfFolded;
      skip.outcome = f.outcome.Data();
    }
    for (std::size_t p = f.rangeFirstPart[r]; p < f.Parts(); ++p)
    {
      ReservePart(f, p);
      CheckPartFolds(h, f, r, p);
    }
    for (std::size_t p = f.rangeFirstPart[r]; p < f.Parts(); ++p)
    {
      if (f.checks)
        Check(cudaStreamWaitEvent(stream, f.PartEvent(p, BatchFlight::FoldEnd), 0),
              "ordering corners after fold checks");
      if (f.items > 0)
      {
        cuda::CandidateBatch part = m_Batch;
        part.firstCandidate = f.candidateBounds[p];
        part.candidates = f.candidateBounds[p + 1];
        cuda::LaunchGatherCandidateCorners(part, f.items, skip, f.corners.Data(), f.tetrahedra.Data(),
                                           f.itemSkip.Data(), stream);
        ScreenRange(candidates, f, part);
      }
      PreparePart(f, p);
      SamplePart(f, p);
    }
    f.sampledParts = f.Parts();
  }

  /** Events, workspaces and room for part `p` of flight `f`. */
  void
  ReservePart(BatchFlight & f, std::size_t p)
  {
    if (p >= BatchFlight::MaxRanges * MaxParts)
      throw Error("CUDA backend: a batch in more parts than its ranges allow");
    while (f.partEvents.size() < BatchFlight::PartSteps * (p + 1))
      f.partEvents.push_back(std::make_unique<cuda::Event>());
    while (f.copiedEvents.size() < p + 1)
    {
      f.copiedEvents.push_back(std::make_unique<cuda::Event>());
      f.sumsCopiedEvents.push_back(std::make_unique<cuda::Event>());
    }
    while (f.workspaces.size() < p + 1)
    {
      f.workspaces.push_back(std::make_unique<cuda::DeviceArray<unsigned char>>());
      f.chunkWorkspaces.push_back(std::make_unique<cuda::DeviceArray<unsigned char>>());
    }
    if (f.chunkCapacity.size() < p + 1)
      f.chunkCapacity.resize(p + 1, 0);
  }

  /** On the texture path, the sampling set-up of part `p` (reserved). */
  void
  PreparePart(BatchFlight & f, std::size_t p)
  {
    f.hostChunks[p] = 0; // stays 0 for a part without items
    if (!UsesTexturePath())
      return;
    cudaStream_t      stream = m_Stream->Get();
    const std::size_t begin = f.itemBounds[p], count = f.itemBounds[p + 1] - begin;
    f.workspaces[p]->Reserve(std::max<std::size_t>(1, cuda::TexturePrepareWorkspaceBytes(count)));
    Check(cudaEventRecord(f.PartEvent(p, BatchFlight::SetUpStart), stream), "recording an event");
    cuda::LaunchPrepareTexture(m_Constants, f.corners.Data() + begin * cuda::ItemCorners, f.tetrahedra.Data() + begin,
                               f.skipItems ? f.itemSkip.Data() + begin : nullptr, count, f.workspaces[p]->Data(),
                               f.itemValues.Data() + begin * cuda::ItemValues, f.hostChunks.Data() + p, stream);
    Check(cudaEventRecord(f.PartEvent(p, BatchFlight::SetUpEnd), stream), "recording an event");
  }

  /** Queues the sampling of part `p` of flight `f`, set up, and its values'
   *  copy to the host. On the texture path the host does not wait for the
   *  part's number of chunks: it gets room for the most chunks per item seen
   *  so far, and one with more is sampled again when handed over
   *  (CompleteOverflowingPart). */
  void
  SamplePart(BatchFlight & f, std::size_t p)
  {
    cudaStream_t      stream = m_Stream->Get(), copies = m_CopyStream->Get();
    const std::size_t begin = f.itemBounds[p], count = f.itemBounds[p + 1] - begin;
    double *          itemValues = f.itemValues.Data() + begin * cuda::ItemValues;
    double *          directionValues = f.directionValues.Data() + begin * 2 * cuda::DirectionValues;
    if (UsesTexturePath())
    {
      const auto capacity = static_cast<std::size_t>(std::ceil(m_ChunksPerItem * static_cast<double>(count))) + 1024;
      f.chunkCapacity[p] = capacity;
      f.chunkWorkspaces[p]->Reserve(cuda::TextureChunkWorkspaceBytes(capacity));
      Check(cudaEventRecord(f.PartEvent(p, BatchFlight::SamplingStart), stream), "recording an event");
      cuda::LaunchSampleTexture(m_Constants, count, f.workspaces[p]->Data(), capacity, f.chunkWorkspaces[p]->Data(),
                                directionValues, stream);
    }
    else
    {
      Check(cudaEventRecord(f.PartEvent(p, BatchFlight::SamplingStart), stream), "recording an event");
      cuda::LaunchEvaluateTetrahedra(m_Constants, f.corners.Data() + begin * cuda::ItemCorners,
                                     f.tetrahedra.Data() + begin, f.skipItems ? f.itemSkip.Data() + begin : nullptr,
                                     count, itemValues, directionValues, stream);
    }
    Check(cudaEventRecord(f.PartEvent(p, BatchFlight::SamplingEnd), stream), "recording an event");
    // A batch of candidates (not whole solutions): each one's sum.
    const std::size_t firstCandidate = f.candidateBounds[p], endCandidate = f.candidateBounds[p + 1];
    if (f.skipItems && endCandidate > firstCandidate)
    {
      cuda::CandidateBatch part = m_Batch; // this flight's tables: queued right after their upload
      part.firstCandidate = firstCandidate;
      part.candidates = endCandidate;
      cuda::LaunchSumCandidateValues(part, f.itemValues.Data(), f.directionValues.Data(), f.candidateSums.Data(),
                                     stream);
    }
    Check(cudaEventRecord(f.PartEvent(p, BatchFlight::ValuesEnd), stream), "recording an event");
    // The values go back on the copy stream, so that the next part's
    // kernels do not wait for the transfer (about 70 bytes per tetrahedron).
    // The candidates' sums first: acceptance needs only them, and the
    // values of the few it keeps (FetchValues) later.
    Check(cudaStreamWaitEvent(copies, f.PartEvent(p, BatchFlight::ValuesEnd), 0), "ordering a copy after its part");
    if (f.skipItems && endCandidate > firstCandidate)
      Check(cudaMemcpyAsync(f.hostCandidateSums.Data() + firstCandidate * cuda::CandidateSumValues,
                            f.candidateSums.Data() + firstCandidate * cuda::CandidateSumValues,
                            (endCandidate - firstCandidate) * cuda::CandidateSumValues * sizeof(double),
                            cudaMemcpyDeviceToHost, copies),
            "copying candidate sums from the device");
    Check(cudaEventRecord(f.sumsCopiedEvents[p]->Get(), copies), "recording an event");
    Check(cudaMemcpyAsync(f.hostItemValues.Data() + begin * cuda::ItemValues, itemValues,
                          count * cuda::ItemValues * sizeof(double), cudaMemcpyDeviceToHost, copies),
          "copying values from the device");
    Check(cudaMemcpyAsync(f.hostDirectionValues.Data() + begin * 2 * cuda::DirectionValues, directionValues,
                          count * 2 * cuda::DirectionValues * sizeof(double), cudaMemcpyDeviceToHost, copies),
          "copying values from the device");
    Check(cudaEventRecord(f.copiedEvents[p]->Get(), copies), "recording an event");
  }

  /** Queues the sampling of the parts of flight `f` not yet queued (see
   *  SamplePart), then f.end. */
  void
  QueueSampling(BatchFlight & f)
  {
    for (std::size_t p = f.sampledParts; p < f.Parts(); ++p)
      SamplePart(f, p);
    f.sampledParts = f.Parts();
    Check(cudaEventRecord(f.end.Get(), m_Stream->Get()), "recording an event");
  }

  /** Part `p` of flight `f`, whose values are on the host, sampled again
   *  where it had more chunks than room for them; and the room of later
   *  parts made enough for it. `first`: the candidates' first items (null
   *  for whole solutions), whose sums are then made again. */
  void
  CompleteOverflowingPart(BatchFlight & f, std::size_t p, const std::uint64_t * first)
  {
    if (!UsesTexturePath())
      return;
    const std::size_t begin = f.itemBounds[p], count = f.itemBounds[p + 1] - begin;
    const std::size_t chunks = f.hostChunks[p];
    if (count > 0)
      m_ChunksPerItem = std::max(m_ChunksPerItem, ChunkRoomMargin * static_cast<double>(chunks) / static_cast<double>(count));
    if (chunks <= f.chunkCapacity[p])
      return;
    // Rare: once early in a run. The part's set-up is still in its workspace;
    // its first values must have landed before they are copied again.
    WaitForValues(f, p + 1);
    cudaStream_t stream = m_FallbackStream->Get();
    double *     directionValues = f.directionValues.Data() + begin * 2 * cuda::DirectionValues;
    f.chunkWorkspaces[p]->Reserve(cuda::TextureChunkWorkspaceBytes(chunks));
    f.chunkCapacity[p] = chunks;
    cuda::LaunchSampleTexture(m_Constants, count, f.workspaces[p]->Data(), chunks, f.chunkWorkspaces[p]->Data(),
                              directionValues, stream);
    Check(cudaMemcpyAsync(f.hostDirectionValues.Data() + begin * 2 * cuda::DirectionValues, directionValues,
                          count * 2 * cuda::DirectionValues * sizeof(double), cudaMemcpyDeviceToHost, stream),
          "copying values from the device");
    Check(cudaStreamSynchronize(stream), "sampling a part again");
    ++m_Statistics.partsSampledAgain;
    // The device summed the values that overflowed: the same sums afresh.
    if (first != nullptr)
      for (std::size_t c = f.candidateBounds[p]; c < f.candidateBounds[p + 1]; ++c)
      {
        ObjectiveTotals sum;
        for (std::uint64_t item = first[c]; item < first[c + 1]; ++item)
          sum.Add(Unpack(f, item));
        WriteSum(f, c, sum.sum);
      }
  }

  /** Waits until the values of flight `f`'s first `parts` parts are on the
   *  host (each part's follow its sums on the copy stream). */
  void
  WaitForValues(BatchFlight & f, std::size_t parts)
  {
    if (parts > f.partsWithValues)
    {
      WaitFor(f.copiedEvents[parts - 1]->Get(), "copying values from the device");
      f.partsWithValues = parts;
    }
  }

  /** WaitForValues for the parts holding candidates `which` of flight `f`. */
  void
  WaitForCandidateValues(BatchFlight & f, const std::vector<std::size_t> & which)
  {
    std::size_t parts = 0;
    for (std::size_t i : which)
    {
      const auto bound = std::upper_bound(f.candidateBounds.begin(), f.candidateBounds.end(), i);
      parts = std::max(parts, static_cast<std::size_t>(bound - f.candidateBounds.begin()));
    }
    WaitForValues(f, std::min(parts, f.Parts()));
  }

  /** Hands the parts of flight `f` over in order as their sums arrive:
   *  fold outcomes, sums (or bounds), then ready(); their values follow
   *  (WaitForValues). On an H100 the sums ahead of the values changed late
   *  generations by less than their spread (0.1058 against 0.1072 s). */
  void
  Deliver(const std::vector<PartialCandidate> & candidates, const HostCandidates & h, BatchFlight & f,
          const ReadyCandidates & ready)
  {
    const std::size_t     parts = f.Parts();
    const std::uint64_t * first = h.firstItem.Data();
    const std::uint32_t * spared = f.screened ? f.hostRefusal.Data() : nullptr;
    const auto &          witnesses = f.screen.witnesses;
    std::uint64_t         skippedItems = 0;
    for (std::size_t p = 0; p < parts; ++p)
    {
      WaitFor(f.sumsCopiedEvents[p]->Get(), "copying candidate sums from the device");
      CompleteOverflowingPart(f, p, first);
      // Read before ready() may start the next batch on the previous flight.
      if (p == 0 && f.items > 0 && m_PreviousFlight)
        m_Statistics.devicePhases.betweenBatches += ElapsedSeconds(m_PreviousFlight->end, f.start);
      const auto unpack = std::chrono::steady_clock::now();
      ReadFoldChecks(candidates, h, f, p);
      const std::size_t begin = f.candidateBounds[p], end = f.candidateBounds[p + 1];
      skippedItems += UnpackSums(candidates, f, first, begin, end, spared, witnesses);
      m_Statistics.unpackSeconds += SecondsSince(unpack);
      // The caller may start the next batch's head while handing over the
      // next-to-last part: it runs behind the last one.
      const AcceptHeadScope scope(m_AcceptHead, p + 2 == parts);
      if (ready)
        ready(begin, end);
    }
    // The batch's end, not the stream's: a started head may follow it. Its
    // values too, so that no copy into the flight's buffers is left pending.
    WaitFor(f.end.Get(), "evaluating tetrahedra");
    WaitForValues(f, parts);
    AddKernelSeconds(f);
    ++m_Statistics.batches;
    m_Statistics.tetrahedra += f.items - skippedItems;
    if (f.items > 0)
    {
      AddDevicePhases(f);
      m_PreviousFlight = &f;
    }
  }

  void
  AddKernelSeconds(const BatchFlight & f)
  {
    for (std::size_t p = 0; p < f.Parts(); ++p)
    {
      if (UsesTexturePath())
      {
        const double setUp =
          ElapsedSeconds(f.PartEvent(p, BatchFlight::SetUpStart), f.PartEvent(p, BatchFlight::SetUpEnd));
        m_Statistics.kernelSeconds += setUp;
        m_Statistics.setUpKernelSeconds += setUp;
      }
      m_Statistics.kernelSeconds +=
        ElapsedSeconds(f.PartEvent(p, BatchFlight::SamplingStart), f.PartEvent(p, BatchFlight::SamplingEnd));
    }
  }

  /** Evaluates `items` items of whole solutions, their corners in flight
   *  `f` already, in one part, and waits for their values. */
  void
  RunWhole(BatchFlight & f, std::size_t items)
  {
    f.skipItems = false;
    f.items = items;
    f.ranges = 0;
    f.candidateBounds.assign({ 0, 0 });
    f.itemBounds.assign({ 0, items });
    f.sampledParts = 0;
    ReservePart(f, 0);
    PreparePart(f, 0);
    QueueSampling(f);
    WaitFor(f.copiedEvents[0]->Get(), "evaluating tetrahedra");
    CompleteOverflowingPart(f, 0, nullptr);
    WaitFor(f.end.Get(), "evaluating tetrahedra");
    AddKernelSeconds(f);
    ++m_Statistics.batches;
    m_Statistics.tetrahedra += items;
    m_PreviousFlight = nullptr; // its end is not a batch's
  }

  /** Hands candidates [begin, end) of flight `f` their sums (their values
   *  wait for FetchValues) and bounds' outcome, counting their samples;
   *  those left folded without values are left alone, as on the CPU.
   *  `spared` (null: none): per candidate, the refusal screen's verdict.
   *  Returns the number of items left alone. */
  std::uint64_t
  UnpackSums(const std::vector<PartialCandidate> & candidates, const BatchFlight & f, const std::uint64_t * first,
             std::size_t begin, std::size_t end, const std::uint32_t * spared, const std::vector<std::uint64_t> & witnesses)
  {
    std::uint64_t itemsLeftAlone = 0;
    for (std::size_t i = begin; i < end; ++i)
    {
      const PartialCandidate & c = candidates[i];
      const std::uint32_t      by = spared ? spared[i] : 0;
      if (c.bound)
      {
        c.bound->skipped = by != 0;
        c.bound->witness = by != 0 && by - 1 < witnesses.size() ? witnesses[by - 1] : 0;
      }
      if (Skipped(c))
      {
        itemsLeftAlone += first[i + 1] - first[i];
        continue;
      }
      const TetrahedronValues sum = SumOf(f, i);
      if (c.sum)
        *c.sum = sum;
      if (by != 0)
      {
        ++m_Statistics.boundSkipped;
        m_Statistics.boundSkippedSamples += sum.samples;
      }
      else
        m_Statistics.samples += sum.samples;
    }
    return itemsLeftAlone;
  }

  /** Unpacks whole solutions' values from flight `f` (n items each, in
   *  solution order) on the pool, counting their samples. */
  void
  UnpackSolutions(const BatchFlight & f, std::size_t n, const std::vector<std::vector<TetrahedronValues> *> & values)
  {
    std::vector<double> samples(values.size(), 0.0);
    m_Pool->ParallelFor(values.size(), [&](std::size_t s) {
      std::vector<TetrahedronValues> & out = *values[s];
      out.resize(n);
      for (std::size_t t = 0; t < n; ++t)
      {
        out[t] = Unpack(f, s * n + t);
        samples[s] += out[t].samples;
      }
    });
    for (double count : samples)
      m_Statistics.samples += count;
  }

  const TetrahedronEvaluator &  m_Evaluator;
  std::shared_ptr<ThreadPool> m_Pool;
  std::unique_ptr<cuda::Stream> m_Stream;
  std::unique_ptr<cuda::Stream> m_CopyStream; ///< the parts' values back to the host
  /** The parts' fold checks, part p on stream p % MaxParts: a range's parts
   *  run side by side, so that one part's slowest sides (ten rounds of
   *  repair) do not hold the device idle, yet each part's corners and
   *  sampling wait for its own checks only. */
  std::array<std::unique_ptr<cuda::Stream>, MaxParts> m_FoldStreams;
  /** On the copy stream, after the last repaired points' copy back (made
   *  once a device is known to be there, as the streams are). */
  std::unique_ptr<cuda::Event> m_MovedCopied;
  std::unique_ptr<BatchFlight>  m_Flights[2]; ///< as m_HostCandidates: the batch in flight, the next one
  const BatchFlight *           m_PreviousFlight{ nullptr }; ///< the last batch handed over, for its end
  double                        m_ChunksPerItem{ 6.0 }; ///< room for chunks per item: the most seen, with a margin
  cuda::EvaluationConstants     m_Constants;
  cuda::DeviceArray<float>      m_Moving, m_Fixed, m_PackedMoving, m_PackedFixed;
  VolumeTextures m_MovingTextures, m_FixedTextures;
  cuda::DeviceArray<double>     m_GuidanceWeights, m_Elasticity, m_ReferenceVolumes;
  cuda::PinnedArray<double>        m_HostSolutionPoints; ///< whole solutions' points, staged
  cuda::DeviceArray<double>        m_SolutionPoints;
  // Partial candidates: the mesh once, then per batch (device and staging).
  cuda::CandidateBatch             m_Batch;
  cuda::DeviceArray<std::uint32_t> m_Mesh, m_ElementPointOffsets, m_ElementPoints, m_ElementTetrahedronOffsets,
    m_ElementTetrahedra, m_CandidateElement, m_CandidateParent, m_CandidateMoved;
  cuda::DeviceArray<std::uint64_t> m_FirstItem;
  ParentSlots                      m_ParentSlots;
  cuda::DeviceArray<double>        m_Parents; ///< the parent store: slots of m_ParentSlots
  cuda::DeviceArray<double>        m_Moved;
  ParentStaging                    m_ParentStaging[2]; ///< the batch's first range, the rest
  std::vector<std::uint64_t>       m_ParentKeys;       ///< per parent of the batch on the device
  std::vector<std::uint32_t>       m_ParentSlot;       ///< per parent of the batch on the device
  /** The next batch's head, started while the current one is handed over. */
  struct
  {
    bool        open{ false };
    std::size_t count{ 0 };
  } m_Head;
  bool m_AcceptHead{ false }; ///< StartNextPartials may start a head now
  cuda::PinnedArray<std::uint32_t> m_HostElementPointOffsets, m_HostElementPoints, m_HostElementTetrahedronOffsets,
    m_HostElementTetrahedra, m_HostCandidateSlot;
  HostCandidates                   m_HostCandidates[2];
  int                              m_CurrentHost{ 0 }; ///< the one of the batch in flight (or last)

  std::size_t                      m_MovedCount{ 0 };
  // Fold checks: the constraint once (SetFoldHandling), then per batch.
  cuda::FoldRepairConstants        m_Folds;
  cuda::DeviceArray<double>        m_FoldReferenceVolumes;
  cuda::DeviceArray<std::uint32_t> m_PointTetrahedronOffsets, m_PointTetrahedra;
  cuda::DeviceArray<std::int8_t>   m_Pins;
  const std::uint8_t *             m_FoldCheck{ nullptr };
  const std::uint8_t *             m_SkipIfFolded{ nullptr }; ///< per candidate: left folded, it needs no values
  const std::uint64_t *            m_SideSeeds{ nullptr };
  cuda::DeviceArray<std::uint8_t>  m_FoldCheckDevice, m_SkipIfFoldedDevice;
  cuda::DeviceArray<std::uint64_t> m_SideSeedsDevice;
  cuda::PinnedArray<std::uint8_t>  m_HostSkipIfFolded;
  // The sampling of the candidates a refusal screen skipped that the
  // optimiser needs after all.
  std::unique_ptr<cuda::Stream>                m_FallbackStream;
  std::unique_ptr<cuda::Event>                 m_FallbackStart, m_FallbackEnd; ///< around its kernels
  cuda::PinnedArray<std::uint64_t>             m_HostFallbackItems;
  cuda::DeviceArray<std::uint64_t>             m_FallbackItems;
  cuda::DeviceArray<double> m_FallbackCorners, m_FallbackItemValues, m_FallbackDirectionValues;
  cuda::DeviceArray<std::uint32_t>             m_FallbackTetrahedra;
  cuda::PinnedArray<std::uint32_t>             m_HostFallbackList;
  cuda::DeviceArray<std::uint32_t>             m_FallbackList;
  cuda::DeviceArray<double>                    m_FallbackChunkSums;
  cuda::PinnedArray<double>                    m_HostFallbackChunkSums;
  cuda::PinnedArray<double>                    m_HostFallbackDirectionValues;
};
} // namespace

std::unique_ptr<EvaluationBackend>
CreateCudaEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads,
                            CudaInterpolation interpolation)
{
  return std::make_unique<CudaEvaluationBackend>(evaluator, threads, interpolation);
}
} // namespace morea
