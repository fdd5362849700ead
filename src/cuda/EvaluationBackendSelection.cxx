// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The one place that chooses between the CPU and CUDA evaluation backends.
#include "morea_core/ComputeDevices.h"
#include "morea_core/Error.h"
#include "morea_core/EvaluationBackend.h"

#include <string>

namespace morea_core
{
namespace
{
const char * const ChoiceHelp = "choose cpu, cuda, cuda-exact or auto";

/** Why device `device` cannot run a CUDA backend under `request`, or "". */
std::string
DeviceUnusableReason(const BackendRequest & request)
{
  if (const std::string reason = CudaUnavailableReason(); !reason.empty())
    return (request.device != 0 ? "CUDA device " + std::to_string(request.device) + " does not exist: " : "") + reason;
  const auto devices = ListCudaDevices();
  if (request.device < 0 || static_cast<std::size_t>(request.device) >= devices.size())
    return "CUDA device " + std::to_string(request.device) + " does not exist (" + std::to_string(devices.size()) +
           " present; set cuda_gpu_id or the device index to one of them)";
  const CudaDeviceInfo & d = devices[static_cast<std::size_t>(request.device)];
  const int              level = 10 * d.computeCapabilityMajor + d.computeCapabilityMinor;
  if (level < request.minimumComputeLevel)
    return "CUDA device " + std::to_string(d.ordinal) + " (" + d.name + ") has compute capability " +
           std::to_string(d.computeCapabilityMajor) + "." + std::to_string(d.computeCapabilityMinor) +
           ", below cuda_compute_level = " + std::to_string(request.minimumComputeLevel);
  return {};
}

std::string
DeviceName(int device)
{
  for (const auto & d : ListCudaDevices())
    if (d.ordinal == device)
      return d.name;
  return "?";
}
} // namespace

BackendChoice
ParseBackendChoice(const std::string & name)
{
  if (name == "cpu")
    return BackendChoice::Cpu;
  if (name == "cuda" || name == "cuda-texture")
    return BackendChoice::CudaTexture;
  if (name == "cuda-exact")
    return BackendChoice::CudaExact;
  if (name == "auto")
    return BackendChoice::Auto;
  throw Error("unknown backend '" + name + "' (" + ChoiceHelp + ")");
}

std::string
BackendChoiceName(BackendChoice choice)
{
  switch (choice)
  {
    case BackendChoice::Cpu:
      return "cpu";
    case BackendChoice::CudaTexture:
      return "cuda";
    case BackendChoice::CudaExact:
      return "cuda-exact";
    case BackendChoice::Auto:
      break;
  }
  return "auto";
}

std::string
CheckBackendRequest(const BackendRequest & request, BackendChoice * resolved)
{
  BackendChoice choice = request.choice;
  std::string   note;
  if (choice == BackendChoice::Auto)
  {
    // Another device than the first, named on purpose: its absence is an
    // error, not a reason to run elsewhere.
    const std::size_t present = ListCudaDevices().size();
    if (request.device != 0 && (request.device < 0 || static_cast<std::size_t>(request.device) >= present))
      throw Error("backend 'auto': CUDA device " + std::to_string(request.device) + " does not exist (" +
                  std::to_string(present) + " present; set cuda_gpu_id or the device index to one of them)");
    const std::string unusable = DeviceUnusableReason(request);
    if (unusable.empty())
    {
      choice = BackendChoice::CudaTexture;
      note = "auto: CUDA device " + std::to_string(request.device) + " (" + DeviceName(request.device) +
             "), texture path";
    }
    else
    {
      choice = BackendChoice::Cpu;
      note = "auto: the CPU, since " + unusable;
    }
  }
  else if (choice != BackendChoice::Cpu)
  {
    if (const std::string unusable = DeviceUnusableReason(request); !unusable.empty())
      throw Error("backend '" + BackendChoiceName(choice) + "': " + unusable + " (backend auto uses the CPU then)");
  }
  if (resolved)
    *resolved = choice;
  return note;
}

std::unique_ptr<EvaluationBackend>
CreateEvaluationBackend(BackendChoice choice, const TetrahedronEvaluator & evaluator, std::size_t threads, int device)
{
  BackendRequest request;
  request.choice = choice;
  request.device = device;
  request.threads = threads;
  return CreateEvaluationBackend(request, evaluator);
}

std::unique_ptr<EvaluationBackend>
CreateEvaluationBackend(const BackendRequest & request, const TetrahedronEvaluator & evaluator, std::string * note)
{
  BackendChoice                      choice = request.choice;
  const std::string                  why = CheckBackendRequest(request, &choice);
  std::unique_ptr<EvaluationBackend> backend;
  switch (choice)
  {
    case BackendChoice::CudaTexture:
      backend = CreateCudaEvaluationBackend(evaluator, request.threads, CudaInterpolation::Texture, request.device);
      break;
    case BackendChoice::CudaExact:
      backend = CreateCudaEvaluationBackend(evaluator, request.threads, CudaInterpolation::Exact, request.device);
      break;
    case BackendChoice::Cpu:
    case BackendChoice::Auto:
      backend = CreateCpuEvaluationBackend(evaluator, request.threads);
      break;
  }
  if (note)
  {
    *note = why;
    if (const std::string path = backend->PathNote(); !path.empty())
      *note += (note->empty() ? "" : "; ") + path;
  }
  return backend;
}
} // namespace morea_core
