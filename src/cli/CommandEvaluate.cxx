// `morea evaluate`: scores a registration (or the identity baseline) on a problem.
#include "CommandCommon.h"

#include "itkContourOverlayRenderer.h"
#include "itkMOREAImageIO.h"
#include "itkMinimumMaximumImageCalculator.h"

#include <algorithm>
#include <iostream>
#include <memory>

namespace morea::cli
{
void
RenderComparison(const itk::morea::RegistrationProblem & problem, const itk::morea::DisplacementFieldType * field,
                 const std::string & focusStructure, const std::string & prefix)
{
  using namespace itk::morea;
  DisplacementFieldType::Pointer identity;
  if (field == nullptr)
  {
    identity = MakeIdentityField(problem.fixedImage);
    field = identity;
  }
  // Fixed contours in green, warped moving contours in magenta; the focus structure first
  // so that the slice goes through it.
  std::vector<const Structure *> order;
  for (const auto & s : problem.structures)
    if (s.fixedMask && s.movingMask && s.name != "body")
      order.push_back(&s);
  std::stable_partition(order.begin(), order.end(), [&](const Structure * s) { return s->name == focusStructure; });
  std::vector<MaskType::Pointer> warped;
  std::vector<ContourLayer>      layers;
  for (const Structure * s : order)
  {
    warped.push_back(WarpMask(s->movingMask, field));
    layers.push_back({ s->fixedMask.GetPointer(), { { 0, 220, 0 } }, s->name + " (fixed)" });
    layers.push_back({ warped.back().GetPointer(), { { 255, 0, 255 } }, s->name + " (moving, warped)" });
  }
  auto range = itk::MinimumMaximumImageCalculator<ImageType>::New();
  range->SetImage(problem.fixedImage);
  range->Compute();
  SliceRenderOptions options;
  if (range->GetMaximum() <= 1.0f && range->GetMinimum() >= 0.0f)
  {
    options.windowMin = 0.0f; // preprocessed images are already windowed to [0,1]
    options.windowMax = 1.0f;
  }
  options.pixelsPerMm = 3.0 / problem.fixedImage->GetSpacing()[0];
  for (const auto & [axis, name] : { std::pair{ SliceAxis::Axial, "axial" }, { SliceAxis::Coronal, "coronal" },
                                     { SliceAxis::Sagittal, "sagittal" } })
  {
    options.axis = axis;
    RenderContourOverlay(problem.fixedImage, layers, options, prefix + "_" + name + ".png");
  }
}

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
      WriteJson(ToJson(scores), options->output);
    if (!options->renderPrefix.empty())
      RenderComparison(problem, forward, options->focus, options->renderPrefix);
  });
}
} // namespace morea::cli
