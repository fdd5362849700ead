// `morea phantom`: writes the synthetic pelvis pair with its ground truth.
#include "CommandCommon.h"

#include "itkPhantomImages.h"

#include <iostream>
#include <memory>

namespace morea::cli
{
void
AddPhantomCommand(CLI::App & app)
{
  struct Options
  {
    std::string    output;
    PhantomOptions phantom;
  };
  auto   options = std::make_shared<Options>();
  auto * cmd = app.add_subcommand("phantom", "write the synthetic pelvis pair (bladder filling) with its ground truth");
  cmd->add_option("-o,--output", options->output, "output folder")->required();
  cmd->add_option("--spacing", options->phantom.spacing, "voxel size in mm")->capture_default_str();
  cmd->add_option("--seed", options->phantom.seed, "noise seed")->capture_default_str();
  cmd->add_option("--noise", options->phantom.noiseSigma, "noise standard deviation in HU")->capture_default_str();
  cmd->add_option("--bladder-growth", options->phantom.bladderGrowth, "linear growth of the bladder, fixed to moving")
    ->capture_default_str();
  cmd->callback([options] {
    const PelvisPhantom phantom(options->phantom);
    const auto          files = itk::morea::WritePhantomCase(phantom.Generate(), options->output);
    nlohmann::json      j;
    j["spacing_mm"] = options->phantom.spacing;
    j["seed"] = options->phantom.seed;
    j["noise_sigma_hu"] = options->phantom.noiseSigma;
    j["bladder_growth"] = options->phantom.bladderGrowth;
    j["structures"] = PelvisPhantom::StructureNames();
    j["true_fixed_to_moving"] = files.trueFixedToMoving;
    j["true_moving_to_fixed"] = files.trueMovingToFixed;
    WriteJson(j, options->output + "/phantom.json");
    std::cout << "phantom written to " << options->output << " (fixed: small bladder, moving: full bladder)\n";
  });
}
} // namespace morea::cli
