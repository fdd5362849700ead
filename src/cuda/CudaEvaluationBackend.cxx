// The CUDA evaluation backend: the same calls as the CPU backend
// (CpuEvaluationBackend.cxx), evaluated on the GPU. Images, distance maps,
// the mesh and per-tetrahedron constants are uploaded once. A batch of
// partial candidates (all candidates of a parallel group of a cluster) goes
// up as its parents' points, its elements and the moved points; the device
// builds every dependent tetrahedron's corners, evaluates all of them at once
// and the values come back: one host-device synchronisation per call.
#include "morea/EvaluationBackend.h"

#include "DeviceMemory.h"
#include "FoldRepairKernels.h"
#include "TetrahedronKernels.h"

#include "morea/ComputeDevices.h"
#include "morea/Error.h"
#include "morea/TetrahedronSampling.h"
#include "morea/ThreadPool.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <unordered_map>
#include <vector>

namespace morea
{
namespace
{
using cuda::Check;

/** The texture path's textures of one image. */
struct VolumeTextures
{
  std::unique_ptr<cuda::Texture3D> intensity, distance;
};

class CudaEvaluationBackend final : public EvaluationBackend
{
public:
  CudaEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads, CudaInterpolation interpolation)
    : m_Evaluator(evaluator)
    , m_Pool(threads)
  {
    const std::string unavailable = CudaUnavailableReason();
    if (!unavailable.empty())
      throw Error("CUDA backend: " + unavailable);
    Check(cudaSetDevice(0), "selecting device 0");
    m_Stream = std::make_unique<cuda::Stream>();
    m_KernelStart = std::make_unique<cuda::Event>();
    m_KernelEnd = std::make_unique<cuda::Event>();
    m_FoldStart = std::make_unique<cuda::Event>();
    m_FoldEnd = std::make_unique<cuda::Event>();
    m_HostChunks.Reserve(1);
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
    Reserve(solutions.size() * n);
    m_Pool.ParallelFor(solutions.size(), [&](std::size_t s) {
      for (std::size_t t = 0; t < n; ++t)
        Pack(s * n + t, static_cast<std::uint32_t>(t), CornersOf(tets[t], solutions[s]->source),
             CornersOf(tets[t], solutions[s]->target));
    });
    CopyCornersToDevice(solutions.size() * n);
    Run(solutions.size() * n);
    std::vector<std::size_t> first(solutions.size() + 1);
    for (std::size_t s = 0; s <= solutions.size(); ++s)
      first[s] = s * n;
    for (auto * v : values)
      v->resize(n);
    UnpackAll(first, [&](std::size_t s) { return values[s]->data(); });
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

  void
  EvaluatePartials(const std::vector<PartialCandidate> & candidates) override
  {
    const auto  start = std::chrono::steady_clock::now();
    const auto  items = UploadCandidates(candidates);
    const bool  checks = items > 0 && StageFoldChecks(candidates);
    if (checks)
      LaunchFoldChecks(candidates.size());
    if (items > 0)
    {
      Reserve(items);
      cuda::LaunchGatherCandidateCorners(m_Batch, items, m_Corners.Data(), m_Tetrahedra.Data(), m_Stream->Get());
    }
    Run(items);
    if (checks)
      ReadFoldChecks(candidates);
    else
      for (const PartialCandidate & c : candidates)
        if (c.folds)
          *c.folds = CandidateFolds{}; // no dependent tetrahedra, nothing checked
    std::vector<std::size_t> first(candidates.size() + 1, 0);
    for (std::size_t i = 0; i < candidates.size(); ++i)
      first[i + 1] = first[i] + candidates[i].element->dependentTetrahedra.size();
    UnpackAll(first, [&](std::size_t i) { return candidates[i].values; });
    m_Statistics.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

private:
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
      textures.intensity = std::make_unique<cuda::Texture3D>(
        intensity.data(), sizeof(std::uint16_t), cudaCreateChannelDesc<unsigned short>(), view.size);
      view.intensityTexture = static_cast<unsigned long long>(textures.intensity->Get());
      const std::size_t structures = volume.channels - 1;
      if (structures > 0)
      {
        const int          channels = structures == 1 ? 1 : (structures == 2 ? 2 : 4);
        // Padding channels hold a distance no radius reaches. (16-bit
        // normalised distance texels measured 11 % slower on an H100.)
        std::vector<float> distance(channels * voxels, 3.0e38f);
        for (std::size_t v = 0; v < voxels; ++v)
          for (std::size_t g = 0; g < structures; ++g)
            distance[channels * v + g] = volume.data[volume.channels * v + 1 + g];
        const cudaChannelFormatDesc format = cudaCreateChannelDesc(32, channels > 1 ? 32 : 0, channels > 2 ? 32 : 0,
                                                                   channels > 2 ? 32 : 0, cudaChannelFormatKindFloat);
        textures.distance =
          std::make_unique<cuda::Texture3D>(distance.data(), channels * sizeof(float), format, view.size);
        view.distanceTexture = static_cast<unsigned long long>(textures.distance->Get());
        view.distanceChannels = channels;
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

  /** Uploads the batch's parents (each once), elements (each once),
   *  candidate table and moved points; returns the number of items. */
  std::size_t
  UploadCandidates(const std::vector<PartialCandidate> & candidates)
  {
    std::unordered_map<const DualMesh *, std::uint32_t>   parentSlot;
    std::unordered_map<const FosElement *, std::uint32_t> elementSlot;
    std::vector<const DualMesh *>                         parents;
    std::vector<std::uint32_t> pointOffsets{ 0 }, points, tetrahedronOffsets{ 0 }, dependent;
    std::vector<std::uint32_t> candidateElement, candidateParent, candidateMoved;
    std::vector<std::uint64_t> firstItem{ 0 };
    std::vector<double>        moved;
    for (const PartialCandidate & c : candidates)
    {
      const auto p = parentSlot.emplace(c.parent, static_cast<std::uint32_t>(parents.size()));
      if (p.second)
        parents.push_back(c.parent);
      const auto e = elementSlot.emplace(c.element, static_cast<std::uint32_t>(pointOffsets.size() - 1));
      if (e.second)
      {
        points.insert(points.end(), c.element->points.begin(), c.element->points.end());
        pointOffsets.push_back(static_cast<std::uint32_t>(points.size()));
        dependent.insert(dependent.end(), c.element->dependentTetrahedra.begin(), c.element->dependentTetrahedra.end());
        tetrahedronOffsets.push_back(static_cast<std::uint32_t>(dependent.size()));
      }
      candidateElement.push_back(e.first->second);
      candidateParent.push_back(p.first->second);
      candidateMoved.push_back(static_cast<std::uint32_t>(moved.size() / 6));
      for (std::size_t k = 0; k < c.element->points.size(); ++k)
      {
        moved.insert(moved.end(), c.source[k].begin(), c.source[k].end());
        moved.insert(moved.end(), c.target[k].begin(), c.target[k].end());
      }
      firstItem.push_back(firstItem.back() + c.element->dependentTetrahedra.size());
    }
    const std::size_t items = firstItem.back();
    if (items == 0)
      return 0;
    const std::size_t perParent = 6 * static_cast<std::size_t>(m_Batch.points);
    m_HostParents.Reserve(parents.size() * perParent);
    m_Pool.ParallelFor(parents.size(), [&](std::size_t slot) {
      double * out = m_HostParents.Data() + slot * perParent;
      for (const Vec3 & v : parents[slot]->source)
        out = std::copy(v.begin(), v.end(), out);
      for (const Vec3 & v : parents[slot]->target)
        out = std::copy(v.begin(), v.end(), out);
    });
    m_Batch.parents = UploadAsync(m_HostParents.Data(), parents.size() * perParent, m_Parents);
    m_Batch.elementPointOffsets = StageAndUpload(pointOffsets, m_HostElementPointOffsets, m_ElementPointOffsets);
    m_Batch.elementPoints = StageAndUpload(points, m_HostElementPoints, m_ElementPoints);
    m_Batch.elementTetrahedronOffsets =
      StageAndUpload(tetrahedronOffsets, m_HostElementTetrahedronOffsets, m_ElementTetrahedronOffsets);
    m_Batch.elementTetrahedra = StageAndUpload(dependent, m_HostElementTetrahedra, m_ElementTetrahedra);
    m_Batch.candidateElement = StageAndUpload(candidateElement, m_HostCandidateElement, m_CandidateElement);
    m_Batch.candidateParent = StageAndUpload(candidateParent, m_HostCandidateParent, m_CandidateParent);
    m_Batch.candidateMoved = StageAndUpload(candidateMoved, m_HostCandidateMoved, m_CandidateMoved);
    m_Batch.candidateFirstItem = StageAndUpload(firstItem, m_HostFirstItem, m_FirstItem);
    m_Batch.moved = StageAndUpload(moved, m_HostMoved, m_Moved);
    m_MovedCount = moved.size();
    m_Batch.candidates = candidates.size();
    return items;
  }

  /** Stages which candidates are checked and their sides' seeds; false
   *  when no candidate of the batch asks for a check. */
  bool
  StageFoldChecks(const std::vector<PartialCandidate> & candidates)
  {
    if (!m_FoldHandling.constraint)
      return false;
    std::vector<std::uint8_t>  check(candidates.size(), 0);
    std::vector<std::uint64_t> seeds(2 * candidates.size(), 0);
    bool                       any = false;
    for (std::size_t i = 0; i < candidates.size(); ++i)
    {
      const PartialCandidate & c = candidates[i];
      if (!c.folds)
        continue;
      if (c.element->points.size() > cuda::MaxRepairElementPoints)
        throw Error("CUDA backend: fold checks handle elements of up to " +
                    std::to_string(cuda::MaxRepairElementPoints) + " points, not " +
                    std::to_string(c.element->points.size()));
      check[i] = 1;
      seeds[2 * i] = RepairSeed(c.seed, 0);
      seeds[2 * i + 1] = RepairSeed(c.seed, 1);
      any = true;
    }
    if (!any)
      return false;
    m_FoldCheck = StageAndUpload(check, m_HostFoldCheck, m_FoldCheckDevice);
    m_SideSeeds = StageAndUpload(seeds, m_HostSideSeeds, m_SideSeedsDevice);
    return true;
  }

  /** The fold kernel, then its outcome and the repaired points back to the
   *  host on the stream (read after the evaluation's synchronisation). */
  void
  LaunchFoldChecks(std::size_t candidates)
  {
    cudaStream_t stream = m_Stream->Get();
    m_Outcome.Reserve(2 * candidates);
    m_HostOutcome.Reserve(2 * candidates);
    Check(cudaEventRecord(m_FoldStart->Get(), stream), "recording an event");
    cuda::LaunchCheckCandidateFolds(m_Batch, m_Folds, m_FoldCheck, m_SideSeeds, m_Moved.Data(), m_Outcome.Data(),
                                    stream);
    Check(cudaEventRecord(m_FoldEnd->Get(), stream), "recording an event");
    Check(cudaMemcpyAsync(m_HostOutcome.Data(), m_Outcome.Data(), 2 * candidates, cudaMemcpyDeviceToHost, stream),
          "copying fold checks from the device");
    if (m_Folds.repair)
      Check(cudaMemcpyAsync(m_HostMoved.Data(), m_Moved.Data(), m_MovedCount * sizeof(double),
                            cudaMemcpyDeviceToHost, stream),
            "copying repaired points from the device");
  }

  void
  ReadFoldChecks(const std::vector<PartialCandidate> & candidates)
  {
    float milliseconds = 0.0f;
    Check(cudaEventElapsedTime(&milliseconds, m_FoldStart->Get(), m_FoldEnd->Get()), "reading an event");
    m_Statistics.foldSeconds += 1e-3 * milliseconds;
    for (std::size_t i = 0; i < candidates.size(); ++i)
    {
      const PartialCandidate & c = candidates[i];
      if (!c.folds)
        continue;
      CandidateFolds folds;
      for (int side = 0; side < 2; ++side)
      {
        const std::uint8_t outcome = m_HostOutcome[2 * i + side];
        if (!(outcome & cuda::SideFolded))
          continue;
        ++folds.foldedSides;
        folds.repairedSides += (outcome & cuda::SideRepaired) ? 1 : 0;
        if (!m_Folds.repair)
          continue;
        Vec3 *         out = side == 0 ? c.source : c.target;
        const double * in = m_HostMoved.Data() + 6 * static_cast<std::size_t>(m_HostCandidateMoved[i]) + 3 * side;
        for (std::size_t k = 0; k < c.element->points.size(); ++k)
          for (int a = 0; a < 3; ++a)
            out[k][a] = in[6 * k + a];
      }
      *c.folds = folds;
    }
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

  void
  CopyCornersToDevice(std::size_t items)
  {
    if (items == 0)
      return;
    cudaStream_t stream = m_Stream->Get();
    Check(cudaMemcpyAsync(m_Corners.Data(), m_HostCorners.Data(), items * cuda::ItemCorners * sizeof(double),
                          cudaMemcpyHostToDevice, stream),
          "copying corners to the device");
    Check(cudaMemcpyAsync(m_Tetrahedra.Data(), m_HostTetrahedra.Data(), items * sizeof(std::uint32_t),
                          cudaMemcpyHostToDevice, stream),
          "copying tetrahedron indices to the device");
  }

  void
  Reserve(std::size_t items)
  {
    m_HostCorners.Reserve(items * cuda::ItemCorners);
    m_HostTetrahedra.Reserve(items);
    m_HostItemValues.Reserve(items * cuda::ItemValues);
    m_HostDirectionValues.Reserve(items * 2 * cuda::DirectionValues);
    m_Corners.Reserve(items * cuda::ItemCorners);
    m_Tetrahedra.Reserve(items);
    m_ItemValues.Reserve(items * cuda::ItemValues);
    m_DirectionValues.Reserve(items * 2 * cuda::DirectionValues);
    if (UsesTexturePath())
      m_Workspace.Reserve(cuda::TexturePrepareWorkspaceBytes(items));
  }

  void
  Pack(std::size_t item, std::uint32_t t, const Corners & source, const Corners & target) const
  {
    double * c = m_HostCorners.Data() + item * cuda::ItemCorners;
    for (int i = 0; i < 4; ++i)
      for (int a = 0; a < 3; ++a)
      {
        c[3 * i + a] = source[i][a];
        c[12 + 3 * i + a] = target[i][a];
      }
    m_HostTetrahedra[item] = t;
  }

  TetrahedronValues
  Unpack(std::size_t item) const
  {
    const double *    v = m_HostItemValues.Data() + item * cuda::ItemValues;
    const double *    d = m_HostDirectionValues.Data() + item * 2 * cuda::DirectionValues;
    TetrahedronValues out;
    out.magnitude = v[0];
    out.foldValue = v[1];
    out.folded = v[2];
    out.intensity = d[0] + d[3];
    out.guidance = d[1] + d[4];
    out.samples = d[2] + d[5];
    return out;
  }

  void
  Run(std::size_t items)
  {
    if (items == 0)
      return;
    cudaStream_t stream = m_Stream->Get();
    Check(cudaEventRecord(m_KernelStart->Get(), stream), "recording an event");
    if (UsesTexturePath())
    {
      // Step 1 tells how many chunks step 2 has: one synchronisation.
      cuda::LaunchPrepareTexture(m_Constants, m_Corners.Data(), m_Tetrahedra.Data(), items, m_Workspace.Data(),
                                 m_ItemValues.Data(), m_HostChunks.Data(), stream);
      Check(cudaStreamSynchronize(stream), "preparing the texture sampling");
      const std::size_t chunks = m_HostChunks[0];
      m_ChunkWorkspace.Reserve(cuda::TextureChunkWorkspaceBytes(chunks));
      cuda::LaunchSampleTexture(m_Constants, items, m_Workspace.Data(), chunks, m_ChunkWorkspace.Data(),
                                m_DirectionValues.Data(), stream);
    }
    else
      cuda::LaunchEvaluateTetrahedra(m_Constants, m_Corners.Data(), m_Tetrahedra.Data(), items, m_ItemValues.Data(),
                                     m_DirectionValues.Data(), stream);
    Check(cudaEventRecord(m_KernelEnd->Get(), stream), "recording an event");
    Check(cudaMemcpyAsync(m_HostItemValues.Data(), m_ItemValues.Data(), items * cuda::ItemValues * sizeof(double),
                          cudaMemcpyDeviceToHost, stream),
          "copying values from the device");
    Check(cudaMemcpyAsync(m_HostDirectionValues.Data(), m_DirectionValues.Data(),
                          items * 2 * cuda::DirectionValues * sizeof(double), cudaMemcpyDeviceToHost, stream),
          "copying values from the device");
    Check(cudaStreamSynchronize(stream), "evaluating tetrahedra");
    float milliseconds = 0.0f;
    Check(cudaEventElapsedTime(&milliseconds, m_KernelStart->Get(), m_KernelEnd->Get()), "reading an event");
    m_Statistics.kernelSeconds += 1e-3 * milliseconds;
    ++m_Statistics.batches;
    m_Statistics.tetrahedra += items;
  }

  /** Unpacks items [first[i], first[i + 1]) into out(i) for every i on the
   *  pool, counting the samples on the way. */
  template <typename Output>
  void
  UnpackAll(const std::vector<std::size_t> & first, Output out)
  {
    const std::size_t   groups = first.size() - 1;
    std::vector<double> samples(groups, 0.0);
    m_Pool.ParallelFor(groups, [&](std::size_t i) {
      TetrahedronValues * o = out(i);
      for (std::size_t item = first[i]; item < first[i + 1]; ++item)
      {
        *o = Unpack(item);
        samples[i] += o->samples;
        ++o;
      }
    });
    for (double v : samples)
      m_Statistics.samples += v;
  }

  const TetrahedronEvaluator &  m_Evaluator;
  ThreadPool                    m_Pool;
  std::unique_ptr<cuda::Stream> m_Stream;
  std::unique_ptr<cuda::Event>  m_KernelStart, m_KernelEnd, m_FoldStart, m_FoldEnd;
  cuda::EvaluationConstants     m_Constants;
  cuda::DeviceArray<float>      m_Moving, m_Fixed, m_PackedMoving, m_PackedFixed;
  VolumeTextures m_MovingTextures, m_FixedTextures;
  cuda::DeviceArray<double>     m_GuidanceWeights, m_Elasticity, m_ReferenceVolumes;
  cuda::DeviceArray<double>     m_Corners, m_ItemValues, m_DirectionValues;
  cuda::DeviceArray<std::uint32_t> m_Tetrahedra;
  cuda::PinnedArray<double>        m_HostCorners, m_HostItemValues, m_HostDirectionValues;
  cuda::PinnedArray<std::uint32_t> m_HostTetrahedra;
  cuda::DeviceArray<unsigned char> m_Workspace, m_ChunkWorkspace;
  cuda::PinnedArray<std::uint32_t> m_HostChunks; ///< step 1's number of chunks
  // Partial candidates: the mesh once, then per batch (device and staging).
  cuda::CandidateBatch             m_Batch;
  cuda::DeviceArray<std::uint32_t> m_Mesh, m_ElementPointOffsets, m_ElementPoints, m_ElementTetrahedronOffsets,
    m_ElementTetrahedra, m_CandidateElement, m_CandidateParent, m_CandidateMoved;
  cuda::DeviceArray<std::uint64_t> m_FirstItem;
  cuda::DeviceArray<double>        m_Parents, m_Moved;
  cuda::PinnedArray<std::uint32_t> m_HostElementPointOffsets, m_HostElementPoints, m_HostElementTetrahedronOffsets,
    m_HostElementTetrahedra, m_HostCandidateElement, m_HostCandidateParent, m_HostCandidateMoved;
  cuda::PinnedArray<std::uint64_t> m_HostFirstItem;
  cuda::PinnedArray<double>        m_HostParents, m_HostMoved;
  std::size_t                      m_MovedCount{ 0 };
  // Fold checks: the constraint once (SetFoldHandling), then per batch.
  cuda::FoldRepairConstants        m_Folds;
  cuda::DeviceArray<double>        m_FoldReferenceVolumes;
  cuda::DeviceArray<std::uint32_t> m_PointTetrahedronOffsets, m_PointTetrahedra;
  cuda::DeviceArray<std::int8_t>   m_Pins;
  const std::uint8_t *             m_FoldCheck{ nullptr };
  const std::uint64_t *            m_SideSeeds{ nullptr };
  cuda::DeviceArray<std::uint8_t>  m_FoldCheckDevice, m_Outcome;
  cuda::DeviceArray<std::uint64_t> m_SideSeedsDevice;
  cuda::PinnedArray<std::uint8_t>  m_HostFoldCheck, m_HostOutcome;
  cuda::PinnedArray<std::uint64_t> m_HostSideSeeds;
};
} // namespace

std::unique_ptr<EvaluationBackend>
CreateCudaEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads,
                            CudaInterpolation interpolation)
{
  return std::make_unique<CudaEvaluationBackend>(evaluator, threads, interpolation);
}
} // namespace morea
