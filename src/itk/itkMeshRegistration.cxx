// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkMeshRegistration.h"

#include "itkObjectiveData.h"
#include "morea_core/CheckpointWriter.h"
#include "morea_core/Error.h"
#include "morea_core/EvaluationBackend.h"
#include "morea_core/FoldConstraint.h"
#include "morea_core/InitialPopulation.h"
#include "morea_core/MemoryEstimate.h"
#include "morea_core/MeshRefinement.h"
#include "morea_core/ParameterSet.h"
#include "morea_core/TetrahedronObjectives.h"
#include "morea_core/ThreadPool.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <future>
#include <optional>
#include <string>
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
    text += (i ? " " : "") + morea_core::ExactText(values[i]);
  return text;
}

/** An image's grid as text, and its voxels' hash, under `name`. */
template <typename TImage>
void
AddImage(morea_core::RunFingerprint & fingerprint, const std::string & name, const TImage * image)
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
AddPoints(morea_core::RunFingerprint & fingerprint, const std::string & name, const PointListType & points)
{
  std::vector<double> coordinates;
  for (const PointType & p : points)
    coordinates.insert(coordinates.end(), { p[0], p[1], p[2] });
  fingerprint.AddHash(name, coordinates.data(), coordinates.size() * sizeof(double));
}
} // namespace

