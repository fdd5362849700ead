// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The CUDA evaluation backend's construction and calls (see
// CudaEvaluationBackend.h).
#include "CudaEvaluationBackend.h"

#include <thread>

namespace morea_core
{
namespace cudabackend
{
CudaEvaluationBackend::CudaEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads,
                                             CudaInterpolation interpolation, int device)
  : m_Evaluator(evaluator)
  , m_Pool(ThreadPool::Shared(threads))
  , m_Device(device)
{
  const std::string unavailable = CudaUnavailableReason();
  if (!unavailable.empty())
    throw Error("CUDA backend: " + unavailable);
  SelectDevice();
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
  for (std::size_t g = 0; g < std::min<std::size_t>(cuda::MaxTextureStructures, data.guidanceWeights.size()); ++g)
    m_Constants.textureGuidanceWeights[g] = static_cast<float>(data.guidanceWeights[g]);
  m_Constants.guidanceRadius = data.guidanceRadius;
  m_Constants.samplingRate = data.samplingRate;
  m_Constants.voxelVolume = data.voxelVolume;
  m_Constants.elasticity = evaluator.Elasticity().empty() ? nullptr : Upload(evaluator.Elasticity(), m_Elasticity);
  if (!evaluator.Rigidity().Empty())
  {
    m_Constants.rigidWeights = Upload(evaluator.Rigidity().weights, m_RigidWeights);
    m_Constants.rigidInverseEdges = Upload(evaluator.Rigidity().inverseEdges, m_RigidInverseEdges);
    if (!evaluator.Rigidity().limitVolumes.empty())
    {
      m_Constants.rigidLimitVolumes = Upload(evaluator.Rigidity().limitVolumes, m_RigidLimitVolumes);
      m_Constants.rigidStrainLimitSquared = evaluator.Rigidity().strainLimitSquared;
    }
  }
  m_Constants.referenceVolumes = Upload(evaluator.Constraint().ReferenceVolumes(), m_ReferenceVolumes);
  m_Constants.tetrahedra = static_cast<std::uint32_t>(evaluator.Constraint().ReferenceVolumes().size());
  m_Constants.volumeFraction = evaluator.Constraint().VolumeFraction();
  // The texture path keeps each structure in textures of its own, up to
  // MaxTextureStructures; the packed exact kernel reads 4 channels per voxel
  // at once (intensity and up to 3 distances); the generic exact kernel
  // any number.
  const std::size_t structures = data.moving.channels > 0 ? data.moving.channels - 1 : 0; // what the textures hold
  const bool        texture =
    interpolation == CudaInterpolation::Texture && structures <= static_cast<std::size_t>(cuda::MaxTextureStructures);
  if (interpolation == CudaInterpolation::Texture && !texture)
    m_PathNote = "exact CUDA kernels instead of the texture path: " + std::to_string(structures) +
                 " guidance structures, the texture path reads at most " +
                 std::to_string(cuda::MaxTextureStructures);
  if (texture || data.moving.channels <= 4)
  {
    const CudaInterpolation packed = texture ? CudaInterpolation::Texture : CudaInterpolation::Exact;
    m_Constants.packed = true;
    m_Constants.interpolation = texture ? cuda::Interpolation::Texture : cuda::Interpolation::Exact;
    m_Constants.packedMoving = UploadPacked(data.moving, m_PackedMoving, m_MovingTextures, packed);
    m_Constants.packedFixed = UploadPacked(data.fixed, m_PackedFixed, m_FixedTextures, packed);
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

void
CudaEvaluationBackend::EvaluateSolutions(const std::vector<const DualMesh *> & solutions,
                                         const std::vector<std::vector<TetrahedronValues> *> & values)
{
  SelectDevice();
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

MemoryEstimate
CudaEvaluationBackend::MemoryFor(const RunShape & shape) const
{
  const double tetrahedra = static_cast<double>(shape.tetrahedra);
  const double solutionPoints = 6.0 * static_cast<double>(shape.points) * sizeof(double);
  // Per item of a flight (ReserveItems), on the device and pinned, and the
  // texture path's set-up workspace and chunk room (ChunkRoomPerItem).
  double itemDevice = cuda::ItemCorners * sizeof(double) + sizeof(std::uint32_t) + sizeof(std::uint8_t) +
                      (cuda::ItemValues + 2 * cuda::DirectionValues) * sizeof(double);
  const double itemPinned = (cuda::ItemValues + 2 * cuda::DirectionValues) * sizeof(double);
  if (UsesTexturePath())
  {
    // Per item and per chunk from a large count: the workspaces' parts are
    // aligned, and the sort's scratch is nearly linear.
    constexpr std::size_t many = std::size_t{ 1 } << 20;
    const ObjectiveData & data = m_Evaluator.Data();
    const double voxels = static_cast<double>(data.fixed.size[0]) * static_cast<double>(data.fixed.size[1]) *
                          static_cast<double>(data.fixed.size[2]);
    // Both directions sample about the domain's voxels times the rate.
    const double chunksPerItem =
      tetrahedra > 0.0 ? 2.0 + 2.0 * data.samplingRate * voxels / (tetrahedra * m_Constants.chunkSamples) : 0.0;
    itemDevice += static_cast<double>(cuda::TexturePrepareWorkspaceBytes(many)) / many +
                  std::max(FirstChunkRoomPerItem, ChunkRoomMargin * chunksPerItem) *
                    static_cast<double>(cuda::TextureChunkWorkspaceBytes(many)) / many;
  }
  // A candidate's staging on both sides: element, parent, first point,
  // first item, seeds, fold outcomes, sums and refusal bound.
  constexpr double candidateBytes = 3 * sizeof(std::uint32_t) + sizeof(std::uint64_t) + 2 * sizeof(std::uint64_t) +
                                    4 * sizeof(std::uint8_t) + cuda::CandidateSumValues * sizeof(double) +
                                    sizeof(cuda::CandidateBoundInput) + 2 * sizeof(std::uint32_t);
  const double batch = static_cast<double>(shape.groupElements) * candidateBytes +
                       static_cast<double>(shape.groupPoints) * 6.0 * sizeof(double);
  MemoryEstimate estimate;
  estimate.device = m_Device;
  // Two flights, the staged solutions, the parent store (it grows by half
  // again), and the batches in both flights.
  estimate.devicePerSolution = 2.0 * tetrahedra * itemDevice + solutionPoints + 1.5 * solutionPoints + 2.0 * batch;
  estimate.hostPerSolution = 2.0 * tetrahedra * itemPinned + solutionPoints + 2.0 * solutionPoints + 2.0 * batch;
  return estimate;
}

std::optional<double>
CudaEvaluationBackend::FreeDeviceMemory() const
{
  const std::size_t free = CudaFreeMemory(m_Device);
  if (free == 0) // unreadable: a full device still has a little
    return std::nullopt;
  return static_cast<double>(free);
}

void
CudaEvaluationBackend::SetFoldHandling(const FoldHandling & handling)
{
  SelectDevice();
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

void
CudaEvaluationBackend::EvaluatePartials(const std::vector<PartialCandidate> & candidates, const ReadyCandidates & ready,
                                        const Meanwhile & meanwhile)
{
  SelectDevice();
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
CudaEvaluationBackend::HoldStream(const std::atomic<bool> & release)
{
  SelectDevice();
  const auto wait = [](void * flag) {
    while (!static_cast<const std::atomic<bool> *>(flag)->load())
      std::this_thread::yield();
  };
  Check(cudaLaunchHostFunc(m_Stream->Get(), wait, const_cast<std::atomic<bool> *>(&release)), "holding the stream");
}

void
CudaEvaluationBackend::PrepareNextPartials(const std::vector<PartialCandidate> & next)
{
  SelectDevice();
  const auto start = std::chrono::steady_clock::now();
  HostCandidates & host = m_HostCandidates[1 - m_CurrentHost];
  PackCandidates(next, host);
  host.prepared = true;
  m_Statistics.stagingSeconds += SecondsSince(start);
}

void
CudaEvaluationBackend::StartNextPartials(const std::vector<PartialCandidate> & next, std::size_t head,
                                         const RefusalScreen * screen)
{
  SelectDevice();
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

void
CudaEvaluationBackend::FetchValues(const std::vector<PartialCandidate> & candidates,
                                   const std::vector<std::size_t> & which)
{
  SelectDevice();
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
CudaEvaluationBackend::SampleSkipped(const std::vector<PartialCandidate> & candidates,
                                     const std::vector<std::size_t> & which)
{
  SelectDevice();
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
  // Their samples count in `samples`, so their kernel's time counts too;
  // the part of it the batches' sampling covers is taken off again once
  // that is counted (AddKernelSeconds).
  m_Statistics.kernelSeconds += ElapsedSeconds(*m_FallbackStart, *m_FallbackEnd);
  if (m_FallbackFlight != &f)
  {
    m_FallbackIntervals.clear();
    m_FallbackFlight = &f;
  }
  m_FallbackIntervals.emplace_back(ElapsedSeconds(f.start, *m_FallbackStart), ElapsedSeconds(f.start, *m_FallbackEnd));
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
    m_Statistics.boundSampledLaterSamples += samples;
    m_Statistics.boundSkippedSamples -= samples;
  }
  m_Statistics.seconds += SecondsSince(start);
  m_Statistics.boundSampleLaterSeconds += SecondsSince(start);
  ++m_Statistics.boundSampleLaterCalls;
}

void
CudaEvaluationBackend::RunWhole(BatchFlight & f, std::size_t items)
{
  f.skipItems = false;
  f.scheduled = false; // whole solutions' items: sorted by tetrahedron
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

void
CudaEvaluationBackend::UnpackSolutions(const BatchFlight & f, std::size_t n,
                                       const std::vector<std::vector<TetrahedronValues> *> & values)
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

void
CudaEvaluationBackend::SelectDevice() const
{
  // The current device is per host thread: a backend called from another
  // thread than the one that made it still runs on its own device.
  Check(cudaSetDevice(m_Device), ("selecting CUDA device " + std::to_string(m_Device)).c_str());
}
} // namespace cudabackend

void
HoldCudaEvaluationStream(EvaluationBackend & backend, const std::atomic<bool> & release)
{
  auto * cuda = dynamic_cast<cudabackend::CudaEvaluationBackend *>(&backend);
  if (!cuda)
    throw Error("holding the evaluation stream: not the CUDA backend");
  cuda->HoldStream(release);
}

std::unique_ptr<EvaluationBackend>
CreateCudaEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads,
                            CudaInterpolation interpolation, int device)
{
  return std::make_unique<cudabackend::CudaEvaluationBackend>(evaluator, threads, interpolation, device);
}
} // namespace morea_core
