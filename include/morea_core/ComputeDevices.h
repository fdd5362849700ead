// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: which CUDA devices this build can use.
// Implemented by the CUDA library when the build has CUDA, and by a CPU-only
// translation unit otherwise, so callers never need #ifdefs.
#ifndef morea_ComputeDevices_h
#define morea_ComputeDevices_h

#include <cstddef>
#include <string>
#include <thread>
#include <vector>

namespace morea_core
{
struct CudaDeviceInfo
{
  int         ordinal{ 0 };
  std::string name;
  int         computeCapabilityMajor{ 0 };
  int         computeCapabilityMinor{ 0 };
  std::size_t totalMemoryBytes{ 0 };
  int         multiprocessors{ 0 };
};

/** True when this build contains the CUDA backend. */
bool
BuiltWithCuda();

/** The CUDA devices present (empty without a device, a driver, or CUDA in the build). */
std::vector<CudaDeviceInfo>
ListCudaDevices();

/** Why ListCudaDevices() is empty, or "" when it is not. */
std::string
CudaUnavailableReason();
/** Sets up device `device`'s CUDA context on a thread of its own while the
 *  caller goes on (reading and preprocessing images), so that a CUDA backend
 *  made later does not wait for it; waits for that thread when destroyed.
 *  Errors are left for the backend to report. Does nothing without CUDA. */
class CudaContextWarmUp
{
public:
  explicit CudaContextWarmUp(int device = 0);
  ~CudaContextWarmUp();
  CudaContextWarmUp(const CudaContextWarmUp &) = delete;
  CudaContextWarmUp &
  operator=(const CudaContextWarmUp &) = delete;

private:
  std::thread m_Thread;
};

/** Bytes of device `device`'s memory free now (cudaMemGetInfo); 0 without
 *  such a device. */
std::size_t
CudaFreeMemory(int device);

/** Bytes of device 0's memory in use (total - free); 0 without a device. */
std::size_t
CudaMemoryInUse();

/** Hardware-filtered trilinear fetches per second from a 3D float texture
 *  on device 0 when neighbouring threads read neighbouring points: the
 *  coherent best case the tetrahedron kernels are measured against. Throws
 *  morea_core::Error without a device. */
double
MeasureTrilinearFetchRate();
} // namespace morea_core

#endif