morea_core::RunFingerprint
RunFingerprintOf(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters)
{
  morea_core::RunFingerprint fingerprint;
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

namespace
{
/** Level `level`'s checkpoint file: the run's own for the last level (or
 *  the only one), beside it with ".levelK" for earlier ones. */
std::string
LevelCheckpointPath(const std::string & path, std::size_t level, const morea_core::MeshLevelPlan & plan)
{
  if (path.empty() || level + 1 == plan.levels)
    return path;
  return path + ".level" + std::to_string(level);
}

/** Per coarse tetrahedron, where the next level needs points: from up to 16
 *  archived solutions spread along the front (by guidance). */
std::vector<double>
NextLevelDensity(const MeshModel & model, const morea_core::ElitistArchive & archive, morea_core::EvaluationBackend & backend)
{
  std::vector<const morea_core::ArchiveEntry *> entries;
  for (const auto & e : archive.Entries())
    entries.push_back(&e);
  std::stable_sort(entries.begin(), entries.end(), [](const auto * a, const auto * b) {
    return a->fitness.objectives[2] < b->fitness.objectives[2];
  });
  const std::size_t                                    count = std::min<std::size_t>(16, entries.size());
  std::vector<const morea_core::DualMesh *>               solutions;
  std::vector<std::vector<morea_core::TetrahedronValues>> values(count);
  std::vector<std::vector<morea_core::TetrahedronValues> *> outputs;
  for (std::size_t i = 0; i < count; ++i)
  {
    solutions.push_back(&entries[i * entries.size() / count]->solution);
    outputs.push_back(&values[i]);
  }
  if (count > 0)
    backend.EvaluateSolutions(solutions, outputs);
  return morea_core::RefinementDensity(model.base, values);
}
} // namespace

MeshRegistrationResult
RegisterMeshes(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters,
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
  const morea_core::MeshLevelPlan plan = morea_core::MeshLevelPlan::FromParameters(parameters);
  // The objective data (distance maps) need the model's frame only: they are
  // made while the mesh is built (TetGen runs on one core). Without a moving
  // image there is no frame, and BuildMeshModel reports the missing images.
  std::future<morea_core::ObjectiveData> objectiveData;
  if (problem.movingImage)
    objectiveData = std::async(std::launch::async, [&problem, &parameters] {
      return BuildObjectiveData(problem, DomainFrame::Of(problem.movingImage), parameters);
    });
  MeshModel model = BuildMeshModel(problem, parameters);
  result.secondsMesh = lap();
  const morea_core::ObjectiveData data = objectiveData.get();
  result.secondsObjectiveData = lap(); // what the mesh did not hide
  const std::size_t coarsePoints = model.base.NumberOfPoints();

  morea_core::BackendRequest request;
  request.choice = options.backend;
  request.device = options.device;
  request.minimumComputeLevel = options.minimumComputeLevel;
  request.threads = options.threads;
  result.threads = options.threads ? options.threads : morea_core::HostThreads();

  morea_core::GomeaOptions baseOptions = morea_core::GomeaOptions::FromParameters(parameters);
  baseOptions.threads = options.threads; // the backend's pool: the two take turns on it
  // What a checkpoint belongs to: the caller's entries, then the problem's.
  baseOptions.fingerprint = options.fingerprint;
  const morea_core::RunFingerprint ofProblem = RunFingerprintOf(problem, parameters);
  for (const auto & [key, value] : ofProblem.Entries())
    baseOptions.fingerprint.Add(key, value);

  morea_core::CheckpointWriter checkpoints; // files written while the next generations run
  const morea_core::CheckpointSchedule checkpointSchedule{ options.checkpointInterval, options.checkpointSeconds };
  auto                         lastCheckpoint = Clock::now(); // or the optimisation's start
  std::size_t               checkpointGeneration = 0; // of the last checkpoint written; 0: none
  std::string               checkpointPath = options.checkpointPath;
  std::size_t               generation = 0;
  // Each level's solutions carried over to the next (refined) mesh.
  std::vector<morea_core::DualMesh> carriedPopulation, carriedArchive;
  std::optional<MeshModel>       refined;
  double                         secondsLevels = 0.0;
  try
  {
    for (std::size_t level = 0; level < plan.levels; ++level)
    {
      if (refined)
      {
        model = std::move(*refined);
        refined.reset();
      }
      const morea_core::FoldConstraint constraint(model.topology, model.base.points,
                                               parameters.GetReal("morea_fold_volume_fraction"));
      const morea_core::TetrahedronEvaluator evaluator(model.topology, constraint, model.elasticity, model.rigidity, data);
      auto backend = morea_core::CreateEvaluationBackend(request, evaluator, level == 0 ? &result.backendNote : nullptr);
      if (level == 0)
      {
        result.backend = backend->Name();
        result.pathNote = backend->PathNote();
        result.secondsBackend = lap();
        result.secondsModel = result.secondsMesh + result.secondsObjectiveData + result.secondsBackend;
      }
      start = Clock::now();

      morea_core::GomeaOptions gomea = baseOptions;
      gomea.boundRefusals = morea_core::UsesRefusalBounds(options.refusalBounds, *backend);
      gomea.firstGeneration = plan.FirstGeneration(level);
      gomea.generations = plan.EndGeneration(level);
      gomea.fingerprint.AddEvaluationBackend(result.backend);
      if (plan.levels > 1)
        gomea.fingerprint.Add("mesh level", std::to_string(level) + " of " + std::to_string(plan.levels));
      morea_core::RunShape shape = morea_core::RunShapeOf(gomea, model.topology, model.parallel);
      shape.checkpoints = !options.checkpointPath.empty();
      morea_core::CheckRunMemory(shape, *backend); // before the population exists, not as bad_alloc midway
      morea_core::MoRvGomea optimiser(model.base, model.topology, model.parallel, constraint, *backend, gomea);
      checkpointPath = LevelCheckpointPath(options.checkpointPath, level, plan);
      if (options.resume && !checkpointPath.empty() && std::filesystem::exists(checkpointPath))
      {
        optimiser.LoadCheckpoint(checkpointPath);
        result.resumedAtGeneration = optimiser.Generation(); // the last level loaded says where
        checkpointGeneration = optimiser.Generation();
      }
      else
      {
        if (level == 0)
          optimiser.Initialize(morea_core::GenerateInitialPopulation(
            model.base, constraint, gomea.populationSize, gomea.seed,
            morea_core::InitialPopulationOptions::FromParameters(parameters)));
        else
          optimiser.Initialize(std::move(carriedPopulation), carriedArchive);
        // Later levels' files are another run's now: a resume must not take them.
        for (std::size_t later = level + 1; later < plan.levels && !options.checkpointPath.empty(); ++later)
          std::filesystem::remove(LevelCheckpointPath(options.checkpointPath, later, plan));
      }
      carriedPopulation.clear();
      carriedArchive.clear();
      generation = optimiser.Generation();
      while (!optimiser.Finished())
      {
        optimiser.RunGeneration();
        generation = optimiser.Generation();
        const bool last = optimiser.Finished();
        if (!checkpointPath.empty() &&
            (last || checkpointSchedule.Due(optimiser.Generation(),
                                            std::chrono::duration<double>(Clock::now() - lastCheckpoint).count())))
        {
          lastCheckpoint = Clock::now();
          std::string bytes = checkpoints.TakeBuffer(); // the last checkpoint's room
          optimiser.CheckpointBytes(bytes);
          checkpoints.Write(std::move(bytes), checkpointPath);
          checkpointGeneration = optimiser.Generation();
        }
        if (options.onGeneration)
          options.onGeneration(optimiser.History().back(), plan.generations);
      }
      checkpoints.Wait(); // a level's last checkpoint is whole before the next level starts
      const auto & history = optimiser.History();
      // A later level's first record repeats the generation the level before ended at.
      result.history.insert(result.history.end(), history.begin() + (level > 0 ? 1 : 0), history.end());
      if (level + 1 < plan.levels)
      {
        morea_core::MeshRefinement refinement;
        refined = RefineMeshModel(model, problem, parameters, NextLevelDensity(model, optimiser.Archive(), *backend),
                                  plan.PointsAt(level + 1, coarsePoints), refinement);
        for (const auto & solution : optimiser.Population())
          carriedPopulation.push_back(morea_core::CarryOver(refinement, solution));
        for (const auto & e : optimiser.Archive().Entries())
          carriedArchive.push_back(morea_core::CarryOver(refinement, e.solution));
      }
      else
      {
        for (const auto & e : optimiser.Archive().Entries())
          result.front.push_back({ e.id, e.fitness, e.solution });
      }
      secondsLevels += std::chrono::duration<double>(Clock::now() - start).count();
    }
  }
  catch (const morea_core::OutOfDeviceMemory & e)
  {
    // Another process took the device's memory, or the estimate fell
    // short: say what ran out where, and what is left to resume from.
    checkpoints.Wait();
    std::string message = std::string(e.what()) + " after " + std::to_string(generation) +
                          " generations, with a population of " + std::to_string(baseOptions.populationSize) +
                          " (ea_population_size) on a mesh of " + std::to_string(model.base.NumberOfPoints()) +
                          " points: free the device, lower ea_population_size or morea_mesh_num_points, or run "
                          "on the cpu backend";
    if (checkpointGeneration > 0)
      message += "; the checkpoint " + checkpointPath + " (generation " + std::to_string(checkpointGeneration) +
                 ") resumes on a device with room";
    throw morea_core::Error(message);
  }
  checkpoints.Wait();
  result.model = std::move(model);
  result.secondsOptimisation = secondsLevels;
  std::stable_sort(result.front.begin(), result.front.end(), [](const FrontSolution & a, const FrontSolution & b) {
    return a.fitness.objectives[2] < b.fitness.objectives[2];
  });
  return result;
}
} // namespace morea
} // namespace itk
