// CPU-only builds: there is no CUDA backend to offer.
#include "morea/ComputeDevices.h"

namespace morea
{
bool
BuiltWithCuda()
{
  return false;
}

std::vector<CudaDeviceInfo>
ListCudaDevices()
{
  return {};
}

std::string
CudaUnavailableReason()
{
  return "this build has no CUDA backend (nvcc was not found when it was configured)";
}
} // namespace morea
