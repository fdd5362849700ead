// `morea register`: preprocesses a problem, runs MOREA and writes the
// approximation set, the chosen solutions and their scores.
#include "CommandCommon.h"
#include "RegistrationOutputs.h"

#include "itkMOREAImageIO.h"
#include "itkMeshRegistration.h"
#include "itkMultiObjectiveMeshRegistrationFilterSupport.h"
#include "itkPreprocessing.h"
#include "itkRigidPreAlignment.h"
#include "morea/ComputeDevices.h"
#include "morea/Error.h"
#include "morea/EvaluationBackend.h"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

namespace morea::cli
{
void
AddRegisterCommand(CLI::App & app)
{
  struct Options
  {
    ProblemOptions   problem;
    ParameterOptions parameters;
    std::string      output;
    std::string      select{ "best-guidance,knee" };
    std::size_t      checkpointEvery{ 10 };
    bool             resume{ false };
    std::size_t      threads{ 0 };
    std::string      backend{ "auto" };
    std::size_t      killAfter{ 0 };
    std::string      refusalBound{ "auto" };
  };
  auto   options = std::make_shared<Options>();
  auto * cmd = app.add_subcommand("register", "register a problem with MOREA and write the approximation set");
  options->problem.AddTo(*cmd);
  options->parameters.AddTo(*cmd);
  cmd->add_option("-o,--output", options->output, "output folder")->required();
  cmd->add_option("--select", options->select,
                  "solutions to write: best-guidance, knee, weighted:a:b:c, nearest:m:i:g, all (comma-separated)")
    ->capture_default_str();
  cmd->add_option("--checkpoint-every", options->checkpointEvery,
                  "write output/checkpoint.bin every N generations (0: only at the end)")
    ->capture_default_str();
  cmd->add_flag("--resume", options->resume, "continue from output/checkpoint.bin when it exists");
  cmd->add_option("--threads", options->threads, "CPU threads (0: all)")->capture_default_str();
  cmd->add_option("--backend", options->backend,
                  "evaluation backend: cpu, cuda, cuda-texture (hardware interpolation, faster), or auto (cuda when "
                  "a device is present)")
    ->check(CLI::IsMember({ "cpu", "cuda", "cuda-texture", "auto" }))
    ->capture_default_str();
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
    // The device's context is made while the problem is read and preprocessed.
    std::optional<::morea::CudaContextWarmUp> warmUp;
    if (options->backend != "cpu")
      warmUp.emplace();
    auto       secondsSince = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
    const auto parameters = options->parameters.Load();
    itk::morea::CheckSolutionSelection(options->select); // before a long run, not after
    const auto input = options->problem.Load();
    const double secondsLoad = secondsSince(started);
    auto         stage = Clock::now();
    const auto preprocessed = itk::morea::Preprocess(input, itk::morea::PreprocessOptions::FromParameters(parameters));
    const double secondsPreprocess = secondsSince(stage);
    const auto & r = preprocessed.report;
    std::cout << "preprocessed: " << r.size[0] << "x" << r.size[1] << "x" << r.size[2] << " voxels of " << r.spacing
              << " mm around '" << r.cropStructure << "'"
              << (r.rigidStructure.empty() ? std::string() : ", rigid on '" + r.rigidStructure + "'") << "\n";
    // A CUDA backend asked for by name but unusable: said before any output
    // is written (the context warm-up has long finished by now, so this
    // costs the run nothing).
    const ::morea::BackendChoice backend = ::morea::ParseBackendChoice(options->backend);
    if (backend == ::morea::BackendChoice::Cuda || backend == ::morea::BackendChoice::CudaTexture)
      if (const std::string reason = ::morea::CudaUnavailableReason(); !reason.empty())
        throw ::morea::Error("CUDA backend: " + reason + " (--backend auto falls back to the CPU)");
    fs::create_directories(options->output);
    const std::string out = options->output + "/";
    itk::morea::WriteTextFile(parameters.ToToml(), out + "parameters.toml");
    itk::morea::WriteRigidTransform(preprocessed.rigidTransform, out + "rigid_fixed_to_moving.tfm");

    itk::morea::MeshRegistrationOptions run;
    run.checkpointPath = out + "checkpoint.bin";
    run.checkpointInterval = options->checkpointEvery;
    run.resume = options->resume;
    run.threads = options->threads;
    run.backend = backend;
    run.refusalBounds = ::morea::ParseRefusalBoundChoice(options->refusalBound);
    run.onGeneration = [print = ProgressPrinter(), killAfter = options->killAfter](
                         const ::morea::GenerationRecord & r, std::size_t total) {
      print(r, total);
      if (killAfter > 0 && r.generation == killAfter)
        std::raise(SIGKILL);
    };
    stage = Clock::now();
    const auto result = itk::morea::RegisterMeshes(preprocessed.problem, parameters, run);
    const double secondsRegister = secondsSince(stage);
    if (result.resumedAtGeneration > 0)
      std::cout << "resumed from generation " << result.resumedAtGeneration << "\n";
    std::cout << "mesh " << result.model.base.NumberOfPoints() << " points, " << result.model.base.NumberOfTetrahedra()
              << " tetrahedra (" << result.secondsModel << " s); optimisation " << result.secondsOptimisation
              << " s on the " << result.backend << " backend (" << result.threads << " threads); front of " << result.front.size()
              << "\n";

    const auto chosen = ChooseSolutions(result.front, options->select);
    const CommandTimes times{ started, secondsLoad, secondsPreprocess, secondsRegister };
    const auto summary = WriteRegistrationOutputs(preprocessed, result, chosen,
                                                  parameters.GetReal("evaluation_border_margin"), options->output,
                                                  nullptr, &times);
    for (const auto & c : chosen)
    {
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
              << seconds["outputs"].get<double>() << " s, command " << seconds["command"].get<double>() << " s\n";
    std::cout << "written to " << options->output << "\n";
  });
}
} // namespace morea::cli
