// Writing a MOREA run's results (shared by `morea register` and `morea demo`).
#ifndef morea_cli_RegistrationOutputs_h
#define morea_cli_RegistrationOutputs_h

#include "CommandCommon.h"

#include "itkMultiObjectiveMeshRegistrationFilterSupport.h"

#include <chrono>
#include <string>
#include <vector>

namespace morea::cli
{
/** Where a command's time went before its outputs (`morea register`). */
struct CommandTimes
{
  std::chrono::steady_clock::time_point started; ///< the command's start
  double                                load{ 0.0 }; ///< reading the problem
};

/** A terminal progress line per generation (a bar on a terminal, every 10th
 *  generation otherwise). */
std::function<void(const ::morea::GenerationRecord &, std::size_t)>
ProgressPrinter();

/** Writes a registration's folder: parameters.toml, the pre-alignment
 *  (rigid_fixed_to_moving.tfm), front.csv, front.json, generations.csv and,
 *  per chosen solution, a folder with both fields (NIfTI, preprocessed
 *  frame), both transforms (.h5, original images' space), both meshes (.vtu)
 *  and, when the fixed structures are known, scores.json and renders; returns
 *  the scores as JSON (also written to summary.json, last, with the baseline,
 *  the backend and why, the run's labels and, where `times` is given, the
 *  seconds of each stage, the outputs' parts included). */
nlohmann::json
WriteRegistrationOutputs(const itk::morea::MultiObjectiveRegistrationRun & run, const ParameterSet & parameters,
                         const std::string & folder,
                         const itk::morea::DisplacementFieldType * trueFixedToMoving = nullptr,
                         const CommandTimes * times = nullptr);
} // namespace morea::cli

#endif
