// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// RAII owners for CUDA device and pinned host memory, and the one place that
// turns a CUDA status into an exception. Private to src/cuda: nothing outside
// the CUDA library sees CUDA headers.
#ifndef morea_cuda_DeviceMemory_h
#define morea_cuda_DeviceMemory_h

#include "morea_core/Error.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <cstddef>
#include <string>

namespace morea_core::cuda
{
/** Throws morea_core::Error naming `what` when `status` is not cudaSuccess
 *  (morea_core::OutOfDeviceMemory when the device's memory is spent). */
inline void
Check(cudaError_t status, const char * what)
{
  if (status == cudaSuccess)
    return;
  cudaGetLastError(); // clear a non-sticky error so that later calls can go on
  if (status == cudaErrorMemoryAllocation)
    throw OutOfDeviceMemory(std::string("CUDA backend: out of GPU memory (") + what + ")");
  throw Error(std::string("CUDA backend: ") + what + ": " + cudaGetErrorString(status));
}

/** Where a GrowingArray lives: device memory or page-locked host memory
 *  (fast asynchronous copies). */
struct DeviceAllocation
{
  static constexpr const char * what = "of device memory";
  static cudaError_t
  Allocate(void ** p, std::size_t bytes)
  {
    return cudaMalloc(p, bytes);
  }
  static void
  Free(void * p) noexcept
  {
    cudaFree(p); // errors at release cannot be reported usefully
  }
};
struct PinnedAllocation
{
  static constexpr const char * what = "of pinned host memory";
  static cudaError_t
  Allocate(void ** p, std::size_t bytes)
  {
    return cudaMallocHost(p, bytes);
  }
  static void
  Free(void * p) noexcept
  {
    cudaFreeHost(p);
  }
};

/** At least `count` elements of T; grows on demand (losing the contents), never shrinks. */
template <typename T, typename Allocation>
class GrowingArray
{
public:
  GrowingArray() = default;
  explicit GrowingArray(std::size_t count) { Reserve(count); }
  ~GrowingArray() { Release(); }
  GrowingArray(const GrowingArray &) = delete;
  GrowingArray &
  operator=(const GrowingArray &) = delete;

