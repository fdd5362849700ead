// Writing a MOREA run's results (shared by `morea register` and `morea demo`).
#ifndef morea_cli_RegistrationOutputs_h
#define morea_cli_RegistrationOutputs_h

#include "CommandCommon.h"

#include "itkMeshRegistration.h"
#include "itkPreprocessing.h"

#include <chrono>
#include <string>
#include <vector>

namespace morea::cli
{
/** A chosen solution of the front and why it was chosen. */
struct ChosenSolution
{
  std::string label; ///< "best_guidance", "knee", ...
  std::size_t index{ 0 }; ///< into the front
};

/** Where a command's time went before its outputs (`morea register`). */
struct CommandTimes
{
  std::chrono::steady_clock::time_point started; ///< the command's start
  double                                load{ 0.0 };          ///< reading the problem
  double                                preprocessing{ 0.0 }; ///< resampling, pre-alignment, cropping
  double                                registration{ 0.0 };  ///< model and optimisation (RegisterMeshes)
};

/** Parses "best-guidance,knee,weighted:1:1:2,nearest:m:i:g,all" into front indices. */
std::vector<ChosenSolution>
ChooseSolutions(const std::vector<itk::morea::FrontSolution> & front, const std::string & selection);

/** A terminal progress line per generation (a bar on a terminal, every 10th
 *  generation otherwise). */
std::function<void(const ::morea::GenerationRecord &, std::size_t)>
ProgressPrinter();

/** Writes front.csv, front.json, generations.csv and, per chosen solution, a
 *  folder with both fields (NIfTI, preprocessed frame), both transforms (.h5,
 *  original images' space), both meshes (.vtu) and, when the fixed structures
 *  are known, scores.json and renders; returns the scores as JSON (also
 *  written to summary.json with the baseline and, where `times` is given,
 *  the seconds of each stage, the outputs' parts included). */
nlohmann::json
WriteRegistrationOutputs(const itk::morea::PreprocessResult & preprocessed,
                         const itk::morea::MeshRegistrationResult & result,
                         const std::vector<ChosenSolution> & chosen, double borderMargin, const std::string & folder,
                         const itk::morea::DisplacementFieldType * trueFixedToMoving = nullptr,
                         const CommandTimes * times = nullptr);
} // namespace morea::cli

#endif
