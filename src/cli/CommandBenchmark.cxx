// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// `morea benchmark`: times MO-RV-GOMEA on a real problem with each evaluation
// backend (SPEC 6): per-generation wall time, partial evaluations and sample
// points per second, kernel time, peak GPU memory, the GPU's own coherent
// trilinear fetch rate as a yardstick, and the CPU backend on the same work.
#include "CommandCommon.h"

#include "itkMOREAImageIO.h"
#include "itkMeshModel.h"
#include "itkMeshRegistration.h"
#include "itkObjectiveData.h"
#include "itkPreprocessing.h"
#include "morea_core/ComputeDevices.h"
#include "morea_core/EvaluationBackend.h"
#include "morea_core/FoldConstraint.h"
#include "morea_core/InitialPopulation.h"
#include "morea_core/MemoryEstimate.h"
#include "morea_core/MoRvGomea.h"
#include "morea_core/TetrahedronObjectives.h"
#include "morea_core/ThreadPool.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace morea_cli
{
namespace
{
using Clock = std::chrono::steady_clock;

double
Since(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/** One backend's run: `generations` generations from the seeded start, or
 *  from a checkpoint of `morea register` (late generations). */
nlohmann::json
TimeBackend(const std::string & name, const itk::morea::MeshModel & model, const TetrahedronEvaluator & evaluator,
            GomeaOptions gomea, const InitialPopulationOptions & initial, std::size_t generations,
            std::size_t threads, const std::string & checkpoint, RefusalBoundChoice refusalBounds)
{
  const std::size_t memoryBefore = CudaMemoryInUse();
  std::size_t       memoryPeak = memoryBefore;
  auto              backend = CreateEvaluationBackend(ParseBackendChoice(name), evaluator, threads);
  gomea.boundRefusals = UsesRefusalBounds(refusalBounds, *backend);
  gomea.threads = threads; // the backend's pool: the two take turns on it
  gomea.fingerprint.AddEvaluationBackend(backend->Name()); // as morea register's checkpoints
  const RunShape shape = RunShapeOf(gomea, model.topology, model.parallel);
  CheckRunMemory(shape, *backend);
  const MemoryEstimate memoryEstimate = MoRvGomea::MemoryFor(shape) + backend->MemoryFor(shape);
  std::cout << "  backend " << backend->Name() << ": initial population of " << gomea.populationSize << "\n"
            << std::flush;
  auto      start = Clock::now();
  MoRvGomea optimiser(model.base, model.topology, model.parallel, evaluator.Constraint(), *backend, gomea);
  double    secondsPopulation = 0.0;
  if (checkpoint.empty())
  {
    std::vector<DualMesh> population =
      GenerateInitialPopulation(model.base, evaluator.Constraint(), gomea.populationSize, gomea.seed, initial);
    secondsPopulation = Since(start);
    start = Clock::now();
    optimiser.Initialize(std::move(population));
  }
  else
    optimiser.LoadCheckpoint(checkpoint);
  const double            secondsInitialEvaluation = Since(start);
  const std::size_t       firstGeneration = optimiser.Generation();
  const BackendStatistics afterInit = backend->Statistics();
  memoryPeak = std::max(memoryPeak, CudaMemoryInUse());

  // The device's phases between two readings of the statistics.
  const auto DevicePhasesJson = [](const BackendStatistics & before, const BackendStatistics & after) {
    const auto & a = after.devicePhases;
    const auto & b = before.devicePhases;
    return nlohmann::json{ { "between_batches", a.betweenBatches - b.betweenBatches },
                           { "staging", a.staging - b.staging },
                           { "uploads", a.uploads - b.uploads },
                           { "fold_checks", a.foldChecks - b.foldChecks },
                           { "preparation", a.preparation - b.preparation },
                           { "chunk_counts", a.chunkCounts - b.chunkCounts },
                           { "sampling", a.sampling - b.sampling } };
  };
  nlohmann::json perGeneration = nlohmann::json::array();
  start = Clock::now();
  for (std::size_t g = 0; g < generations && !optimiser.Finished(); ++g)
  {
    const BackendStatistics before = backend->Statistics();
    const auto              generationStart = Clock::now();
    optimiser.RunGeneration();
    const double            seconds = Since(generationStart);
    const BackendStatistics after = backend->Statistics();
    memoryPeak = std::max(memoryPeak, CudaMemoryInUse());
    const GenerationRecord & r = optimiser.History().back();
    perGeneration.push_back({ { "generation", r.generation },
                              { "seconds", seconds },
                              { "backend_seconds", after.seconds - before.seconds },
                              { "kernel_seconds", after.kernelSeconds - before.kernelSeconds },
                              { "setup_kernel_seconds", after.setUpKernelSeconds - before.setUpKernelSeconds },
                              { "backend_host_seconds",
                                { { "staging", after.stagingSeconds - before.stagingSeconds },
                                  { "waiting", after.waitSeconds - before.waitSeconds },
                                  { "unpacking", after.unpackSeconds - before.unpackSeconds } } },
                              { "tetrahedra", after.tetrahedra - before.tetrahedra },
                              { "samples", after.samples - before.samples },
                              { "bound_skipped_samples", after.boundSkippedSamples - before.boundSkippedSamples },
                              { "batches", after.batches - before.batches },
                              { "parents_uploaded", after.parentsUploaded - before.parentsUploaded },
                              { "batch_span_seconds", after.BatchSpanSeconds() - before.BatchSpanSeconds() },
                              { "device_phase_seconds", DevicePhasesJson(before, after) },
                              { "best_guidance", r.bestGuidance },
                              { "hypervolume", r.hypervolume },
                              { "archive", r.archiveSize },
                              { "candidates", r.candidates },
                              { "folded", r.folded },
                              { "repaired", r.repaired },
                              { "forced_improvements", r.forcedImprovements },
                              { "phase_seconds",
                                { { "sampling", r.phaseSeconds.sampling },
                                  { "fold_checks_and_repair", r.phaseSeconds.foldChecks },
                                  { "evaluation", r.phaseSeconds.evaluation },
                                  { "acceptance", r.phaseSeconds.acceptance },
                                  { "forced_improvements", r.phaseSeconds.forcedImprovements },
                                  { "modelling", r.phaseSeconds.modelling },
                                  { "bookkeeping", r.phaseSeconds.bookkeeping } } } });
    std::cout << "    generation " << r.generation << ": " << std::fixed << std::setprecision(3) << seconds
              << " s (backend " << after.seconds - before.seconds << " s, kernels "
              << after.kernelSeconds - before.kernelSeconds << " s, staging "
              << after.stagingSeconds - before.stagingSeconds << ", waiting " << after.waitSeconds - before.waitSeconds
              << ", unpacking " << after.unpackSeconds - before.unpackSeconds << ", parents uploaded "
              << after.parentsUploaded - before.parentsUploaded << ", batch spans "
              << after.BatchSpanSeconds() - before.BatchSpanSeconds() << "; sampling " << r.phaseSeconds.sampling
              << ", folds " << r.phaseSeconds.foldChecks << ", acceptance " << r.phaseSeconds.acceptance
              << ", forced " << r.phaseSeconds.forcedImprovements << ", modelling " << r.phaseSeconds.modelling
              << ", bookkeeping " << r.phaseSeconds.bookkeeping << "), best guidance " << std::defaultfloat
              << r.bestGuidance << "\n"
              << std::flush;
  }
  const double            secondsGenerations = Since(start);
  const BackendStatistics total = backend->Statistics();
  const double            tetrahedra = static_cast<double>(total.tetrahedra - afterInit.tetrahedra);
  const double            samples = total.samples - afterInit.samples;
  const double            kernel = total.kernelSeconds - afterInit.kernelSeconds;
  const std::size_t       done = perGeneration.size();
  nlohmann::json          out{ { "backend", backend->Name() },
                      { "refusal_bounds", gomea.boundRefusals },
                      { "draw_ahead_threads", optimiser.DrawAheadThreads() },
                      { "bound_skipped_samples", total.boundSkippedSamples - afterInit.boundSkippedSamples },
                      { "samples_sampled_later",
                        total.boundSampledLaterSamples - afterInit.boundSampledLaterSamples },
                      { "parts_sampled_again", total.partsSampledAgain - afterInit.partsSampledAgain },
                      { "threads", threads ? threads : morea_core::HostThreads() },
                      { "first_generation", firstGeneration },
                      { "seconds_initial_population", secondsPopulation },
                      { "seconds_initial_evaluation", secondsInitialEvaluation },
                      { "generations", done },
                      { "seconds_generations", secondsGenerations },
                      { "seconds_per_generation", done ? secondsGenerations / static_cast<double>(done) : 0.0 },
                      { "seconds_in_backend", total.seconds - afterInit.seconds },
                      { "seconds_in_kernels", kernel },
                      { "seconds_in_setup_kernels", total.setUpKernelSeconds - afterInit.setUpKernelSeconds },
                      { "tetrahedron_evaluations", tetrahedra },
                      { "samples", samples },
                      { "tetrahedron_evaluations_per_second", secondsGenerations > 0 ? tetrahedra / secondsGenerations : 0.0 },
                      { "samples_per_second_wall", secondsGenerations > 0 ? samples / secondsGenerations : 0.0 },
                      { "samples_per_second_kernel", kernel > 0 ? samples / kernel : 0.0 },
                      { "gpu_memory_peak_bytes", memoryPeak - memoryBefore },
                      { "gpu_memory_estimate_bytes", memoryEstimate.Device(gomea.populationSize) },
                      { "host_memory_estimate_bytes", memoryEstimate.Host(gomea.populationSize) },
                      { "device_phase_seconds", DevicePhasesJson(afterInit, total) },
                      { "archive_size", optimiser.Archive().Size() },
                      { "per_generation", perGeneration } };
  return out;
}
} // namespace

void
AddBenchmarkCommand(CLI::App & app)
{
  struct Options
  {
    ProblemOptions   problem;
    ParameterOptions parameters;
    std::string      output;
    std::string      backends{ "cuda,cpu" };
    std::size_t      generations{ 0 };
    std::size_t      cpuGenerations{ 2 };
    std::size_t      threads{ 0 };
    bool             probe{ true };
    std::string      checkpoint;
    std::string      refusalBound{ "auto" };
    std::string      drawAhead{ "auto" };
  };
  auto   options = std::make_shared<Options>();
  auto * cmd = app.add_subcommand("benchmark", "time MO-RV-GOMEA with the CUDA and CPU backends on a problem");
  options->problem.AddTo(*cmd);
  options->parameters.AddTo(*cmd);
  cmd->add_option("-o,--output", options->output, "JSON file for the results")->required();
  cmd->add_option("--backends", options->backends, "comma-separated: cuda (the texture path; also cuda-texture), cuda-exact, cpu")->capture_default_str();
  cmd->add_option("--generations", options->generations, "generations of the CUDA run (0: ea_num_generations)")
    ->capture_default_str();
  cmd->add_option("--cpu-generations", options->cpuGenerations, "generations of the CPU run (the same first ones)")
    ->capture_default_str();
  cmd->add_option("--threads", options->threads, "CPU threads (0: all)")->capture_default_str();
  cmd->add_option("--from-checkpoint", options->checkpoint,
                  "start each run from this checkpoint of `morea register` (the same problem and parameters)")
    ->check(CLI::ExistingFile);
  cmd->add_option("--refusal-bound", options->refusalBound,
                  "skip candidates a bound shows refused: on, off, or auto (on with the cpu backend)")
    ->check(CLI::IsMember({ "auto", "on", "off" }))
    ->capture_default_str();
  cmd->add_option("--draw-ahead", options->drawAhead,
                  "threads that draw batches of candidates ahead, beside the optimiser's pool: auto, or a count (0: "
                  "none)")
    ->check(CLI::IsMember({ "auto" }) | CLI::NonNegativeNumber)
    ->capture_default_str();
  cmd->add_option("--probe", options->probe, "measure the GPU's coherent trilinear fetch rate")->capture_default_str();
  cmd->callback([options] {
    const auto parameters = options->parameters.Load();
    CheckRunMemory(parameters); // an absurd population before any work
    const auto start = Clock::now();
    const auto input = options->problem.Load();
    const auto preprocessed = itk::morea::Preprocess(input, itk::morea::PreprocessOptions::FromParameters(parameters));
    itk::morea::CheckGuidanceStructuresKept(preprocessed.report, parameters); // as morea register does
    const auto & r = preprocessed.report;
    const double voxels = static_cast<double>(r.size[0]) * r.size[1] * r.size[2];
    std::cout << "preprocessed: " << r.size[0] << "x" << r.size[1] << "x" << r.size[2] << " = " << voxels
              << " voxels of " << r.spacing << " mm (" << Since(start) << " s)\n";
    auto       modelStart = Clock::now();
    const auto model = itk::morea::BuildMeshModel(preprocessed.problem, parameters);
    const ObjectiveData data = itk::morea::BuildObjectiveData(preprocessed.problem, model, parameters);
    const FoldConstraint constraint(model.topology, model.base.points, parameters.GetReal("morea_fold_volume_fraction"));
    const TetrahedronEvaluator evaluator(model.topology, constraint, model.elasticity, model.rigidity, data);
    GomeaOptions               gomea = GomeaOptions::FromParameters(parameters);
    gomea.fingerprint = itk::morea::RunFingerprintOf(preprocessed.problem, parameters); // as morea register's checkpoints
    if (options->drawAhead != "auto")
      gomea.drawAheadThreads = static_cast<std::size_t>(std::stoul(options->drawAhead));
    const auto                 initial = InitialPopulationOptions::FromParameters(parameters);
    std::cout << "mesh: " << model.base.NumberOfPoints() << " points, " << model.base.NumberOfTetrahedra()
              << " tetrahedra, " << model.parallel.elements.size() << " FOS elements in "
              << model.parallel.groups.size() << " parallel groups (" << Since(modelStart) << " s)\n";

    nlohmann::json report{ { "voxels", voxels },
                           { "size", { r.size[0], r.size[1], r.size[2] } },
                           { "spacing_mm", r.spacing },
                           { "mesh_points", model.base.NumberOfPoints() },
                           { "tetrahedra", model.base.NumberOfTetrahedra() },
                           { "fos_elements", model.parallel.elements.size() },
                           { "parallel_groups", model.parallel.groups.size() },
                           { "population", gomea.populationSize },
                           { "clusters", gomea.numberOfClusters },
                           { "archive_capacity", gomea.archiveCapacity },
                           { "sampling_rate", data.samplingRate },
                           { "guidance_structures", data.NumberOfGuidanceStructures() } };
    const auto devices = ListCudaDevices();
    if (!devices.empty())
      report["device"] = devices.front().name;
    if (options->probe && !devices.empty())
    {
      const double rate = MeasureTrilinearFetchRate();
      report["trilinear_fetches_per_second"] = rate;
      std::cout << "coherent trilinear texture fetches: " << rate << " per second\n";
    }
    std::stringstream list(options->backends);
    for (std::string name; std::getline(list, name, ',');)
    {
      const std::size_t generations =
        name == "cpu" ? options->cpuGenerations : (options->generations ? options->generations : gomea.generations);
      std::cout << "timing " << name << " for " << generations << " generations\n";
      report["runs"][name] = TimeBackend(name, model, evaluator, gomea, initial, generations, options->threads,
                                          options->checkpoint, ParseRefusalBoundChoice(options->refusalBound));
    }
    if (report.contains("runs") && report["runs"].contains("cuda") && report["runs"].contains("cpu"))
    {
      // The same first generations on both: the ratio of their mean times.
      const auto &      cuda = report["runs"]["cuda"]["per_generation"];
      const auto &      cpu = report["runs"]["cpu"]["per_generation"];
      const std::size_t n = std::min(cuda.size(), cpu.size());
      double            a = 0.0, b = 0.0;
      for (std::size_t i = 0; i < n; ++i)
      {
        a += cuda[i]["seconds"].get<double>();
        b += cpu[i]["seconds"].get<double>();
      }
      if (n > 0 && a > 0.0)
      {
        report["cpu_over_cuda_same_generations"] = b / a;
        report["compared_generations"] = n;
        std::cout << "CPU (" << report["runs"]["cpu"]["threads"] << " threads) / CUDA time over the first " << n
                  << " generations: " << b / a << "\n";
      }
    }
    itk::morea::WriteTextFile(report.dump(2) + "\n", options->output);
    std::cout << "wrote " << options->output << "\n";
  });
}
} // namespace morea_cli
