// The one place that chooses between the CPU and CUDA evaluation backends.
#include "morea/ComputeDevices.h"
#include "morea/Error.h"
#include "morea/EvaluationBackend.h"

namespace morea
{
BackendChoice
ParseBackendChoice(const std::string & name)
{
  if (name == "cpu")
    return BackendChoice::Cpu;
  if (name == "cuda")
    return BackendChoice::Cuda;
  if (name == "cuda-texture")
    return BackendChoice::CudaTexture;
  if (name == "auto")
    return BackendChoice::Auto;
  throw Error("unknown backend '" + name + "' (choose cpu, cuda, cuda-texture or auto)");
}

std::unique_ptr<EvaluationBackend>
CreateEvaluationBackend(BackendChoice choice, const TetrahedronEvaluator & evaluator, std::size_t threads)
{
  switch (choice)
  {
    case BackendChoice::Cpu:
      return CreateCpuEvaluationBackend(evaluator, threads);
    case BackendChoice::Cuda:
      return CreateCudaEvaluationBackend(evaluator, threads);
    case BackendChoice::CudaTexture:
      return CreateCudaEvaluationBackend(evaluator, threads, CudaInterpolation::Texture);
    case BackendChoice::Auto:
      break;
  }
  if (CudaUnavailableReason().empty())
    return CreateCudaEvaluationBackend(evaluator, threads);
  return CreateCpuEvaluationBackend(evaluator, threads);
}
} // namespace morea
