// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The CUDA backend's batches on the device, part by part: fold checks and
// their outcome, the sampling's set-up and kernels, and the values and sums
// handed back as each part ends.
#include "CudaEvaluationBackend.h"

namespace morea_core
{
namespace cudabackend
{
void
CudaEvaluationBackend::CheckPartFolds(HostCandidates & h, BatchFlight & f, std::size_t r, std::size_t p)
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

void
CudaEvaluationBackend::CheckStartedHead(const std::vector<PartialCandidate> & candidates, const HostCandidates & h,
                                        const BatchFlight & f,
                                        std::size_t head) const
{
  for (std::size_t i = 0; i < head; ++i)
  {
    const PartialCandidate & c = candidates[i];
    if (c.parentKey != m_ParentKeys[h.candidateParent[i]] ||
        (f.checks && f.hostSkipIfFolded[i] != (c.folds && !c.evaluateFolded ? 1 : 0)))
      throw Error("evaluation backend: candidates started early changed before their evaluation");
  }
}

void
CudaEvaluationBackend::CopyFoldChecksBack(HostCandidates & h, BatchFlight & f, std::size_t p)
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

void
CudaEvaluationBackend::ReadFoldChecks(const std::vector<PartialCandidate> & candidates, const HostCandidates & h,
                                      BatchFlight & f,
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

void
CudaEvaluationBackend::AddDevicePhases(const BatchFlight & f)
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

void
CudaEvaluationBackend::ReservePart(BatchFlight & f, std::size_t p)
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
  if (f.refusalOnDevice.size() < p + 1)
    f.refusalOnDevice.resize(p + 1, 0);
}

void
CudaEvaluationBackend::PreparePart(BatchFlight & f, std::size_t p)
{
  f.hostChunks[p] = 0; // stays 0 for a part without items
  if (!UsesTexturePath())
    return;
  cudaStream_t      stream = m_Stream->Get();
  const std::size_t begin = f.itemBounds[p], count = f.itemBounds[p + 1] - begin;
  f.workspaces[p]->Reserve(std::max<std::size_t>(1, cuda::TexturePrepareWorkspaceBytes(count)));
  cuda::ItemSchedule schedule;
  if (f.scheduled)
  {
    schedule.slots = f.schedule.Data();
    schedule.candidateFirstItem = m_Batch.candidateFirstItem;
    schedule.firstCandidate = f.candidateBounds[p];
    schedule.endCandidate = f.candidateBounds[p + 1];
    schedule.partFirstItem = begin;
  }
  Check(cudaEventRecord(f.PartEvent(p, BatchFlight::SetUpStart), stream), "recording an event");
  cuda::LaunchPrepareTexture(m_Constants, f.corners.Data() + begin * cuda::ItemCorners, f.tetrahedra.Data() + begin,
                             f.skipItems ? f.itemSkip.Data() + begin : nullptr, count, schedule,
                             f.workspaces[p]->Data(), f.itemValues.Data() + begin * cuda::ItemValues, stream);
  Check(cudaEventRecord(f.PartEvent(p, BatchFlight::SetUpEnd), stream), "recording an event");
}

void
CudaEvaluationBackend::ScheduleItems(const HostCandidates & h, BatchFlight & f, std::size_t p)
{
  // Each element's tetrahedra in turn, all of the part's candidates of
  // that element at one tetrahedron together: the order a stable sort by
  // tetrahedron gives where no tetrahedron depends on two of the part's
  // elements (a parallel group's), so that the warps running at one time
  // read the same places of both images (see PrepareWorkspace).
  const std::size_t begin = f.candidateBounds[p], end = f.candidateBounds[p + 1];
  m_SlotGroup.assign(h.pointOffsets.size() - 1, ~std::uint32_t{ 0 }); // per element slot
  m_ScheduleGroups.clear();
  for (std::size_t c = begin; c < end; ++c)
  {
    std::uint32_t & group = m_SlotGroup[h.candidateElement[c]];
    if (group == ~std::uint32_t{ 0 })
    {
      group = static_cast<std::uint32_t>(m_ScheduleGroups.size());
      m_ScheduleGroups.push_back({ 0, static_cast<std::uint32_t>(h.firstItem[c + 1] - h.firstItem[c]), 0 });
    }
    ++m_ScheduleGroups[group].candidates;
  }
  std::uint32_t place = 0;
  for (ScheduleGroup & g : m_ScheduleGroups)
  {
    g.next = place;
    place += g.candidates * g.items;
  }
  std::uint32_t * out = f.hostSchedule.Data();
  for (std::size_t c = begin; c < end; ++c)
  {
    ScheduleGroup & g = m_ScheduleGroups[m_SlotGroup[h.candidateElement[c]]];
    out[2 * c] = g.next++;
    out[2 * c + 1] = g.candidates;
  }
  if (end > begin)
    Check(cudaMemcpyAsync(f.schedule.Data() + 2 * begin, out + 2 * begin, 2 * (end - begin) * sizeof(std::uint32_t),
                          cudaMemcpyHostToDevice, m_Stream->Get()),
          "copying the sampling order to the device");
}

void
CudaEvaluationBackend::SamplePart(BatchFlight & f, std::size_t p)
{
  cudaStream_t      stream = m_Stream->Get(), copies = m_CopyStream->Get();
  const std::size_t begin = f.itemBounds[p], count = f.itemBounds[p + 1] - begin;
  double *          itemValues = f.itemValues.Data() + begin * cuda::ItemValues;
  double *          directionValues = f.directionValues.Data() + begin * 2 * cuda::DirectionValues;
  if (UsesTexturePath())
  {
    const auto capacity = static_cast<std::size_t>(std::ceil(ChunkRoomPerItem() * static_cast<double>(count))) + 1024;
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
  // Read with the sums (CompleteOverflowingPart). On the sampling stream
  // this copy waited behind the previous parts' values, and the sampling
  // with it: 57 ms in 20 early generations on an H100.
  if (UsesTexturePath())
    cuda::CopyTextureChunkCount(count, f.workspaces[p]->Data(), f.hostChunks.Data() + p, copies);
  // Read with the sums too (Deliver); on the sampling stream the copy
  // stalled it the same way.
  if (f.refusalOnDevice[p] && endCandidate > firstCandidate)
    Check(cudaMemcpyAsync(f.hostRefusal.Data() + firstCandidate, f.refusal.Data() + firstCandidate,
                          (endCandidate - firstCandidate) * sizeof(std::uint32_t), cudaMemcpyDeviceToHost, copies),
          "copying the refusal screen from the device");
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

void
CudaEvaluationBackend::QueueSampling(BatchFlight & f)
{
  for (std::size_t p = f.sampledParts; p < f.Parts(); ++p)
    SamplePart(f, p);
  f.sampledParts = f.Parts();
  Check(cudaEventRecord(f.end.Get(), m_Stream->Get()), "recording an event");
}

void
CudaEvaluationBackend::CompleteOverflowingPart(BatchFlight & f, std::size_t p, const std::uint64_t * first)
{
  if (!UsesTexturePath())
    return;
  const std::size_t begin = f.itemBounds[p], count = f.itemBounds[p + 1] - begin;
  const std::size_t chunks = f.hostChunks[p];
  // The room follows the most seen, below the first guess too: with the
  // paper's configuration on the abdominal pair, parts held about 2.9 chunks
  // per item, and a room of 6 left half of the sampling grid's blocks
  // without a chunk.
  if (count > 0)
    m_MostChunksPerItem = std::max(m_MostChunksPerItem, static_cast<double>(chunks) / static_cast<double>(count));
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

void
CudaEvaluationBackend::WaitForValues(BatchFlight & f, std::size_t parts)
{
  if (parts > f.partsWithValues)
  {
    WaitFor(f.copiedEvents[parts - 1]->Get(), "copying values from the device");
    f.partsWithValues = parts;
  }
}

void
CudaEvaluationBackend::WaitForCandidateValues(BatchFlight & f, const std::vector<std::size_t> & which)
{
  std::size_t parts = 0;
  for (std::size_t i : which)
  {
    const auto bound = std::upper_bound(f.candidateBounds.begin(), f.candidateBounds.end(), i);
    parts = std::max(parts, static_cast<std::size_t>(bound - f.candidateBounds.begin()));
  }
  WaitForValues(f, std::min(parts, f.Parts()));
}

void
CudaEvaluationBackend::Deliver(const std::vector<PartialCandidate> & candidates, const HostCandidates & h,
                               BatchFlight & f,
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
    {
      m_Statistics.devicePhases.betweenBatches += ElapsedSeconds(m_PreviousFlight->end, f.start);
      RebaseFallbackIntervals(f);
    }
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
CudaEvaluationBackend::RebaseFallbackIntervals(const BatchFlight & f)
{
  if (m_FallbackIntervals.empty() || m_FallbackFlight == &f)
    return;
  if (m_FallbackFlight != m_PreviousFlight) // its start may be another batch's by now
  {
    m_FallbackIntervals.clear();
    m_FallbackFlight = nullptr;
    return;
  }
  const double shift = ElapsedSeconds(m_FallbackFlight->start, f.start);
  for (auto & interval : m_FallbackIntervals)
  {
    interval.first -= shift;
    interval.second -= shift;
  }
  m_FallbackFlight = &f;
}

void
CudaEvaluationBackend::AddKernelSeconds(const BatchFlight & f)
{
  // Each span as seconds after the flight's start. The parts' spans follow
  // one another on one stream, the fallback's on another: the overlap of
  // the two unions is the sum of the pairwise overlaps.
  const bool overlaps = m_FallbackFlight == &f && !m_FallbackIntervals.empty();
  double     last = 0.0, overlap = 0.0;
  const auto add = [&](BatchFlight::PartStep from, BatchFlight::PartStep to, std::size_t p) {
    const double span = ElapsedSeconds(f.PartEvent(p, from), f.PartEvent(p, to));
    m_Statistics.kernelSeconds += span;
    if (overlaps) // (a whole evaluation's flight has no start event)
    {
      const double a = ElapsedSeconds(f.start.Get(), f.PartEvent(p, from)), b = a + span;
      for (const auto & interval : m_FallbackIntervals)
        overlap += std::max(0.0, std::min(b, interval.second) - std::max(a, interval.first));
      last = std::max(last, b);
    }
    return span;
  };
  for (std::size_t p = 0; p < f.Parts(); ++p)
  {
    if (UsesTexturePath())
      m_Statistics.setUpKernelSeconds += add(BatchFlight::SetUpStart, BatchFlight::SetUpEnd, p);
    add(BatchFlight::SamplingStart, BatchFlight::SamplingEnd, p);
  }
  m_Statistics.kernelSeconds -= overlap;
  // Spans that end after this flight's sampling may overlap the next one's.
  if (overlaps)
    m_FallbackIntervals.erase(std::remove_if(m_FallbackIntervals.begin(), m_FallbackIntervals.end(),
                                             [last](const auto & interval) { return interval.second <= last; }),
                              m_FallbackIntervals.end());
}

std::uint64_t
CudaEvaluationBackend::UnpackSums(const std::vector<PartialCandidate> & candidates, const BatchFlight & f,
                                  const std::uint64_t * first,
                                  std::size_t begin, std::size_t end, const std::uint32_t * spared,
                                  const std::vector<std::uint64_t> & witnesses)
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
} // namespace cudabackend
} // namespace morea_core
