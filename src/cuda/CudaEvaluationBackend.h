// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The CUDA evaluation backend: the same calls as the CPU backend
// (CpuEvaluationBackend.cxx), evaluated on the GPU. Images, distance maps,
// the mesh and per-tetrahedron constants are uploaded once. A batch of
// partial candidates (all candidates of a parallel group of a cluster) goes
// up as its parents' points, its elements and the moved points; the device
// builds every dependent tetrahedron's corners, evaluates them part by part
// and the values come back as each part is done. The next batch's candidates
// whose parents are final may start while the current one is handed over.
//
// This header (not installed) declares the backend for its three source
// files: CudaEvaluationBackend.cxx (construction and the backend's calls),
// CudaBatchUpload.cxx (packing and uploading a batch, starting its ranges)
// and CudaBatchParts.cxx (a batch's parts on the device and their values
// handed back).
#ifndef morea_CudaEvaluationBackend_h
#define morea_CudaEvaluationBackend_h

#include "morea_core/EvaluationBackend.h"

#include "DeviceMemory.h"
#include "FoldRepairKernels.h"
#include "RefusalScreenKernels.h"
#include "TetrahedronKernels.h"

#include "morea_core/ComputeDevices.h"
#include "morea_core/NearContourBlocks.h"
#include "morea_core/ParentSlots.h"
#include "morea_core/Error.h"
#include "morea_core/TetrahedronSampling.h"
#include "morea_core/ThreadPool.h"

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

namespace morea_core
{
namespace cudabackend
{
using cuda::Check;

// A batch of partial candidates runs in parts of at least MinItemsPerPart
// tetrahedra, at most MaxParts: the caller accepts one part while the device
// samples the next. Each part costs the device its own set-up launches, the
// tail of its sampling kernel (where the multiprocessors run out of blocks),
// and in its schedule fewer solutions' copies of a tetrahedron side by side
// for the texture cache. On an H100, with the paper's configuration, against
// 4 parts: 3 sampled 1.6 % more points per second of kernels in early
// generations (2.5 % in late ones) at the same seconds per generation; 2
// parts 2.8 % (3.9 %), but late generations were about 3 % slower; 1 part
// 9.6 % in late ones, which took 24 % longer with nothing overlapping the
// acceptance. With the sampling kernel's blocks of 20 warps, 2 parts against
// 3 sampled 0.4 % more points per second in early generations and 1.6 % in
// late ones (generations 341-380), at 0.0808 s per late generation against
// 0.0821 s.
// The last part's acceptance has nothing to overlap with, so that part is
// smaller: LastPartShare of the others'.
constexpr std::size_t MaxParts = 2;
constexpr std::size_t MinItemsPerPart = 100000;
constexpr double      LastPartShare = 0.5;
// Room for this many times the most chunks per item seen so far. The
// sampling grid is sized for the room, and its blocks past the chunks leave
// at once but still pass through the device's block scheduler.
constexpr double ChunkRoomMargin = 1.25;
// The room per item before any part's chunks are known.
constexpr double FirstChunkRoomPerItem = 6.0;

/** The texture path's textures of one image. */
struct VolumeTextures
{
  std::unique_ptr<cuda::Texture3D>                                         intensity;
  std::unique_ptr<cuda::Texture3D>                                         nearestDistance;
  std::array<std::unique_ptr<cuda::Texture3D>, cuda::MaxTextureStructures> distancePairs;
  cuda::DeviceArray<std::uint8_t> nearBlocks; ///< see cuda::PackedVolumeView::nearBlocks
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
  /** Per candidate its parent's slot in the store and whether, left folded,
   *  it needs no values, staged for their upload range by range. Per flight:
   *  the next batch's head is staged while this batch's rest may still wait
   *  for its copy (behind other processes' work on a shared device). */
  cuda::PinnedArray<std::uint32_t> hostCandidateSlot;
  cuda::PinnedArray<std::uint8_t>  hostSkipIfFolded;
  cuda::DeviceArray<std::uint8_t>  outcome; ///< per candidate side: the fold checks' outcome
  cuda::PinnedArray<std::uint8_t>  hostOutcome;
  cuda::PinnedArray<std::uint32_t> hostChunks; ///< per part: the texture set-up's number of chunks
  /** Per candidate the first place and stride of its items in its part's
   *  sampling order (cuda::ItemSchedule); `scheduled`: they are set (a
   *  whole evaluation's items are sorted instead). */
  cuda::PinnedArray<std::uint32_t> hostSchedule;
  cuda::DeviceArray<std::uint32_t> schedule;
  bool                             scheduled{ false };
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
  std::vector<std::uint8_t> refusalOnDevice; ///< per part: its screen ran on the device (its outcome to copy)

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
  CudaEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads, CudaInterpolation interpolation,
                        int device = 0);

