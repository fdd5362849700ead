// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "CommandCommon.h"

#include "itkLandmarkIO.h"
#include "itkMOREAImageIO.h"
#include "morea_core/Error.h"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <set>

namespace fs = std::filesystem;

namespace morea_cli
{
namespace
{
/** The first existing file among folder/stem + each image extension. */
std::string
FindImage(const fs::path & folder, const std::string & stem)
{
  for (const char * ext : { ".nii.gz", ".nii", ".mha", ".mhd", ".nrrd", ".nhdr" })
  {
    const fs::path p = folder / (stem + ext);
    if (fs::exists(p))
      return p.string();
  }
  if (fs::is_directory(folder / stem))
    return (folder / stem).string(); // a DICOM series folder
  return "";
}

std::string
StemOf(const fs::path & file)
{
  std::string name = file.filename().string();
  return name.substr(0, name.find('.'));
}
} // namespace

std::pair<std::string, std::string>
SplitAssignment(const std::string & text, const std::string & what)
{
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error(what + " '" + text + "' must have the form NAME=VALUE");
  return { text.substr(0, eq), text.substr(eq + 1) };
}

void
ProblemOptions::AddTo(CLI::App & app)
{
  app.add_option("--problem", folder,
                 "problem folder: fixed.*, moving.*, fixed_masks/, moving_masks/, fixed_landmarks.txt, ...");
  app.add_option("--fixed", fixed, "fixed (target) image: any ITK format, or a DICOM series folder");
  app.add_option("--moving", moving, "moving (source) image");
  app.add_option("--fixed-structure", fixedStructures,
                 "NAME=SOURCE on the fixed image: mask, labels.mha:LABEL, rtstruct.dcm:ROI or a point file")
    ->take_all();
  app.add_option("--moving-structure", movingStructures, "NAME=SOURCE on the moving image")->take_all();
  app.add_option("--fixed-body", fixedBody, "body mask of the fixed image (outside is background)");
  app.add_option("--moving-body", movingBody, "body mask of the moving image");
  app.add_option("--fixed-landmarks", fixedLandmarks, "landmarks on the fixed image (elastix point file or CSV)");
  app.add_option("--moving-landmarks", movingLandmarks, "landmarks on the moving image");
}

itk::morea::RegistrationProblem
ProblemOptions::Load() const
{
  itk::morea::RegistrationProblem problem;
  std::string                     fixedPath = fixed, movingPath = moving;
  std::vector<std::string>        fixedSources, movingSources;
  std::string fixedBodyPath = fixedBody, movingBodyPath = movingBody;
  std::string fixedLandmarkPath = fixedLandmarks, movingLandmarkPath = movingLandmarks;
  if (!folder.empty())
  {
    const fs::path root(folder);
    if (!fs::is_directory(root))
      throw Error("problem folder '" + folder + "' does not exist");
    if (fixedPath.empty())
      fixedPath = FindImage(root, "fixed");
    if (movingPath.empty())
      movingPath = FindImage(root, "moving");
    for (const auto & [side, sources] :
         { std::pair<std::string, std::vector<std::string> *>{ "fixed", &fixedSources }, { "moving", &movingSources } })
    {
      std::set<fs::path> files;
      for (const char * sub : { "_masks", "_points" })
      {
        const fs::path dir = root / (side + sub);
        if (fs::is_directory(dir))
          for (const auto & entry : fs::directory_iterator(dir))
            if (entry.is_regular_file() && entry.path().filename().string()[0] != '.')
              files.insert(entry.path());
      }
      // Masks sort before points (fixed_masks < fixed_points), so points add to a loaded mask.
      for (const auto & f : files)
        sources->push_back(StemOf(f) + "=" + f.string());
    }
    if (fixedBodyPath.empty())
      fixedBodyPath = FindImage(root, "fixed_body");
    if (movingBodyPath.empty())
      movingBodyPath = FindImage(root, "moving_body");
    if (fixedLandmarkPath.empty() && fs::exists(root / "fixed_landmarks.txt"))
      fixedLandmarkPath = (root / "fixed_landmarks.txt").string();
    if (movingLandmarkPath.empty() && fs::exists(root / "moving_landmarks.txt"))
      movingLandmarkPath = (root / "moving_landmarks.txt").string();
  }
  if (fixedPath.empty() || movingPath.empty())
    throw Error("a fixed and a moving image are needed (--fixed/--moving or --problem with fixed.* and moving.*)");
  problem.LoadImages(fixedPath, movingPath);
  fixedSources.insert(fixedSources.end(), fixedStructures.begin(), fixedStructures.end());
  movingSources.insert(movingSources.end(), movingStructures.begin(), movingStructures.end());
  // Every structure side at once (a label map named twice is read once).
  std::vector<itk::morea::RegistrationProblem::StructureSource> structureSources;
  for (const auto & s : fixedSources)
  {
    const auto [name, source] = SplitAssignment(s, "--fixed-structure");
    structureSources.push_back({ name, true, source });
  }
  for (const auto & s : movingSources)
  {
    const auto [name, source] = SplitAssignment(s, "--moving-structure");
    structureSources.push_back({ name, false, source });
  }
  problem.LoadStructures(structureSources);
  if (!fixedBodyPath.empty())
    problem.LoadBodyMask(true, fixedBodyPath);
  if (!movingBodyPath.empty())
    problem.LoadBodyMask(false, movingBodyPath);
  if (fixedLandmarkPath.empty() != movingLandmarkPath.empty())
    throw Error("landmarks need both --fixed-landmarks and --moving-landmarks");
  if (!fixedLandmarkPath.empty())
    problem.LoadLandmarks(fixedLandmarkPath, movingLandmarkPath);
  problem.Validate();
  return problem;
}

void
ParameterOptions::AddTo(CLI::App & app)
{
  app.add_option("--parameters", file, "TOML parameter file (the MOREA paper's keys)")->check(CLI::ExistingFile);
  app.add_option("--var", variables, "NAME=VALUE for a $NAME placeholder in the parameter file")->take_all();
  app.add_option("--set", overrides, "KEY=VALUE overriding one parameter")->take_all();
}

ParameterSet
ParameterOptions::Load() const
{
  std::map<std::string, std::string> vars;
  for (const auto & v : variables)
    vars.insert(SplitAssignment(v, "--var"));
  ParameterSet parameters = file.empty() ? ParameterSet() : ParameterSet::FromFile(file, vars);
  for (const auto & o : overrides)
  {
    const auto [key, value] = SplitAssignment(o, "--set");
    parameters.SetFromString(key, value);
  }
  return parameters;
}

void
PrintScores(std::ostream & out, const itk::morea::EvaluationScores & scores, const std::string & title)
{
  char line[256];
  out << title << " (border margin " << scores.borderMargin << " mm)\n";
  std::snprintf(line, sizeof line, "  %-18s %8s %10s %10s %10s\n", "structure", "Dice", "HD mm", "HD95 mm", "MSD mm");
  out << line;
  for (const auto & s : scores.structures)
  {
    std::snprintf(line, sizeof line, "  %-18s %8.4f %10.2f %10.2f %10.2f\n", s.name.c_str(), s.dice, s.hausdorff,
                  s.hausdorff95, s.meanSurfaceDistance);
    out << line;
  }
  if (scores.hasLandmarks)
  {
    std::snprintf(line, sizeof line, "  landmarks (%zu, %zu outside the domain): TRE mean %.2f mm, sd %.2f mm, max %.2f mm\n",
                  scores.landmarks.errors.size(), scores.landmarksOutside, scores.landmarks.mean,
                  scores.landmarks.standardDeviation, scores.landmarks.maximum);
    out << line;
  }
  std::snprintf(line, sizeof line, "  voxels with Jacobian determinant <= 0: %.6f\n", scores.nonPositiveJacobianFraction);
  out << line;
  if (scores.hasInverse)
  {
    std::snprintf(line, sizeof line, "  inverse consistency: mean %.3f mm, max %.3f mm\n", scores.inverseConsistency.mean,
                  scores.inverseConsistency.maximum);
    out << line;
  }
}

void
WriteJson(const nlohmann::json & json, const std::string & path)
{
  itk::morea::WriteTextFile(json.dump(2) + "\n", path);
}
} // namespace morea_cli
