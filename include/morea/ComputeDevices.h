// MultiObjectiveRegistration core: which CUDA devices this build can use.
// Implemented by the CUDA library when the build has CUDA, and by a CPU-only
// translation unit otherwise, so callers never need #ifdefs.
#ifndef morea_ComputeDevices_h
#define morea_ComputeDevices_h

#include <cstddef>
#include <string>
#include <vector>

namespace morea
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
/** Bytes of device 0's memory in use (total - free); 0 without a device. */
std::size_t
CudaMemoryInUse();

/** Hardware-filtered trilinear fetches per second from a 3D float texture
 *  on device 0 when neighbouring threads read neighbouring points: the
 *  coherent best case the tetrahedron kernels are measured against. Throws
 *  morea::Error without a device. */
double
MeasureTrilinearFetchRate();
} // namespace morea

#endif
