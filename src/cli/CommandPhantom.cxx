// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// `morea phantom`: writes a case of the synthetic pelvis suite with its ground truth.
#include "CommandCommon.h"

#include "itkPhantomImages.h"

#include <iostream>
#include <memory>

namespace morea_cli
{
void
AddPhantomCommand(CLI::App & app)
{
  struct Options
  {
    std::string    output;
    std::string    caseName{ "pelvis" };
    PhantomOptions phantom;
    double         growth{ 0.0 };
  };
  auto   options = std::make_shared<Options>();
  auto * cmd = app.add_subcommand("phantom", "write a synthetic pelvis case (default: the bladder fills) with its ground truth");
  cmd->add_option("-o,--output", options->output, "output folder")->required();
  cmd->add_option("--case", options->caseName,
                  "pelvis (bladder fills, table moves), bladder-emptying (full to empty, bowel descends), "
                  "gas-pocket (gas in the moving rectum only), static-bones (bladder fills, bones do not move)")
    ->capture_default_str();
  cmd->add_option("--spacing", options->phantom.spacing, "voxel size in mm")->capture_default_str();
  cmd->add_option("--seed", options->phantom.seed, "noise seed")->capture_default_str();
  cmd->add_option("--noise", options->phantom.noiseSigma, "noise standard deviation in HU")->capture_default_str();
  auto * growth = cmd->add_option("--bladder-growth", options->growth,
                                  "linear growth of the deforming organ, fixed to moving (default: the case's; "
                                  "pelvis 1.9, bladder-emptying 0.45, gas-pocket 3.5, static-bones 1.7)");
  cmd->callback([options, growth] {
    PhantomOptions phantomOptions = PhantomOptions::OfCase(options->caseName);
    phantomOptions.spacing = options->phantom.spacing;
    phantomOptions.seed = options->phantom.seed;
    phantomOptions.noiseSigma = options->phantom.noiseSigma;
    if (growth->count() > 0)
      phantomOptions.bladderGrowth = options->growth;
    const PelvisPhantom phantom(phantomOptions);
    const auto          phantomCase = phantom.Generate();
    const auto          files = itk::morea::WritePhantomCase(phantomCase, options->output);
    nlohmann::json      j;
    j["spacing_mm"] = phantomOptions.spacing;
    j["seed"] = phantomOptions.seed;
    j["noise_sigma_hu"] = phantomOptions.noiseSigma;
    j["bladder_growth"] = phantomOptions.bladderGrowth;
    j["structures"] = PelvisPhantom::StructureNames();
    j["true_fixed_to_moving"] = files.trueFixedToMoving;
    j["true_moving_to_fixed"] = files.trueMovingToFixed;
    j["case"] = phantomOptions.caseName;
    j["landmark_kinds"] = phantomCase.landmarkKinds;
    WriteJson(j, options->output + "/phantom.json");
    std::cout << phantomOptions.caseName << " phantom written to " << options->output << "\n";
  });
}
} // namespace morea_cli