  void
  Reserve(std::size_t count)
  {
    if (count <= m_Capacity)
      return;
    // Half as much again once it has grown: freeing waits for the device
    // (a buffer sized by the archive or by a batch's parents grew by a few
    // elements at a time, and each wait cost a paper-scale generation ms).
    if (m_Capacity > 0)
      count = std::max(count, m_Capacity + m_Capacity / 2);
    Release();
    const std::size_t bytes = count * sizeof(T);
    void *            p = nullptr;
    Check(Allocation::Allocate(&p, bytes), (std::to_string(bytes >> 20) + " MiB " + Allocation::what).c_str());
    m_Data = static_cast<T *>(p);
    m_Capacity = count;
  }
  T *
  Data() const
  {
    return m_Data;
  }
  T &
  operator[](std::size_t i) const
  {
    return m_Data[i];
  }

private:
  void
  Release() noexcept
  {
    if (m_Data)
      Allocation::Free(m_Data);
    m_Data = nullptr;
    m_Capacity = 0;
  }
  T *         m_Data{ nullptr };
  std::size_t m_Capacity{ 0 };
};

template <typename T>
using DeviceArray = GrowingArray<T, DeviceAllocation>;
template <typename T>
using PinnedArray = GrowingArray<T, PinnedAllocation>;

/** A CUDA stream owned for the lifetime of the object. */
class Stream
{
public:
  Stream() { Check(cudaStreamCreateWithFlags(&m_Stream, cudaStreamNonBlocking), "creating a stream"); }
  /** A stream whose blocks the device schedules before those of default
   *  priority streams: for short work that others wait on. */
  struct HighPriority
  {};
  explicit Stream(HighPriority)
  {
    int least = 0, greatest = 0;
    Check(cudaDeviceGetStreamPriorityRange(&least, &greatest), "reading stream priorities");
    Check(cudaStreamCreateWithPriority(&m_Stream, cudaStreamNonBlocking, greatest), "creating a stream");
  }
  ~Stream()
  {
    if (m_Stream)
      cudaStreamDestroy(m_Stream);
  }
  Stream(const Stream &) = delete;
  Stream &
  operator=(const Stream &) = delete;
  cudaStream_t
  Get() const
  {
    return m_Stream;
  }

private:
  cudaStream_t m_Stream{ nullptr };
};
/** A 3D texture with trilinear filtering (clamped, unnormalised
 *  coordinates; or none, TextureFilter::Point), owning its array. `voxels`
 *  holds `bytesPerVoxel` bytes per voxel in `format`; integer formats read
 *  as normalised floats where filtered. With
 *  `TextureLayout::Layers`, size[2] counts 2D layers, each filtered
 *  bilinearly on its own (tex2DLayered). */
enum class TextureLayout
{
  Volume,
  Layers
};

/** Filtered (linear; integer texels read as normalised floats) or not
 *  (point; texels read as stored). */
enum class TextureFilter
{
  Linear,
  Point
};

class Texture3D
{
public:
  Texture3D(const void * voxels, std::size_t bytesPerVoxel, const cudaChannelFormatDesc & format, const int size[3],
            TextureLayout layout = TextureLayout::Volume, TextureFilter filter = TextureFilter::Linear)
  {
    const cudaExtent extent = make_cudaExtent(size[0], size[1], size[2]);
    Check(cudaMalloc3DArray(&m_Array, &format, extent, layout == TextureLayout::Layers ? cudaArrayLayered : 0),
          "allocating a texture array");
    cudaMemcpy3DParms copy{};
    copy.srcPtr = make_cudaPitchedPtr(const_cast<void *>(voxels), size[0] * bytesPerVoxel, size[0], size[1]);
    copy.dstArray = m_Array;
    copy.extent = extent;
    copy.kind = cudaMemcpyHostToDevice;
    Check(cudaMemcpy3D(&copy), "filling a texture array");
    cudaResourceDesc resource{};
    resource.resType = cudaResourceTypeArray;
    resource.res.array.array = m_Array;
    cudaTextureDesc description{};
    description.addressMode[0] = description.addressMode[1] = description.addressMode[2] = cudaAddressModeClamp;
    description.filterMode = filter == TextureFilter::Linear ? cudaFilterModeLinear : cudaFilterModePoint;
    description.readMode = format.f == cudaChannelFormatKindFloat || filter == TextureFilter::Point
                             ? cudaReadModeElementType
                             : cudaReadModeNormalizedFloat;
    description.normalizedCoords = 0;
    Check(cudaCreateTextureObject(&m_Texture, &resource, &description, nullptr), "creating a texture");
  }
  ~Texture3D()
  {
    if (m_Texture)
      cudaDestroyTextureObject(m_Texture);
    if (m_Array)
      cudaFreeArray(m_Array);
  }
  Texture3D(const Texture3D &) = delete;
  Texture3D &
  operator=(const Texture3D &) = delete;
  cudaTextureObject_t
  Get() const
  {
    return m_Texture;
  }

private:
  cudaArray_t         m_Array{ nullptr };
  cudaTextureObject_t m_Texture{ 0 };
};

/** A CUDA event (timing only) owned for the lifetime of the object. */
class Event
{
public:
  Event() { Check(cudaEventCreate(&m_Event), "creating an event"); }
  ~Event()
  {
    if (m_Event)
      cudaEventDestroy(m_Event);
  }
  Event(const Event &) = delete;
  Event &
  operator=(const Event &) = delete;
  cudaEvent_t
  Get() const
  {
    return m_Event;
  }

private:
  cudaEvent_t m_Event{ nullptr };
};
} // namespace morea_core::cuda

#endif
