// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// `morea register`: preprocesses a problem, runs MOREA and writes the
// approximation set, the chosen solutions and their scores.
#include "CommandCommon.h"
#include "ProgressPrinter.h"

#include "FilterRun.h"
#include "ZipArchive.h"

#include "itkMOREAImageIO.h"
#include "itkMultiThreaderBase.h"
#include "itkRegistrationOutputs.h"
#include "morea_core/CheckpointWriter.h"
#include "morea_core/ComputeDevices.h"
#include "morea_core/OutputFolderLock.h"
#include "morea_core/ThreadPool.h"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

namespace morea_cli
{
namespace
{
struct Options
{
  ProblemOptions             problem;
  ParameterOptions           parameters;
  std::string                output;
  std::string                select{ "best-guidance,knee" };
  std::string                checkpointEvery{ "30s" };
  bool                       resume{ false };
  std::size_t                threads{ 0 };
  std::string                backend{ "auto" };
  std::optional<std::size_t> device;
  std::size_t                killAfter{ 0 };
  std::string                refusalBound{ "auto" };
  std::string                initialTransform;
};

/** Whether `folder` holds nothing but an output folder's lock file. */
bool
OnlyLockFileIn(const std::string & folder)
{
  std::error_code ec;
  for (const auto & entry : std::filesystem::directory_iterator(folder, ec))
    if (entry.path().filename() != OutputFolderLock::FileName)
      return false;
  return !ec;
}

/** One registration through the filter, its folder written and its scores printed. */
void
RegisterOnce(const itk::morea::RegistrationProblem & input, const ParameterSet & parameters, const Options & options,
             const RegistrationFilterType::InitialTransformType * initialTransform, const std::string & folder,
             const itk::morea::RegistrationOutputTimes & times)
{
  namespace fs = std::filesystem;
  const bool createdFolder = !fs::exists(folder);
  std::optional<OutputFolderLock> ownership(std::in_place, folder);
  FilterSettings settings;
  settings.backend = options.backend;
  settings.threads = options.threads;
  settings.refusalBounds = options.refusalBound;
  settings.selection = options.select;
  settings.checkpointFile = folder + "/checkpoint.bin";
  const auto schedule = morea_core::CheckpointSchedule::Parse(options.checkpointEvery);
  settings.checkpointInterval = schedule.generations;
  settings.checkpointSeconds = schedule.seconds;
  settings.resume = options.resume;
  settings.initialTransform = initialTransform;
  settings.onGeneration = [print = ProgressPrinter(), killAfter = options.killAfter](
                            const morea_core::GenerationRecord & r, std::size_t total) {
    print(r, total);
    if (killAfter > 0 && r.generation == killAfter)
      std::raise(SIGKILL);
  };
  const auto filter = MakeRegistrationFilter(input, parameters, settings);
  try
  {
    UpdateRegistrationFilter(*filter);
  }
  catch (...)
  {
    // A run that failed before its first checkpoint leaves no folder behind.
    ownership.reset();
    std::error_code ec;
    if (createdFolder && OnlyLockFileIn(folder))
      fs::remove_all(folder, ec);
    throw;
  }
  const auto & run = filter->GetRegistrationRun();
  const auto & r = run.preprocessed.report;
  const auto & result = run.registration;
  std::cout << "preprocessed: " << r.size[0] << "x" << r.size[1] << "x" << r.size[2] << " voxels of " << r.spacing
            << " mm around '" << r.cropStructure << "'"
            << (r.rigidStructure.empty() ? std::string() : ", rigid on '" + r.rigidStructure + "'")
            << (r.initialTransform.empty() ? std::string() : ", pre-aligned by the " + r.initialTransform + " given")
            << "\n";
  if (!r.rigid.intensitySkipped.empty())
    std::cout << "note: rigid pre-alignment without its intensity stage: " << r.rigid.intensitySkipped << "\n";
  if (result.resumedAtGeneration > 0)
    std::cout << "resumed from generation " << result.resumedAtGeneration << "\n";
  std::cout << "backend: " << result.backend << (result.backendNote.empty() ? "" : " (" + result.backendNote + ")")
            << "\n";
  if (!result.pathNote.empty())
    std::cout << "warning: " << result.pathNote << "\n";
  std::cout << "mesh " << result.model.base.NumberOfPoints() << " points, " << result.model.base.NumberOfTetrahedra()
            << " tetrahedra (" << result.secondsModel << " s); optimisation " << result.secondsOptimisation
            << " s on the " << result.backend << " backend (" << result.threads << " threads); front of "
            << result.front.size() << "\n";
  for (const auto & note : result.model.report.notes) // e.g. a surface constraint TetGen could not keep
    std::cout << "note: mesh: " << note << "\n";

  const auto summary = itk::morea::WriteRegistrationOutputs(run, parameters, folder, nullptr, &times);
  for (const auto & selected : run.selected)
  {
    const auto & c = selected.choice;
    const auto & s = result.front[c.index];
    std::cout << c.label << ": id " << s.id << ", magnitude " << s.fitness.objectives[0] << ", intensity "
              << s.fitness.objectives[1] << ", guidance " << s.fitness.objectives[2] << "\n";
    if (summary.contains("solutions") && summary["solutions"][c.label].contains("scores"))
      for (const auto & [name, v] : summary["solutions"][c.label]["scores"]["structures"].items())
        std::cout << "  " << name << ": Dice " << v["dice"].get<double>() << " (rigid "
                  << summary["rigid_baseline"]["structures"][name]["dice"].get<double>() << "), HD95 "
                  << v["hausdorff95_mm"].get<double>() << " mm (rigid "
                  << summary["rigid_baseline"]["structures"][name]["hausdorff95_mm"].get<double>() << ")\n";
  }
  const auto & seconds = summary["seconds"];
  std::cout << "times: load " << seconds["load"].get<double>() << " s, preprocessing "
            << seconds["preprocessing"].get<double>() << " s, model " << seconds["model"].get<double>()
            << " s, optimisation " << seconds["optimisation"].get<double>() << " s, outputs "
            << seconds["fields"].get<double>() + seconds["outputs"].get<double>() << " s, command "
            << seconds["command"].get<double>() << " s\n";
  std::cout << "written to " << folder << "\n";
}
} // namespace

void
AddRegisterCommand(CLI::App & app)
{
  auto   options = std::make_shared<Options>();
  auto * cmd = app.add_subcommand("register", "register a problem with MOREA and write the approximation set");
  options->problem.AddTo(*cmd);
  options->parameters.AddTo(*cmd);
  cmd->add_option("-o,--output", options->output, "output folder")->required();
  cmd->add_option("--select", options->select,
                  "solutions to write: best-guidance, knee, weighted:a:b:c, nearest:m:i:g, spread:N (N solutions spread over the front), all (comma-separated)")
    ->capture_default_str();
  cmd->add_option("--checkpoint-every", options->checkpointEvery,
                  "write output/checkpoint.bin every N generations (10), every so long (30s, 5min: at the first "
                  "generation that ends that long after the last checkpoint), or 0: only at the end")
    ->check(
      [](const std::string & text) {
        try
        {
          morea_core::CheckpointSchedule::Parse(text);
          return std::string();
        }
        catch (const std::exception & e)
        {
          return std::string(e.what());
        }
      },
      "N, Ns, Nmin")
    ->capture_default_str();
  cmd->add_flag("--resume", options->resume, "continue from output/checkpoint.bin when it exists");
  cmd->add_option("--threads", options->threads, "host threads for every stage of the run (0: all)")->capture_default_str();
  cmd->add_option("--backend", options->backend,
                  "where solutions are evaluated: auto (the GPU's texture path when a usable CUDA device is present, "
                  "else the CPU), cuda (the texture path), cuda-exact (software interpolation on the GPU, for "
                  "verification) or cpu")
    ->check(CLI::IsMember({ "auto", "cuda", "cuda-texture", "cuda-exact", "cpu" }))
    ->capture_default_str();
  cmd->add_option("--device", options->device, "CUDA device ordinal (sets cuda_gpu_id)");
  cmd->add_option("--initial-transform", options->initialTransform,
                  "a linear transform (ITK .tfm/.h5/.txt, ANTs .mat, 3D Slicer) mapping fixed points to moving "
                  "points, used instead of the rigid pre-alignment")
    ->check(CLI::ExistingFile);
  cmd->add_option("--refusal-bound", options->refusalBound,
                  "skip sampling candidates that a lower bound of their objectives shows refused: on, off, or auto "
                  "(on with the cpu backend; the same result either way)")
    ->check(CLI::IsMember({ "auto", "on", "off" }))
    ->capture_default_str();
  // For crash-recovery tests: the process kills itself (SIGKILL) right after
  // generation N, as an external kill would, leaving only the checkpoint.
  cmd->add_option("--kill-after-generation", options->killAfter)->group("");
  cmd->callback([options] {
    namespace fs = std::filesystem;
    using Clock = std::chrono::steady_clock;
    const auto started = Clock::now();
    // --threads holds for every stage (reading, preprocessing, outputs, ITK's
    // filters), not only the optimiser: registrations side by side on one
    // host (a batch, one per GPU) keep to their share of the cores.
    if (options->threads > 0)
    {
      morea_core::SetHostThreadLimit(options->threads);
      itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(static_cast<itk::ThreadIdType>(options->threads));
    }
    auto       parameters = options->parameters.Load();
    if (options->device)
      parameters.SetFromString("cuda_gpu_id", std::to_string(*options->device));
    // The device's context is made while the problem is read and preprocessed.
    std::optional<morea_core::CudaContextWarmUp> warmUp;
    if (options->backend != "cpu")
      warmUp.emplace(static_cast<int>(parameters.GetInteger("cuda_gpu_id")));
    itk::morea::CheckSolutionSelection(options->select); // before a long run, not after
    RegistrationFilterType::InitialTransformType::Pointer initialTransform;
    if (!options->initialTransform.empty())
      initialTransform = ReadTransformFile(options->initialTransform);
    const auto   input = options->problem.Load();
    const double secondsLoad = std::chrono::duration<double>(Clock::now() - started).count();

    // num_runs registrations with consecutive seeds, each in a folder of its
    // own when there are several; zip = true archives the output folder.
    const auto runs = parameters.GetInteger("num_runs");
    const bool zip = parameters.GetBool("zip");
    if (runs > 1)
    {
      fs::create_directories(options->output);
      itk::morea::WriteTextFile(parameters.ToToml(), options->output + "/parameters.toml");
    }
    for (std::int64_t k = 0; k < runs; ++k)
    {
      ParameterSet run = parameters;
      run.SetFromString("num_runs", "1");
      run.SetFromString("zip", "false");
      run.SetFromString("seed", std::to_string(parameters.GetInteger("seed") + k));
      const std::string folder = runs > 1 ? options->output + "/run_" + std::to_string(k + 1) : options->output;
      if (runs > 1)
        std::cout << "run " << k + 1 << " of " << runs << " (seed " << run.GetInteger("seed") << ") in " << folder
                  << "\n";
      RegisterOnce(input, run, *options, initialTransform, folder, { started, secondsLoad });
    }
    if (zip)
    {
      const std::string archive = ZipFolder(options->output);
      std::cout << "archived to " << archive << "\n";
    }
  });
}
} // namespace morea_cli
