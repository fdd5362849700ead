// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkMultiObjectiveMeshRegistrationFilterSupport.h"

#include "morea_core/Error.h"
#include "morea_core/MemoryEstimate.h"
#include "morea_core/ParameterSet.h"
#include "morea_core/ParetoFront.h"

#include <algorithm>
#include <chrono>
#include <future>
#include <ostream>
#include <sstream>

namespace itk
{
namespace morea
{
namespace
{
const char * const SelectionHelp = "best-guidance, knee, weighted:a:b:c, nearest:m:i:g, spread:N, all";

morea_core::ObjectiveVector
ParseTriple(const std::string & item, const std::string & text)
{
  std::vector<std::string> parts;
  std::istringstream       in(text);
  for (std::string part; std::getline(in, part, ':');)
    parts.push_back(part);
  morea_core::ObjectiveVector v{};
  try
  {
    if (parts.size() != 3)
      throw std::invalid_argument(text);
    for (std::size_t m = 0; m < 3; ++m)
    {
      std::size_t used = 0;
      v[m] = std::stod(parts[m], &used);
      if (used != parts[m].size())
        throw std::invalid_argument(parts[m]);
    }
  }
  catch (const std::exception &)
  {
    throw morea_core::Error("selection: '" + item + "' needs three numbers (magnitude:intensity:guidance)");
  }
  return v;
}

std::size_t
ParseCount(const std::string & item, const std::string & text)
{
  // Digits only (stoul would take "-1" or " 3"), at most 9 of them (no overflow).
  const bool digits =
    !text.empty() && text.size() <= 9 && std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
  const std::size_t count = digits ? std::stoul(text) : 0;
  if (count == 0)
    throw morea_core::Error("selection: '" + item + "' needs a whole number of solutions, at least 1 (spread:N)");
  return count;
}

/** Walks the selection; `add` gets each choice. With an empty `objectives`
 *  only the syntax is checked (no index is computed). */
void
ForEachChoice(const std::string & selection, const std::vector<morea_core::ObjectiveVector> & objectives,
              const std::function<void(const std::string &, std::size_t)> & add)
{
  const bool check = objectives.empty();
  bool       any = false;
  for (const std::string & item : morea_core::ParseNameList(selection))
  {
    any = true;
    if (item == "best-guidance")
    {
      if (!check)
        add("best_guidance", morea_core::SelectBestGuidance(objectives));
    }
    else if (item == "knee")
    {
      if (!check)
        add("knee", morea_core::SelectKnee(objectives));
    }
    else if (item == "all")
    {
      for (std::size_t i = 0; i < objectives.size(); ++i)
        add({}, i); // labelled by the caller, which knows the ids
    }
    else if (item.rfind("weighted:", 0) == 0)
    {
      const auto weights = ParseTriple(item, item.substr(9));
      if (!check)
        add("weighted", morea_core::SelectWeighted(objectives, weights));
    }
    else if (item.rfind("nearest:", 0) == 0)
    {
      const auto point = ParseTriple(item, item.substr(8));
      if (!check)
        add("nearest", morea_core::SelectNearest(objectives, point));
    }
    else if (item.rfind("spread:", 0) == 0)
    {
      const std::size_t count = ParseCount(item, item.substr(7));
      if (!check)
        for (std::size_t index : morea_core::SelectSpread(objectives, count))
          add({}, index); // labelled by the caller, as with "all"
    }
    else
      throw morea_core::Error("selection: unknown choice '" + item + "' (" + SelectionHelp + ")");
  }
  if (!any)
    throw morea_core::Error(std::string("selection: no solution named (") + SelectionHelp + ")");
}
} // namespace

bool
operator==(const ApproximationSolution & a, const ApproximationSolution & b)
{
  return a.id == b.id && a.objectives == b.objectives && a.constraint == b.constraint;
}

bool
operator!=(const ApproximationSolution & a, const ApproximationSolution & b)
{
  return !(a == b);
}

std::ostream &
operator<<(std::ostream & os, const ApproximationSolution & s)
{
  return os << "id " << s.id << ": magnitude " << s.objectives[0] << ", intensity " << s.objectives[1]
            << ", guidance " << s.objectives[2] << ", constraint " << s.constraint;
}

ApproximationSet
ToApproximationSet(const std::vector<FrontSolution> & front)
{
  ApproximationSet set;
  set.reserve(front.size());
  for (const auto & s : front)
    set.push_back({ s.id, s.fitness.objectives, s.fitness.constraint });
  return set;
}

void
CheckSolutionSelection(const std::string & selection)
{
  ForEachChoice(selection, {}, [](const std::string &, std::size_t) {});
}

std::vector<SolutionChoice>
SelectSolutions(const ApproximationSet & set, const std::string & selection)
{
  CheckSolutionSelection(selection);
  if (set.empty())
    throw morea_core::Error("the approximation set is empty: no fold-free solution was found");
  std::vector<morea_core::ObjectiveVector> objectives;
  for (const auto & s : set)
    objectives.push_back(s.objectives);
  std::vector<SolutionChoice> chosen;
  ForEachChoice(selection, objectives, [&](const std::string & label, std::size_t index) {
    const std::string name = label.empty() ? "solution_" + std::to_string(set[index].id) : label;
    // One output pair per label: "knee,knee" or "all,all" do not duplicate.
    if (std::none_of(chosen.begin(), chosen.end(), [&](const SolutionChoice & c) { return c.label == name; }))
      chosen.push_back({ name, index });
  });
  return chosen;
}

void
CheckSingleRunParameters(const morea_core::ParameterSet & parameters)
{
  if (const auto runs = parameters.GetInteger("num_runs"); runs > 1)
    throw morea_core::Error("num_runs = " + std::to_string(runs) +
                         ": one registration runs at a time here; run it once per seed (morea register runs "
                         "num_runs registrations with consecutive seeds), or set num_runs = 1");
  if (parameters.GetBool("zip"))
    throw morea_core::Error("zip = true: this registration writes no output folder to compress (morea register "
                         "does); set zip = false");
}

MultiObjectiveRegistrationRun
RunMultiObjectiveRegistration(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters,
                              const MeshRegistrationOptions & options, const std::string & selection,
                              const std::function<void(double)> & progress,
                              const PreAlignmentTransformType * initialTransform)
{
  using Clock = std::chrono::steady_clock;
  const auto secondsSince = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  const auto report = [&](double fraction) {
    if (progress)
      progress(fraction);
  };
  // Cheap checks first, so that a typo does not surface after the whole run.
  CheckSolutionSelection(selection);
  CheckSingleRunParameters(parameters);
  morea_core::CheckRunMemory(parameters); // an absurd population at once; RegisterMeshes checks the whole run
  MeshRegistrationOptions registration = options;
  registration.device = static_cast<int>(parameters.GetInteger("cuda_gpu_id"));
  registration.minimumComputeLevel = static_cast<int>(parameters.GetInteger("cuda_compute_level"));
  {
    morea_core::BackendRequest request;
    request.choice = registration.backend;
    request.device = registration.device;
    request.minimumComputeLevel = registration.minimumComputeLevel;
    morea_core::CheckBackendRequest(request); // a device asked for by name but unusable: before the work
  }
  problem.Validate();

  MultiObjectiveRegistrationRun run;
  auto                          stage = Clock::now();
  PreprocessOptions preprocessing = PreprocessOptions::FromParameters(parameters);
  preprocessing.initialTransform = initialTransform;
  run.preprocessed = Preprocess(problem, preprocessing);
  CheckGuidanceStructuresKept(run.preprocessed.report, parameters); // before the long part, not silently without it
  run.secondsPreprocessing = secondsSince(stage);
  report(PreprocessingProgressShare);

  registration.onGeneration = [&](const morea_core::GenerationRecord & record, std::size_t generations) {
    const double done = generations > 0 ? static_cast<double>(record.generation) / static_cast<double>(generations) : 1.0;
    report(PreprocessingProgressShare + (OptimisationProgressEnd - PreprocessingProgressShare) * std::min(1.0, done));
    if (options.onGeneration)
      options.onGeneration(record, generations);
  };
  stage = Clock::now();
  run.registration = RegisterMeshes(run.preprocessed.problem, parameters, registration);
  run.secondsRegistration = secondsSince(stage);
  run.approximationSet = ToApproximationSet(run.registration.front);
  report(OptimisationProgressEnd);

  // Two solutions' fields at a time: a rasterisation keeps about two cores busy.
  stage = Clock::now();
  const auto  chosen = SelectSolutions(run.approximationSet, selection);
  const auto & pre = run.preprocessed;
  const auto  rasterize = [&](std::size_t i) {
    return RasterizeSolution(run.registration.model.topology, run.registration.front[chosen[i].index].mesh,
                             pre.problem.fixedImage, pre.problem.movingImage);
  };
  std::future<MeshFields> next;
  if (chosen.size() > 1)
    next = std::async(std::launch::async, rasterize, 1);
  for (std::size_t i = 0; i < chosen.size(); ++i)
  {
    MeshFields fields = i == 0 ? rasterize(0) : next.get();
    if (i > 0 && i + 1 < chosen.size())
      next = std::async(std::launch::async, rasterize, i + 1);
    const OriginalFrameTransforms original = MakeOriginalFrameTransforms(fields, pre.rigidTransform);
    run.selected.push_back({ chosen[i], std::move(fields), original });
    report(OptimisationProgressEnd +
           (1.0 - OptimisationProgressEnd) * static_cast<double>(i + 1) / static_cast<double>(chosen.size()));
  }
  run.secondsSelection = secondsSince(stage);
  return run;
}

std::string
UserMessage(const std::string & description)
{
  const std::string prefix = "ITK ERROR: ";
  if (description.rfind(prefix, 0) != 0)
    return description;
  const std::string rest = description.substr(prefix.size());
  // An object's exception adds "ClassName(0x...): "; a generic one adds nothing more.
  const auto open = rest.find("(0x");
  const auto end = rest.find("): ");
  if (open != std::string::npos && end != std::string::npos && open < end && rest.find(' ') > open)
    return rest.substr(end + 3);
  return rest;
}

void
PrintParameters(std::ostream & os, const morea_core::ParameterSet & parameters, Indent indent)
{
  // The main run keys always, the rest only when set: all ~50 keys would bury them.
  static const char * const always[] = { "ea_num_generations", "ea_population_size", "morea_mesh_num_points",
                                         "seed" };
  std::istringstream lines(parameters.ToToml());
  for (std::string line; std::getline(lines, line);)
  {
    const std::string key = line.substr(0, line.find(" = "));
    if (parameters.IsExplicit(key) || std::find(std::begin(always), std::end(always), key) != std::end(always))
      os << indent << line << std::endl;
  }
}
} // namespace morea
} // namespace itk