  std::string
  Name() const override
  {
    return m_Constants.packed && m_Constants.interpolation == cuda::Interpolation::Texture ? "cuda-texture" : "cuda-exact";
  }

  /** Why the texture path, asked for, does not run (more structures than it
   *  reads); "" otherwise. */
  std::string
  PathNote() const override
  {
    return m_PathNote;
  }

  void
  EvaluateSolutions(const std::vector<const DualMesh *> & solutions,
                    const std::vector<std::vector<TetrahedronValues> *> & values) override;

  /** Both flights sized for a whole population's items (a full evaluation
   *  may land in either), its points staged, the parent store and the
   *  largest batch's candidates. */
  MemoryEstimate
  MemoryFor(const RunShape & shape) const override;

  std::optional<double>
  FreeDeviceMemory() const override;

  void
  SetFoldHandling(const FoldHandling & handling) override;

  using EvaluationBackend::EvaluatePartials;
  void
  EvaluatePartials(const std::vector<PartialCandidate> & candidates, const ReadyCandidates & ready,
                   const Meanwhile & meanwhile) override;

  void
  PrepareNextPartials(const std::vector<PartialCandidate> & next) override;

  /** HoldCudaEvaluationStream. */
  void
  HoldStream(const std::atomic<bool> & release);

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
                    const RefusalScreen * screen) override;

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
  FetchValues(const std::vector<PartialCandidate> & candidates, const std::vector<std::size_t> & which) override;

  void
  SampleSkipped(const std::vector<PartialCandidate> & candidates, const std::vector<std::size_t> & which) override;

private:
  /** Queues the refusal screen of candidates [range.firstCandidate,
   *  range.candidates) of flight `f`, whose corners are queued, when the
   *  batch has a screen. True when it queued a kernel, whose outcome
   *  SamplePart copies to f.hostRefusal with the part's sums; otherwise
   *  the outcome is on the host already. */
  bool
  ScreenRange(const std::vector<PartialCandidate> & candidates, BatchFlight & f, const cuda::CandidateBatch & range);

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
  Upload(const ChannelVolume & volume, cuda::DeviceArray<float> & device);

  cuda::PackedVolumeView
  UploadPacked(const ChannelVolume & volume, cuda::DeviceArray<float> & device, VolumeTextures & textures,
               CudaInterpolation interpolation);

  /** Packs the candidate table, the elements (each once), the moved points
   *  and the fold checks' flags and seeds; the parents only by identity. */
  void
  PackCandidates(const std::vector<PartialCandidate> & candidates, HostCandidates & h);

  /** Queues the upload of what is the same for every candidate range of a
   *  packed batch (elements, candidate table, moved points, which
   *  candidates are checked and their seeds), `staged` first; true when the
   *  batch has fold checks. */
  bool
  UploadTables(const std::vector<PartialCandidate> & candidates, HostCandidates & h, cuda::Event & staged);

  /** Candidates [begin, end) of a batch whose tables are queued: the slots
   *  of the parents they use first, those parents (the ones the device does
   *  not hold, see PartialCandidate::parentKey) and which of them need no
   *  values when left folded. The whole batch is one range, or a head [0, h)
   *  the first call and the rest the second (the store's slots are assigned
   *  in two steps then). */
  void
  UploadRange(const std::vector<PartialCandidate> & candidates, HostCandidates & h, BatchFlight & f,
              std::size_t begin, std::size_t end);

