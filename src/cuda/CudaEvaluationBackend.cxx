// The CUDA evaluation backend: the same calls as the CPU backend
// (CpuEvaluationBackend.cxx), evaluated on the GPU. Images, distance maps
// and per-tetrahedron constants are uploaded once; each call packs the
// corners of every tetrahedron to evaluate, runs one kernel over all of them
// (all candidates of a parallel group of a cluster at once) and copies the
// values back: one host-device synchronisation per call.
#include "morea/EvaluationBackend.h"

#include "DeviceMemory.h"
#include "TetrahedronKernels.h"

#include "morea/ComputeDevices.h"
#include "morea/Error.h"
#include "morea/TetrahedronSampling.h"
#include "morea/ThreadPool.h"

#include <algorithm>
#include <vector>
#include <chrono>

namespace morea
{
namespace
{
using cuda::Check;

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
    cuda::UploadSobolDirections(SobolDirectionNumbers());

    const ObjectiveData & data = evaluator.Data();
    m_Constants.structures = static_cast<int>(data.NumberOfGuidanceStructures());
    m_Constants.guidanceWeights = Upload(data.guidanceWeights, m_GuidanceWeights);
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
      m_Constants.packedMoving = UploadPacked(data.moving, m_PackedMoving, m_MovingTexture, interpolation);
      m_Constants.packedFixed = UploadPacked(data.fixed, m_PackedFixed, m_FixedTexture, interpolation);
    }
    else
    {
      m_Constants.moving = Upload(data.moving, m_Moving);
      m_Constants.fixed = Upload(data.fixed, m_Fixed);
    }
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
    Run(solutions.size() * n);
    m_Pool.ParallelFor(solutions.size(), [&](std::size_t s) {
      values[s]->resize(n);
      for (std::size_t t = 0; t < n; ++t)
        (*values[s])[t] = Unpack(s * n + t);
    });
    m_Statistics.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  void
  EvaluatePartials(const std::vector<PartialCandidate> & candidates) override
  {
    const auto               start = std::chrono::steady_clock::now();
    const auto &             tets = m_Evaluator.Topology().Tetrahedra();
    std::vector<std::size_t> first(candidates.size() + 1, 0);
    for (std::size_t i = 0; i < candidates.size(); ++i)
      first[i + 1] = first[i] + candidates[i].element->dependentTetrahedra.size();
    const std::size_t items = first.back();
    Reserve(items);
    m_Pool.ParallelFor(candidates.size(), [&](std::size_t i) {
      const PartialCandidate & c = candidates[i];
      const auto &             dependent = c.element->dependentTetrahedra;
      Corners                  source, target;
      for (std::size_t k = 0; k < dependent.size(); ++k)
      {
        CandidateCorners(c, tets[dependent[k]], source, target);
        Pack(first[i] + k, dependent[k], source, target);
      }
    });
    Run(items);
    m_Pool.ParallelFor(candidates.size(), [&](std::size_t i) {
      for (std::size_t k = 0; k < candidates[i].element->dependentTetrahedra.size(); ++k)
        candidates[i].values[k] = Unpack(first[i] + k);
    });
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
  UploadPacked(const ChannelVolume & volume, cuda::DeviceArray<float> & device,
               std::unique_ptr<cuda::Texture3D> & texture, CudaInterpolation interpolation)
  {
    const std::size_t  voxels = volume.size[0] * volume.size[1] * volume.size[2];
    std::vector<float> packed(4 * voxels, 0.0f);
    for (std::size_t v = 0; v < voxels; ++v)
      for (std::size_t c = 0; c < volume.channels; ++c)
        packed[4 * v + c] = volume.data[volume.channels * v + c];
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
      texture = std::make_unique<cuda::Texture3D>(packed.data(), view.size);
      view.texture = static_cast<unsigned long long>(texture->Get());
    }
    else
    {
      device.Reserve(packed.size());
      Check(cudaMemcpy(device.Data(), packed.data(), packed.size() * sizeof(float), cudaMemcpyHostToDevice),
            "uploading an image");
      view.data = device.Data();
    }
    return view;
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
    Check(cudaMemcpyAsync(m_Corners.Data(), m_HostCorners.Data(), items * cuda::ItemCorners * sizeof(double),
                          cudaMemcpyHostToDevice, stream),
          "copying corners to the device");
    Check(cudaMemcpyAsync(m_Tetrahedra.Data(), m_HostTetrahedra.Data(), items * sizeof(std::uint32_t),
                          cudaMemcpyHostToDevice, stream),
          "copying tetrahedron indices to the device");
    Check(cudaEventRecord(m_KernelStart->Get(), stream), "recording an event");
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
    const double * d = m_HostDirectionValues.Data();
    for (std::size_t i = 0; i < items; ++i)
      m_Statistics.samples += d[i * 2 * cuda::DirectionValues + 2] + d[i * 2 * cuda::DirectionValues + 5];
  }

  const TetrahedronEvaluator &  m_Evaluator;
  ThreadPool                    m_Pool;
  std::unique_ptr<cuda::Stream> m_Stream;
  std::unique_ptr<cuda::Event>  m_KernelStart, m_KernelEnd;
  cuda::EvaluationConstants     m_Constants;
  cuda::DeviceArray<float>      m_Moving, m_Fixed, m_PackedMoving, m_PackedFixed;
  std::unique_ptr<cuda::Texture3D> m_MovingTexture, m_FixedTexture;
  cuda::DeviceArray<double>     m_GuidanceWeights, m_Elasticity, m_ReferenceVolumes;
  cuda::DeviceArray<double>     m_Corners, m_ItemValues, m_DirectionValues;
  cuda::DeviceArray<std::uint32_t> m_Tetrahedra;
  cuda::PinnedArray<double>        m_HostCorners, m_HostItemValues, m_HostDirectionValues;
  cuda::PinnedArray<std::uint32_t> m_HostTetrahedra;
};
} // namespace

std::unique_ptr<EvaluationBackend>
CreateCudaEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads,
                            CudaInterpolation interpolation)
{
  return std::make_unique<CudaEvaluationBackend>(evaluator, threads, interpolation);
}
} // namespace morea
