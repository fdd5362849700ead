// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// `morea evaluate`: scores a registration (or the identity baseline) on a problem.
#include "CommandCommon.h"

#include "itkRegistrationOutputs.h"
#include "itkMOREAImageIO.h"

#include <algorithm>
#include <iostream>
#include <memory>

namespace morea_cli
{
void
AddEvaluateCommand(CLI::App & app)
{
  struct Options
  {
    ProblemOptions   problem;
    ParameterOptions parameters;
    std::string      field;
    std::string      inverseField;
    double           borderMargin{ -1.0 };
    std::string      output;
    std::string      renderPrefix;
    std::string      focus;
  };
  auto   options = std::make_shared<Options>();
  auto * cmd = app.add_subcommand("evaluate", "score a registration: Dice, Hausdorff, HD95, TRE, folding, inverse consistency");
  options->problem.AddTo(*cmd);
  options->parameters.AddTo(*cmd);
  cmd->add_option("--field", options->field,
                  "fixed-to-moving displacement field on the fixed grid (default: identity, the baseline)");
  cmd->add_option("--inverse-field", options->inverseField, "moving-to-fixed displacement field on the moving grid");
  cmd->add_option("--border-margin", options->borderMargin,
                  "mm left out at the image border (default: evaluation_border_margin, 15)");
  cmd->add_option("-o,--output", options->output, "write the scores as JSON");
  cmd->add_option("--render", options->renderPrefix, "write PREFIX_{axial,coronal,sagittal}.png with contours");
  cmd->add_option("--focus", options->focus, "structure the rendered slices go through");
  cmd->callback([options] {
    using namespace itk::morea;
    const auto parameters = options->parameters.Load();
    const auto problem = options->problem.Load();
    DisplacementFieldType::Pointer forward, inverse;
    if (!options->field.empty())
      forward = ReadDisplacementField(options->field);
    if (!options->inverseField.empty())
      inverse = ReadDisplacementField(options->inverseField);
    const double margin =
      options->borderMargin >= 0.0 ? options->borderMargin : parameters.GetReal("evaluation_border_margin");
    const auto scores = EvaluateRegistration(problem, forward, inverse, margin);
    PrintScores(std::cout, scores, forward ? "scores of " + options->field : "baseline scores (identity)");
    if (!options->output.empty())
      WriteJson(itk::morea::ScoresToJson(scores), options->output);
    if (!options->renderPrefix.empty())
      itk::morea::RenderComparison(problem, forward, options->focus, options->renderPrefix);
  });
}
} // namespace morea_cli
