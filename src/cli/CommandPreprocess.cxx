// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// `morea preprocess`: resample, pre-align, crop, window; writes a problem folder.
#include "CommandCommon.h"

#include "itkPreprocessing.h"

#include <iostream>
#include <memory>

namespace morea_cli
{
namespace
{
nlohmann::json
ReportToJson(const itk::morea::PreprocessReport & r)
{
  nlohmann::json j;
  j["rigid_structure"] = r.rigidStructure;
  j["rigid"] = { { "translation_mm", { r.rigid.translation[0], r.rigid.translation[1], r.rigid.translation[2] } },
                 { "rotation_deg", r.rigid.rotationDegrees },
                 { "iterations", r.rigid.iterations },
                 { "metric_initial", r.rigid.initialMetric },
                 { "metric_final", r.rigid.finalMetric },
                 { "seconds", r.rigid.seconds } };
  j["crop_structure"] = r.cropStructure;
  j["dropped_structures"] = r.droppedStructures;
  j["size"] = { r.size[0], r.size[1], r.size[2] };
  j["spacing_mm"] = r.spacing;
  j["origin_mm"] = { r.origin[0], r.origin[1], r.origin[2] };
  j["seconds"] = r.secondsTotal;
  return j;
}
} // namespace

void
AddPreprocessCommand(CLI::App & app)
{
  struct Options
  {
    ProblemOptions   problem;
    ParameterOptions parameters;
    std::string      output;
  };
  auto   options = std::make_shared<Options>();
  auto * cmd = app.add_subcommand("preprocess", "resample, pre-align, crop and window a problem (SPEC 4.1-4.2)");
  options->problem.AddTo(*cmd);
  options->parameters.AddTo(*cmd);
  cmd->add_option("-o,--output", options->output, "output problem folder")->required();
  cmd->callback([options] {
    const auto parameters = options->parameters.Load();
    const auto input = options->problem.Load();
    const auto result = itk::morea::Preprocess(input, itk::morea::PreprocessOptions::FromParameters(parameters));
    WriteProblemFolder(result.problem, options->output);
    itk::morea::WriteRigidTransform(result.rigidTransform, options->output + "/rigid_fixed_to_moving.tfm");
    WriteJson(ReportToJson(result.report), options->output + "/preprocess.json");
    const auto & r = result.report;
    std::cout << "preprocessed: " << r.size[0] << "x" << r.size[1] << "x" << r.size[2] << " voxels of " << r.spacing
              << " mm, cropped to '" << (r.cropStructure.empty() ? "(whole image)" : r.cropStructure) << "'";
    if (!r.rigidStructure.empty())
      std::cout << ", rigid on '" << r.rigidStructure << "' (translation " << r.rigid.translation[0] << " "
                << r.rigid.translation[1] << " " << r.rigid.translation[2] << " mm, rotation " << r.rigid.rotationDegrees
                << " deg)";
    std::cout << ", " << r.secondsTotal << " s\n";
    for (const auto & name : r.droppedStructures)
      std::cout << "note: structure '" << name << "' lies outside the crop and was left out\n";
    std::cout << "written to " << options->output << "\n";
  });
}
} // namespace morea_cli
