// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// `morea demo`: the default job on the embedded phantom. Generates the phantom,
// preprocesses it, and scores the rigid baseline and the known true
// deformation with the evaluation pipeline.
#include "CommandCommon.h"
#include "ProgressPrinter.h"

#include "FilterRun.h"

#include "itkImageRegionIteratorWithIndex.h"
#include "itkMOREAImageIO.h"
#include "itkPhantomImages.h"
#include "itkPreprocessing.h"
#include "itkRegistrationOutputs.h"
#include "morea_core/ComputeDevices.h"
#include "morea_core/OutputFolderLock.h"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>

namespace morea_cli
{
namespace
{
/** The phantom's true mapping expressed on a preprocessed grid: the fixed frame
 *  is unchanged, the preprocessed moving image is the original one seen through
 *  the rigid map R, so u(x) = R^-1(T(x)) - x and v(y) = T^-1(R(y)) - y. */
itk::morea::DisplacementFieldType::Pointer
TrueField(const PelvisPhantom & phantom, const itk::morea::RegistrationProblem & problem,
          const itk::morea::PreAlignmentTransformType * rigid, bool fixedToMoving)
{
  using namespace itk::morea;
  auto       field = MakeIdentityField(problem.fixedImage);
  const auto rigidInverse = rigid->GetInverseTransform();
  for (itk::ImageRegionIteratorWithIndex<DisplacementFieldType> it(field, field->GetBufferedRegion()); !it.IsAtEnd();
       ++it)
  {
    PointType x;
    field->TransformIndexToPhysicalPoint(it.GetIndex(), x);
    PointType y;
    if (fixedToMoving)
    {
      const Vec3 t = phantom.FixedToMoving({ x[0], x[1], x[2] });
      y = rigidInverse->TransformPoint(PointType(t.data()));
    }
    else
    {
      const PointType r = rigid->TransformPoint(x);
      const Vec3      t = phantom.MovingToFixed({ r[0], r[1], r[2] });
      y = PointType(t.data());
    }
    it.Set(y - x);
  }
  return field;
}
} // namespace

void
AddDemoCommand(CLI::App & app)
{
  struct Options
  {
    std::string      output{ "demo-out" };
    double           spacing{ 2.0 };
    ParameterOptions parameters;
    std::string      refusalBound{ "auto" };
  };
  auto   options = std::make_shared<Options>();
  auto * cmd = app.add_subcommand("demo", "run the default job on the embedded phantom and print its scores");
  cmd->add_option("-o,--output", options->output, "output folder")->capture_default_str();
  cmd->add_option("--phantom-spacing", options->spacing, "voxel size of the generated phantom in mm")
    ->capture_default_str();
  options->parameters.AddTo(*cmd);
  cmd->add_option("--refusal-bound", options->refusalBound,
                  "skip candidates a bound shows refused: on, off, or auto (on with the cpu backend; the same result)")
    ->check(CLI::IsMember({ "auto", "on", "off" }))
    ->capture_default_str();
  cmd->callback([options] {
    using namespace itk::morea;
    namespace fs = std::filesystem;
    const auto start = std::chrono::steady_clock::now();
    auto parameters = options->parameters.Load();
    // A configuration that finishes in a few minutes on 2 cores; any key given
    // on the command line or in a parameter file wins. No shells: at 300 points
    // they take contour points the bladder needs (bladder Dice of the best-guidance
    // solution 0.926 without, 0.897 with; bench/results/mesh-shells.md).
    for (const auto & [key, value] : std::vector<std::pair<std::string, std::string>>{
           { "ea_population_size", "48" },
           { "ea_num_clusters", "4" },
           { "ea_archive_size", "200" },
           { "ea_num_generations", "160" },
           { "ea_adaptive_steering_activated_at_num_generations", "80" },
           { "morea_mesh_num_points", "300" },
           { "morea_mesh_shell_offsets", "" },
           { "morea_sampling_rate", "0.5" },
           { "seed", "1" },
           { "preprocess_isotropic_spacing", "3.0" } })
      if (!parameters.IsExplicit(key))
        parameters.SetFromString(key, value);

    PhantomOptions phantomOptions;
    phantomOptions.spacing = options->spacing;
    const PelvisPhantom phantom(phantomOptions);
    const fs::path      root(options->output);
    const OutputFolderLock ownership(root.string());
    WritePhantomCase(phantom.Generate(), (root / "phantom").string());
    std::cout << "1. phantom written to " << (root / "phantom").string() << "\n";

    ProblemOptions load;
    load.folder = (root / "phantom").string();
    const auto input = load.Load();
    std::cout << "2. registering with MOREA (" << parameters.GetInteger("ea_num_generations") << " generations, population "
              << parameters.GetInteger("ea_population_size") << ", " << parameters.GetInteger("morea_mesh_num_points")
              << " mesh points)\n";
    FilterSettings settings;
    settings.refusalBounds = options->refusalBound;
    settings.onGeneration = ProgressPrinter();
    const auto filter = MakeRegistrationFilter(input, parameters, settings);
    UpdateRegistrationFilter(*filter);
    const auto & run = filter->GetRegistrationRun();
    const auto & result = run.preprocessed;
    const auto & r = result.report;
    std::cout << "3. preprocessed: " << r.size[0] << "x" << r.size[1] << "x" << r.size[2] << " voxels of " << r.spacing
              << " mm around '" << r.cropStructure << "', rigid on '" << r.rigidStructure << "'; evaluated on the "
              << run.registration.backend
              << (run.registration.backendNote.empty() ? "" : " backend (" + run.registration.backendNote + ")")
              << "\n";
    WriteProblemFolder(result.problem, (root / "preprocessed").string());
    WriteRigidTransform(result.rigidTransform, (root / "preprocessed" / "rigid_fixed_to_moving.tfm").string());

    const double margin = parameters.GetReal("evaluation_border_margin");
    const auto   baseline = EvaluateRegistration(result.problem, nullptr, nullptr, margin);
    const auto   forward = TrueField(phantom, result.problem, result.rigidTransform, true);
    const auto   inverse = TrueField(phantom, result.problem, result.rigidTransform, false);
    const auto   truth = EvaluateRegistration(result.problem, forward, inverse, margin);
    WriteDisplacementField(forward, (root / "preprocessed_true_fixed_to_moving.nii.gz").string());
    WriteDisplacementField(inverse, (root / "preprocessed_true_moving_to_fixed.nii.gz").string());
    const auto summary = itk::morea::WriteRegistrationOutputs(run, parameters, (root / "registration").string(), forward);

    std::cout << "4. evaluation\n";
    PrintScores(std::cout, baseline, "   baseline after rigid pre-alignment");
    for (const auto & selected : run.selected)
    {
      const auto & c = selected.choice;
      const auto & entry = summary["solutions"][c.label];
      std::cout << "   MOREA " << c.label << " solution: mean displacement error in the body "
                << entry["mean_displacement_error_in_body_mm"].get<double>() << " mm\n";
      for (const auto & [name, v] : entry["scores"]["structures"].items())
        std::cout << "     " << name << ": Dice " << v["dice"].get<double>() << ", HD95 "
                  << v["hausdorff95_mm"].get<double>() << " mm\n";
    }
    PrintScores(std::cout, truth, "   true deformation (upper bound of what a registration can reach)");
    itk::morea::RenderComparison(result.problem, nullptr, r.cropStructure, (root / "render_baseline").string());
    itk::morea::RenderComparison(result.problem, forward, r.cropStructure, (root / "render_truth").string());
    WriteJson({ { "baseline", itk::morea::ScoresToJson(baseline) }, { "truth", itk::morea::ScoresToJson(truth) }, { "morea", summary } },
              (root / "scores.json").string());
    std::cout << "5. scores.json, registration/ and render_*.png written to " << root.string() << " ("
              << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s)\n";
  });
}

void
AddInfoCommand(CLI::App & app)
{
  auto * cmd = app.add_subcommand("info", "print the build's capabilities and the CUDA devices found");
  cmd->callback([] {
    std::cout << "morea 0.1.0\n";
    std::cout << "CUDA backend in this build: " << (BuiltWithCuda() ? "yes" : "no") << "\n";
    const auto devices = ListCudaDevices();
    if (devices.empty())
      std::cout << "CUDA devices: none (" << CudaUnavailableReason() << ")\n";
    for (const auto & d : devices)
      std::cout << "CUDA device " << d.ordinal << ": " << d.name << ", compute " << d.computeCapabilityMajor << "."
                << d.computeCapabilityMinor << ", " << d.totalMemoryBytes / (1024 * 1024) << " MiB, "
                << d.multiprocessors << " SMs\n";
  });
}
} // namespace morea_cli