  /** The fold checks (and repair) of part `p` of flight `f` in range `r`,
   *  between its fold events, on a fold stream after the range's uploads;
   *  their outcome and repaired points' copy back. Part by part, so that
   *  the first part's sampling and acceptance need not wait for the whole
   *  range's checks (one launch per part on the sampling stream, each
   *  waiting for its slowest sides, took the late generations' checks from
   *  0.038 to 0.051 s on an H100). */
  void
  CheckPartFolds(HostCandidates & h, BatchFlight & f, std::size_t r, std::size_t p);

  /** A started head must be what the call passes: the same parents' keys
   *  and the same candidates needing no values when left folded. */
  void
  CheckStartedHead(const std::vector<PartialCandidate> & candidates, const HostCandidates & h, const BatchFlight & f,
                   std::size_t head) const;

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
                ParentStaging & staging);

  /** The fold checks' outcome and the repaired points of part `p` back to
   *  the host, after them (read when the part is handed over). (An early
   *  version checked part p + 1 on one second stream beside part p's
   *  sampling; with the kernels of then, the two slowed each other down more
   *  than they overlapped: 192.9 s against 184.2 s for 500 generations on an
   *  H100.) */
  void
  CopyFoldChecksBack(HostCandidates & h, BatchFlight & f, std::size_t p);

  /** The fold outcome of part `p`'s candidates, their repaired points in place. */
  void
  ReadFoldChecks(const std::vector<PartialCandidate> & candidates, const HostCandidates & h, BatchFlight & f,
                 std::size_t p);

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
  ReserveItems(BatchFlight & f, std::size_t items);

  /** Inline: the unpacking loops call it once per tetrahedron. */
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
  AddDevicePhases(const BatchFlight & f);

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
              const RefusalScreen * screen);

  /** Queues candidates [begin, end) of the batch begun on flight `f`: their
   *  parents, then part by part the fold checks (and the outcome's copy
   *  back), corners, screen, sampling set-up (texture path), sampling and
   *  the values' copy back. `last`: the batch's last range, whose last part
   *  is smaller. */
  void
  QueueRange(const std::vector<PartialCandidate> & candidates, HostCandidates & h, BatchFlight & f, std::size_t begin,
             std::size_t end, bool last);

  /** Events, workspaces and room for part `p` of flight `f`. */
  void
  ReservePart(BatchFlight & f, std::size_t p);

  /** On the texture path, the order of part `p`'s items in its sampling
   *  (cuda::ItemSchedule) from the candidates' layout, queued to the device. */
  void
  ScheduleItems(const HostCandidates & h, BatchFlight & f, std::size_t p);

  /** On the texture path, the sampling set-up of part `p` (reserved). */
  void
  PreparePart(BatchFlight & f, std::size_t p);

  /** Queues the sampling of part `p` of flight `f`, set up, and its values'
   *  copy to the host. On the texture path the host does not wait for the
   *  part's number of chunks: it gets room for the most chunks per item seen
   *  so far, and one with more is sampled again when handed over
   *  (CompleteOverflowingPart). */
  void
  SamplePart(BatchFlight & f, std::size_t p);

  /** Room for chunks per item: the first guess, then the most seen so far
   *  with ChunkRoomMargin. */
  double
  ChunkRoomPerItem() const
  {
    return m_MostChunksPerItem < 0.0 ? FirstChunkRoomPerItem : ChunkRoomMargin * m_MostChunksPerItem;
  }

  /** Queues the sampling of the parts of flight `f` not yet queued (see
   *  SamplePart), then f.end. */
  void
  QueueSampling(BatchFlight & f);

  /** Part `p` of flight `f`, whose values are on the host, sampled again
   *  where it had more chunks than room for them; and the room of later
   *  parts made enough for it. `first`: the candidates' first items (null
   *  for whole solutions), whose sums are then made again. */
  void
  CompleteOverflowingPart(BatchFlight & f, std::size_t p, const std::uint64_t * first);

  /** Waits until the values of flight `f`'s first `parts` parts are on the
   *  host (each part's follow its sums on the copy stream). */
  void
  WaitForValues(BatchFlight & f, std::size_t parts);

  /** WaitForValues for the parts holding candidates `which` of flight `f`. */
  void
  WaitForCandidateValues(BatchFlight & f, const std::vector<std::size_t> & which);

  /** Hands the parts of flight `f` over in order as their sums arrive:
   *  fold outcomes, sums (or bounds), then ready(); their values follow
   *  (WaitForValues). On an H100 the sums ahead of the values changed late
   *  generations by less than their spread (0.1058 against 0.1072 s). */
  void
  Deliver(const std::vector<PartialCandidate> & candidates, const HostCandidates & h, BatchFlight & f,
          const ReadyCandidates & ready);

  /** Adds the device time of flight `f`'s set-up and sampling kernels,
   *  less what the skipped candidates' sampling (on its own stream, counted
   *  as it ran) overlapped of it: time in which both ran counts once. */
  void
  AddKernelSeconds(const BatchFlight & f);

  /** Re-bases the skipped candidates' sampling intervals on flight `f`'s
   *  start while the previous flight's start still holds (see Deliver). */
  void
  RebaseFallbackIntervals(const BatchFlight & f);

  /** Evaluates `items` items of whole solutions, their corners in flight
   *  `f` already, in one part, and waits for their values. */
  void
  RunWhole(BatchFlight & f, std::size_t items);

  /** Hands candidates [begin, end) of flight `f` their sums (their values
   *  wait for FetchValues) and bounds' outcome, counting their samples;
   *  those left folded without values are left alone, as on the CPU.
   *  `spared` (null: none): per candidate, the refusal screen's verdict.
   *  Returns the number of items left alone. */
  std::uint64_t
  UnpackSums(const std::vector<PartialCandidate> & candidates, const BatchFlight & f, const std::uint64_t * first,
             std::size_t begin, std::size_t end, const std::uint32_t * spared, const std::vector<std::uint64_t> & witnesses);

  /** Unpacks whole solutions' values from flight `f` (n items each, in
   *  solution order) on the pool, counting their samples. */
  void
  UnpackSolutions(const BatchFlight & f, std::size_t n, const std::vector<std::vector<TetrahedronValues> *> & values);

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
  /** The most chunks per item a part has held so far; negative before the
   *  first (see ChunkRoomPerItem). */
  double                        m_MostChunksPerItem{ -1.0 };
  cuda::EvaluationConstants     m_Constants;
  /** Makes this backend's device current on the calling thread. */
  void
  SelectDevice() const;
  std::string                   m_PathNote; ///< see PathNote
  int                           m_Device{ 0 }; ///< the CUDA device ordinal every call runs on
  cuda::DeviceArray<float>      m_Moving, m_Fixed, m_PackedMoving, m_PackedFixed;
  VolumeTextures m_MovingTextures, m_FixedTextures;
  cuda::DeviceArray<double>     m_GuidanceWeights, m_Elasticity, m_ReferenceVolumes;
  cuda::DeviceArray<double>     m_RigidWeights, m_RigidInverseEdges, m_RigidLimitVolumes;
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
    m_HostElementTetrahedra;
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
  // The sampling of the candidates a refusal screen skipped that the
  // optimiser needs after all.
  std::unique_ptr<cuda::Stream>                m_FallbackStream;
  std::unique_ptr<cuda::Event>                 m_FallbackStart, m_FallbackEnd; ///< around its kernels
  /** Its kernels' spans in seconds after m_FallbackFlight's start, kept
   *  until the sampling they may overlap is counted (AddKernelSeconds). */
  std::vector<std::pair<double, double>>       m_FallbackIntervals;
  const BatchFlight *                          m_FallbackFlight{ nullptr };
  /** ScheduleItems' scratch: per element slot its group in the part, and
   *  per group its candidates, their items each and the next free place. */
  struct ScheduleGroup
  {
    std::uint32_t candidates, items, next;
  };
  std::vector<std::uint32_t> m_SlotGroup;
  std::vector<ScheduleGroup> m_ScheduleGroups;
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
} // namespace cudabackend
} // namespace morea_core

#endif
