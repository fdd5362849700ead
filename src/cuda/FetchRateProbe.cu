// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// A yardstick for the tetrahedron kernels: how many hardware-filtered
// trilinear fetches per second the GPU serves from a 3D float texture when
// neighbouring threads read neighbouring points (the coherent best case).
#include "morea_core/ComputeDevices.h"

#include "DeviceMemory.h"

#include <algorithm>
#include <vector>

namespace morea_core
{
namespace
{
constexpr int Edge = 256;
constexpr int FetchesPerThread = 64;

__global__ void
TrilinearFetchKernel(cudaTextureObject_t texture, float * out)
{
  const int thread = blockIdx.x * blockDim.x + threadIdx.x;
  // Consecutive threads walk neighbouring x; each thread steps along z.
  const float x = static_cast<float>(thread % Edge) + 0.31f;
  const float y = static_cast<float>((thread / Edge) % Edge) + 0.57f;
  float       z = static_cast<float>((thread / (Edge * Edge)) % (Edge / 2)) + 0.13f;
  float       sum = 0.0f;
  for (int i = 0; i < FetchesPerThread; ++i)
  {
    sum += tex3D<float>(texture, x, y, z);
    z += 1.37f;
  }
  out[thread] = sum;
}

struct TextureObject
{
  cudaTextureObject_t handle{ 0 };
  ~TextureObject()
  {
    if (handle)
      cudaDestroyTextureObject(handle);
  }
};

struct ArrayOwner
{
  cudaArray_t array{ nullptr };
  ~ArrayOwner()
  {
    if (array)
      cudaFreeArray(array);
  }
};
} // namespace

double
MeasureTrilinearFetchRate()
{
  using cuda::Check;
  const std::string unavailable = CudaUnavailableReason();
  if (!unavailable.empty())
    throw Error("fetch-rate probe: " + unavailable);
  Check(cudaSetDevice(0), "selecting device 0");
  std::vector<float> host(static_cast<std::size_t>(Edge) * Edge * Edge);
  for (std::size_t i = 0; i < host.size(); ++i)
    host[i] = static_cast<float>((i * 2654435761u) % 1000u) * 1e-3f;

  ArrayOwner                  volume;
  const cudaChannelFormatDesc format = cudaCreateChannelDesc<float>();
  const cudaExtent            extent = make_cudaExtent(Edge, Edge, Edge);
  Check(cudaMalloc3DArray(&volume.array, &format, extent), "allocating the probe volume");
  cudaMemcpy3DParms copy{};
  copy.srcPtr = make_cudaPitchedPtr(host.data(), Edge * sizeof(float), Edge, Edge);
  copy.dstArray = volume.array;
  copy.extent = extent;
  copy.kind = cudaMemcpyHostToDevice;
  Check(cudaMemcpy3D(&copy), "filling the probe volume");

  cudaResourceDesc resource{};
  resource.resType = cudaResourceTypeArray;
  resource.res.array.array = volume.array;
  cudaTextureDesc description{};
  description.addressMode[0] = description.addressMode[1] = description.addressMode[2] = cudaAddressModeClamp;
  description.filterMode = cudaFilterModeLinear;
  description.readMode = cudaReadModeElementType;
  description.normalizedCoords = 0;
  TextureObject texture;
  Check(cudaCreateTextureObject(&texture.handle, &resource, &description, nullptr), "creating the probe texture");

  constexpr int            threads = Edge * Edge * (Edge / 2);
  cuda::DeviceArray<float> out(threads);
  cuda::Event              start, end;
  std::vector<float>       times;
  for (int repeat = 0; repeat < 12; ++repeat)
  {
    Check(cudaEventRecord(start.Get()), "recording an event");
    TrilinearFetchKernel<<<threads / 256, 256>>>(texture.handle, out.Data());
    Check(cudaGetLastError(), "launching the fetch probe");
    Check(cudaEventRecord(end.Get()), "recording an event");
    Check(cudaEventSynchronize(end.Get()), "running the fetch probe");
    float ms = 0.0f;
    Check(cudaEventElapsedTime(&ms, start.Get(), end.Get()), "reading an event");
    if (repeat >= 2) // the first launches warm up
      times.push_back(ms);
  }
  std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
  const double seconds = 1e-3 * times[times.size() / 2];
  return static_cast<double>(threads) * FetchesPerThread / seconds;
}

std::size_t
CudaMemoryInUse()
{
  std::size_t free = 0, total = 0;
  if (cudaMemGetInfo(&free, &total) != cudaSuccess)
  {
    cudaGetLastError();
    return 0;
  }
  return total - free;
}
} // namespace morea_core
