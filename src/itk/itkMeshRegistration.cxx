#include "itkMeshRegistration.h"

#include "itkObjectiveData.h"
#include "morea/CheckpointWriter.h"
#include "morea/EvaluationBackend.h"
#include "morea/FoldConstraint.h"
#include "morea/InitialPopulation.h"
#include "morea/ParameterSet.h"
#include "morea/TetrahedronObjectives.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <future>
#include <string>
#include <thread>
#include <utility>

namespace itk
{
namespace morea
{
MeshRegistrationResult
RegisterMeshes(const RegistrationProblem & problem, const ::morea::ParameterSet & parameters,
               const MeshRegistrationOptions & options)
{
  using Clock = std::chrono::steady_clock;
  auto                   start = Clock::now();
  auto                   lap = [&start] {
    const auto now = Clock::now();
    const double seconds = std::chrono::duration<double>(now - start).count();
    start = now;
    return seconds;
  };
  MeshRegistrationResult result;
  // The objective data (distance maps) need the model's frame only: they are
  // made while the mesh is built (TetGen runs on one core). Without a moving
  // image there is no frame, and BuildMeshModel reports the missing images.
  std::future<::morea::ObjectiveData> objectiveData;
  if (problem.movingImage)
    objectiveData = std::async(std::launch::async, [&problem, &parameters] {
      return BuildObjectiveData(problem, DomainFrame::Of(problem.movingImage), parameters);
    });
  result.model = BuildMeshModel(problem, parameters);
  const MeshModel & model = result.model;
  result.secondsMesh = lap();
  const ::morea::ObjectiveData data = objectiveData.get();
  result.secondsObjectiveData = lap(); // what the mesh did not hide
  const ::morea::FoldConstraint constraint(model.topology, model.base.points,
                                                parameters.GetReal("morea_fold_volume_fraction"));
  const ::morea::TetrahedronEvaluator evaluator(model.topology, constraint, model.elasticity, data);
  ::morea::BackendRequest request;
  request.choice = options.backend;
  request.device = options.device;
  request.minimumComputeLevel = options.minimumComputeLevel;
  request.threads = options.threads;
  auto backend = ::morea::CreateEvaluationBackend(request, evaluator, &result.backendNote);
  result.backend = backend->Name();
  result.pathNote = backend->PathNote();
  result.threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  result.secondsBackend = lap();
  result.secondsModel = result.secondsMesh + result.secondsObjectiveData + result.secondsBackend;

  start = Clock::now();
  ::morea::GomeaOptions gomea = ::morea::GomeaOptions::FromParameters(parameters);
  gomea.boundRefusals = ::morea::UsesRefusalBounds(options.refusalBounds, *backend);
  gomea.threads = options.threads; // the backend's pool: the two take turns on it
  ::morea::MoRvGomea optimiser(model.base, model.topology, model.parallel, constraint, *backend, gomea);
  if (options.resume && !options.checkpointPath.empty() && std::filesystem::exists(options.checkpointPath))
  {
    optimiser.LoadCheckpoint(options.checkpointPath);
    result.resumedAtGeneration = optimiser.Generation();
  }
  else
    optimiser.Initialize(::morea::GenerateInitialPopulation(
      model.base, constraint, gomea.populationSize, gomea.seed,
      ::morea::InitialPopulationOptions::FromParameters(parameters)));
  ::morea::CheckpointWriter checkpoints; // files written while the next generations run
  while (!optimiser.Finished())
  {
    optimiser.RunGeneration();
    const bool last = optimiser.Finished();
    if (!options.checkpointPath.empty() &&
        (last || (options.checkpointInterval > 0 && optimiser.Generation() % options.checkpointInterval == 0)))
    {
      std::string bytes = checkpoints.TakeBuffer(); // the last checkpoint's room
      optimiser.CheckpointBytes(bytes);
      checkpoints.Write(std::move(bytes), options.checkpointPath);
    }
    if (options.onGeneration)
      options.onGeneration(optimiser.History().back(), gomea.generations);
  }
  checkpoints.Wait();
  result.secondsOptimisation = std::chrono::duration<double>(Clock::now() - start).count();
  result.history = optimiser.History();
  for (const auto & e : optimiser.Archive().Entries())
    result.front.push_back({ e.id, e.fitness, e.solution });
  std::stable_sort(result.front.begin(), result.front.end(), [](const FrontSolution & a, const FrontSolution & b) {
    return a.fitness.objectives[2] < b.fitness.objectives[2];
  });
  return result;
}
} // namespace morea
} // namespace itk
