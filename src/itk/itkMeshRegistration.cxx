#include "itkMeshRegistration.h"

#include "itkObjectiveData.h"
#include "morea/CheckpointWriter.h"
#include "morea/Error.h"
#include "morea/EvaluationBackend.h"
#include "morea/FoldConstraint.h"
#include "morea/InitialPopulation.h"
#include "morea/MemoryEstimate.h"
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
namespace
{
std::string
Numbers(const double * values, unsigned int count)
{
  std::string text;
  for (unsigned int i = 0; i < count; ++i)
    text += (i ? " " : "") + ::morea::ExactText(values[i]);
  return text;
}

/** An image's grid as text, and its voxels' hash, under `name`. */
template <typename TImage>
void
AddImage(::morea::RunFingerprint & fingerprint, const std::string & name, const TImage * image)
{
  if (!image)
  {
    fingerprint.Add(name, "none");
    return;
  }
  const auto   size = image->GetLargestPossibleRegion().GetSize();
  const double sizes[3] = { static_cast<double>(size[0]), static_cast<double>(size[1]), static_cast<double>(size[2]) };
  double       direction[9];
  for (unsigned int r = 0; r < 3; ++r)
    for (unsigned int c = 0; c < 3; ++c)
      direction[3 * r + c] = image->GetDirection()[r][c];
  fingerprint.Add(name + " grid", "size " + Numbers(sizes, 3) + ", spacing " +
                                    Numbers(image->GetSpacing().GetDataPointer(), 3) + ", origin " +
                                    Numbers(image->GetOrigin().GetDataPointer(), 3) + ", direction " +
                                    Numbers(direction, 9));
  fingerprint.AddHash(name + " voxels", image->GetBufferPointer(),
                      image->GetPixelContainer()->Size() * sizeof(typename TImage::PixelType));
}

void
AddPoints(::morea::RunFingerprint & fingerprint, const std::string & name, const PointListType & points)
{
  std::vector<double> coordinates;
  for (const PointType & p : points)
    coordinates.insert(coordinates.end(), { p[0], p[1], p[2] });
  fingerprint.AddHash(name, coordinates.data(), coordinates.size() * sizeof(double));
}
} // namespace

::morea::RunFingerprint
RunFingerprintOf(const RegistrationProblem & problem, const ::morea::ParameterSet & parameters)
{
  ::morea::RunFingerprint fingerprint;
  fingerprint.AddParameters(parameters);
  AddImage(fingerprint, "fixed image", problem.fixedImage.GetPointer());
  AddImage(fingerprint, "moving image", problem.movingImage.GetPointer());
  AddImage(fingerprint, "fixed body mask", problem.fixedBodyMask.GetPointer());
  AddImage(fingerprint, "moving body mask", problem.movingBodyMask.GetPointer());
  std::string names;
  for (const Structure & s : problem.structures)
    names += (names.empty() ? "" : ", ") + s.name;
  fingerprint.Add("structures", names);
  for (const Structure & s : problem.structures)
  {
    AddImage(fingerprint, "structure " + s.name + " fixed mask", s.fixedMask.GetPointer());
    AddImage(fingerprint, "structure " + s.name + " moving mask", s.movingMask.GetPointer());
    AddPoints(fingerprint, "structure " + s.name + " fixed points", s.fixedPoints);
    AddPoints(fingerprint, "structure " + s.name + " moving points", s.movingPoints);
  }
  return fingerprint;
}

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
  const ::morea::TetrahedronEvaluator evaluator(model.topology, constraint, model.elasticity, model.rigidity, data);
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
  // What a checkpoint belongs to: the caller's entries, then the problem's.
  gomea.fingerprint = options.fingerprint;
  const ::morea::RunFingerprint ofProblem = RunFingerprintOf(problem, parameters);
  for (const auto & [key, value] : ofProblem.Entries())
    gomea.fingerprint.Add(key, value);
  gomea.fingerprint.AddEvaluationBackend(result.backend);
  ::morea::RunShape shape = ::morea::RunShapeOf(gomea, model.topology, model.parallel);
  shape.checkpoints = !options.checkpointPath.empty();
  ::morea::CheckRunMemory(shape, *backend); // before the population exists, not as bad_alloc midway
  ::morea::MoRvGomea optimiser(model.base, model.topology, model.parallel, constraint, *backend, gomea);
  ::morea::CheckpointWriter checkpoints; // files written while the next generations run
  std::size_t               checkpointGeneration = 0; // of the last checkpoint written; 0: none
  try
  {
    if (options.resume && !options.checkpointPath.empty() && std::filesystem::exists(options.checkpointPath))
    {
      optimiser.LoadCheckpoint(options.checkpointPath);
      result.resumedAtGeneration = checkpointGeneration = optimiser.Generation();
    }
    else
      optimiser.Initialize(::morea::GenerateInitialPopulation(
        model.base, constraint, gomea.populationSize, gomea.seed,
        ::morea::InitialPopulationOptions::FromParameters(parameters)));
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
        checkpointGeneration = optimiser.Generation();
      }
      if (options.onGeneration)
        options.onGeneration(optimiser.History().back(), gomea.generations);
    }
  }
  catch (const ::morea::OutOfDeviceMemory & e)
  {
    // Another process took the device's memory, or the estimate fell
    // short: say what ran out where, and what is left to resume from.
    checkpoints.Wait();
    std::string message = std::string(e.what()) + " after " + std::to_string(optimiser.Generation()) +
                          " generations, with a population of " + std::to_string(gomea.populationSize) +
                          " (ea_population_size) on a mesh of " + std::to_string(model.base.NumberOfPoints()) +
                          " points: free the device, lower ea_population_size or morea_mesh_num_points, or run "
                          "on the cpu backend";
    if (checkpointGeneration > 0)
      message += "; the checkpoint " + options.checkpointPath + " (generation " +
                 std::to_string(checkpointGeneration) + ") resumes on a device with room";
    throw ::morea::Error(message);
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
