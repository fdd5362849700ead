// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Device discovery through the CUDA runtime. No ITK here.
#include "morea_core/ComputeDevices.h"

#include <cuda_runtime.h>

namespace morea_core
{
bool
BuiltWithCuda()
{
  return true;
}

std::vector<CudaDeviceInfo>
ListCudaDevices()
{
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess)
  {
    cudaGetLastError(); // clear the sticky "no device/driver" error
    return {};
  }
  std::vector<CudaDeviceInfo> devices;
  for (int i = 0; i < count; ++i)
  {
    cudaDeviceProp prop{};
    if (cudaGetDeviceProperties(&prop, i) != cudaSuccess)
    {
      cudaGetLastError();
      continue;
    }
    CudaDeviceInfo info;
    info.ordinal = i;
    info.name = prop.name;
    info.computeCapabilityMajor = prop.major;
    info.computeCapabilityMinor = prop.minor;
    info.totalMemoryBytes = prop.totalGlobalMem;
    info.multiprocessors = prop.multiProcessorCount;
    devices.push_back(info);
  }
  return devices;
}

std::string
CudaUnavailableReason()
{
  int               count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess)
  {
    cudaGetLastError();
    return std::string("no usable CUDA device: ") + cudaGetErrorString(status);
  }
  return count == 0 ? "no CUDA device present" : "";
}

CudaContextWarmUp::CudaContextWarmUp(int device)
  : m_Thread([device] {
    // The runtime creates the primary context on its first call that
    // needs one; later calls on any thread find it made.
    if (cudaSetDevice(device) != cudaSuccess || cudaFree(nullptr) != cudaSuccess)
      cudaGetLastError(); // the backend reports what is wrong when it is made
  })
{}

CudaContextWarmUp::~CudaContextWarmUp()
{
  if (m_Thread.joinable())
    m_Thread.join();
}

std::size_t
CudaFreeMemory(int device)
{
  // On `device`, then back: the caller's current device stays its own.
  int current = 0;
  std::size_t free = 0, total = 0;
  if (cudaGetDevice(&current) != cudaSuccess || cudaSetDevice(device) != cudaSuccess ||
      cudaMemGetInfo(&free, &total) != cudaSuccess)
  {
    cudaGetLastError();
    free = 0;
  }
  cudaSetDevice(current);
  return free;
}
} // namespace morea_core
