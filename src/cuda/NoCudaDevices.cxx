// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// CPU-only builds: there is no CUDA backend to offer.
#include "morea_core/ComputeDevices.h"
#include "morea_core/Error.h"
#include "morea_core/EvaluationBackend.h"

namespace morea_core
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

CudaContextWarmUp::CudaContextWarmUp(int) {}

CudaContextWarmUp::~CudaContextWarmUp() = default;

std::size_t
CudaFreeMemory(int)
{
  return 0;
}

std::size_t
CudaMemoryInUse()
{
  return 0;
}

double
MeasureTrilinearFetchRate()
{
  throw Error("fetch-rate probe: " + CudaUnavailableReason());
}

void
HoldCudaEvaluationStream(EvaluationBackend &, const std::atomic<bool> &)
{
  throw Error("holding the evaluation stream: " + CudaUnavailableReason());
}

std::unique_ptr<EvaluationBackend>
CreateCudaEvaluationBackend(const TetrahedronEvaluator &, std::size_t, CudaInterpolation, int)
{
  throw Error("CUDA backend: " + CudaUnavailableReason());
}
} // namespace morea_core
