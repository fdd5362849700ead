// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The CUDA backend's images and batches on their way up: the volumes and
// their textures, a batch's candidates packed on the host, its tables,
// parents and ranges uploaded and queued, and its refusal screen.
#include "CudaEvaluationBackend.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace morea_core
{
namespace cudabackend
{
bool
CudaEvaluationBackend::ScreenRange(const std::vector<PartialCandidate> & candidates, BatchFlight & f,
                                   const cuda::CandidateBatch & range)
{
  if (!f.hasScreen)
    return false;
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
    return false;
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
  f.screened = true;
  return true;
}

cuda::VolumeView
CudaEvaluationBackend::Upload(const ChannelVolume & volume, cuda::DeviceArray<float> & device)
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
CudaEvaluationBackend::UploadPacked(const ChannelVolume & volume, cuda::DeviceArray<float> & device,
                                    VolumeTextures & textures,
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
                  std::to_string(maxLayers - 1) +
                  " slices); use --backend cuda-exact (the exact CUDA kernels), or a coarser preprocessing spacing");
    const int  layers[3] = { view.size[0], view.size[1], depth + 1 };
    const auto slicePairs = [&](const std::vector<std::uint16_t> & texels) {
      std::vector<std::uint16_t> pairs(2 * slice * (depth + 1));
      for (int l = 0; l <= depth; ++l)
      {
        const std::uint16_t * below = texels.data() + std::max(l - 1, 0) * slice;
        const std::uint16_t * above = texels.data() + std::min(l, depth - 1) * slice;
        std::uint16_t *       out = pairs.data() + 2 * slice * l;
        for (std::size_t v = 0; v < slice; ++v)
        {
          out[2 * v] = below[v];
          out[2 * v + 1] = above[v];
        }
      }
      return std::make_unique<cuda::Texture3D>(pairs.data(), 2 * sizeof(std::uint16_t),
                                               cudaCreateChannelDesc<ushort2>(), layers, cuda::TextureLayout::Layers);
    };
    textures.intensity = slicePairs(intensity);
    view.intensityTexture = static_cast<unsigned long long>(textures.intensity->Get());
    const std::size_t structures = volume.channels - 1;
    if (structures > static_cast<std::size_t>(cuda::MaxTextureStructures))
      throw Error("CUDA backend: the texture path reads at most " + std::to_string(cuda::MaxTextureStructures) +
                  " guidance structures, not " + std::to_string(structures));
    if (structures > 0)
    {
      // Per structure its 16-bit slice pairs for the sampling kernel (as a
      // 16-bit normalised 3D texture, one that took two filtering passes,
      // they measured 11 % slower on an H100; as slice pairs, 2 % faster),
      // and for the set-up kernel one float map of the smallest distance
      // over all of them.
      std::vector<float> distance(voxels), nearest(voxels, std::numeric_limits<float>::infinity());
      double             quantum = 0.0;
      for (std::size_t g = 0; g < structures; ++g)
      {
        float largest = 0.0f;
        for (std::size_t v = 0; v < voxels; ++v)
        {
          distance[v] = volume.data[volume.channels * v + 1 + g];
          nearest[v] = std::min(nearest[v], distance[v]);
          largest = std::max(largest, distance[v]);
        }
        // The sampling kernel's copy: 16-bit steps of the largest distance.
        const float                scale = std::max(largest, 1e-6f);
        std::vector<std::uint16_t> steps(voxels);
        for (std::size_t v = 0; v < voxels; ++v)
          steps[v] = static_cast<std::uint16_t>(std::lround(std::clamp(distance[v] / scale, 0.0f, 1.0f) * 65535.0f));
        textures.distancePairs[g] = slicePairs(steps);
        view.distancePairTextures[g] = static_cast<unsigned long long>(textures.distancePairs[g]->Get());
        view.distanceScales[g] = scale;
        quantum = std::max(quantum, static_cast<double>(scale) / 65535.0);
      }
      textures.nearestDistance =
        std::make_unique<cuda::Texture3D>(nearest.data(), sizeof(float), cudaCreateChannelDesc<float>(), view.size);
      view.nearestDistanceTexture = static_cast<unsigned long long>(textures.nearestDistance->Get());
      view.distanceMaps = static_cast<int>(structures);
      // A rounded texel is at most half a step below its distance.
      const NearContourBlocks near = FindNearContourBlocks(volume, m_Constants.guidanceRadius + quantum);
      // As few bits per block as hold the structures (cuda::NearBlockBits),
      // so that the mask stays small enough for L1.
      const int                 bits = cuda::NearBlockBits(static_cast<int>(structures));
      std::vector<std::uint8_t> mask((near.mask.size() * static_cast<std::size_t>(bits) + 7) / 8, 0);
      for (std::size_t b = 0; b < near.mask.size(); ++b)
      {
        const std::uint32_t m = near.mask[b];
        if (bits == 4)
          mask[b / 2] |= static_cast<std::uint8_t>((m & 0x0fu) << (4 * (b % 2)));
        else if (bits == 8)
          mask[b] = static_cast<std::uint8_t>(m);
        else
        {
          mask[2 * b] = static_cast<std::uint8_t>(m & 0xffu);
          mask[2 * b + 1] = static_cast<std::uint8_t>(m >> 8);
        }
      }
      textures.nearBlocks.Reserve(mask.size());
      Check(cudaMemcpy(textures.nearBlocks.Data(), mask.data(), mask.size(), cudaMemcpyHostToDevice),
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

void
CudaEvaluationBackend::PackCandidates(const std::vector<PartialCandidate> & candidates, HostCandidates & h)
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

bool
CudaEvaluationBackend::UploadTables(const std::vector<PartialCandidate> & candidates, HostCandidates & h,
                                    cuda::Event & staged)
{
  const std::size_t n = candidates.size();
  const bool        checks = m_FoldHandling.constraint && h.anyChecked;
  if (checks && h.largestChecked > cuda::MaxRepairElementPoints)
    throw Error("CUDA backend: fold checks handle elements of up to " + std::to_string(cuda::MaxRepairElementPoints) +
                " points, not " + std::to_string(h.largestChecked));
  Check(cudaEventRecord(staged.Get(), m_Stream->Get()), "recording an event");
  m_ParentKeys.assign(h.parents.size(), 0);
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
    m_SkipIfFoldedDevice.Reserve(n);
    m_SkipIfFolded = m_SkipIfFoldedDevice.Data();
  }
  return checks;
}

void
CudaEvaluationBackend::UploadRange(const std::vector<PartialCandidate> & candidates, HostCandidates & h,
                                   BatchFlight & f,
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
    f.hostCandidateSlot[i] = m_ParentSlot[h.candidateParent[i]];
  const std::vector<const DualMesh *> parents(h.parents.begin() + static_cast<std::ptrdiff_t>(pBegin),
                                              h.parents.begin() + static_cast<std::ptrdiff_t>(pEnd));
  UploadParents(parents, slots, m_ParentStaging[begin == 0 ? 0 : 1]);
  cudaStream_t stream = m_Stream->Get();
  Check(cudaMemcpyAsync(m_CandidateParent.Data() + begin, f.hostCandidateSlot.Data() + begin,
                        (end - begin) * sizeof(std::uint32_t), cudaMemcpyHostToDevice, stream),
        "copying a batch to the device");
  if (!checks)
    return;
  m_Pool->ParallelFor(end - begin, [&](std::size_t k) {
    const PartialCandidate & c = candidates[begin + k];
    f.hostSkipIfFolded[begin + k] = c.folds && !c.evaluateFolded ? 1 : 0;
  });
  Check(cudaMemcpyAsync(m_SkipIfFoldedDevice.Data() + begin, f.hostSkipIfFolded.Data() + begin, end - begin,
                        cudaMemcpyHostToDevice, stream),
        "copying a batch to the device");
}

void
CudaEvaluationBackend::UploadParents(const std::vector<const DualMesh *> & parents,
                                     const ParentSlots::Assignment & slots,
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

void
CudaEvaluationBackend::ReserveItems(BatchFlight & f, std::size_t items)
{
  f.corners.Reserve(items * cuda::ItemCorners);
  f.tetrahedra.Reserve(items);
  f.itemSkip.Reserve(items);
  f.itemValues.Reserve(items * cuda::ItemValues);
  f.directionValues.Reserve(items * 2 * cuda::DirectionValues);
  f.hostItemValues.Reserve(items * cuda::ItemValues);
  f.hostDirectionValues.Reserve(items * 2 * cuda::DirectionValues);
}

void
CudaEvaluationBackend::BeginFlight(const std::vector<PartialCandidate> & candidates, HostCandidates & h,
                                   BatchFlight & f,
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
  f.scheduled = UsesTexturePath() && f.items > 0;
  if (f.scheduled)
  {
    f.hostSchedule.Reserve(2 * n);
    f.schedule.Reserve(2 * n);
  }
  f.hostCandidateSlot.Reserve(std::max<std::size_t>(1, n));
  if (f.checks)
  {
    f.outcome.Reserve(2 * n);
    f.hostOutcome.Reserve(2 * n);
    f.hostSkipIfFolded.Reserve(n);
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

void
CudaEvaluationBackend::QueueRange(const std::vector<PartialCandidate> & candidates, HostCandidates & h,
                                  BatchFlight & f, std::size_t begin,
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
    f.refusalOnDevice[p] = 0;
    if (f.items > 0)
    {
      cuda::CandidateBatch part = m_Batch;
      part.firstCandidate = f.candidateBounds[p];
      part.candidates = f.candidateBounds[p + 1];
      cuda::LaunchGatherCandidateCorners(part, f.items, skip, f.corners.Data(), f.tetrahedra.Data(),
                                         f.itemSkip.Data(), stream);
      f.refusalOnDevice[p] = ScreenRange(candidates, f, part) ? 1 : 0;
    }
    if (f.scheduled)
      ScheduleItems(h, f, p);
    PreparePart(f, p);
    SamplePart(f, p);
  }
  f.sampledParts = f.Parts();
}
} // namespace cudabackend
} // namespace morea_core
