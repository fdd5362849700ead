#include "itkMeshModel.h"

#include "itkMOREAImageIO.h"
#include "itkPreprocessing.h"
#include "morea/ElasticityFactors.h"
#include "morea/Error.h"
#include "morea/ParameterSet.h"

#include <algorithm>
#include <cctype>
#include <chrono>

namespace itk
{
namespace morea
{
namespace
{
using Clock = std::chrono::steady_clock;

double
SecondsSince(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string
Lower(std::string s)
{
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}
} // namespace

std::vector<std::string>
GuidanceStructureNames(const RegistrationProblem & problem, const ::morea::ParameterSet & parameters)
{
  const std::string &      selection = parameters.GetString("problem_guidance_selection");
  std::vector<std::string> names;
  if (selection == "-1")
  {
    for (const Structure & s : problem.structures)
      if (Lower(s.name) != "body")
        names.push_back(s.name);
    return names;
  }
  for (const std::string & name : ::morea::ParseNameList(selection))
  {
    problem.GetStructure(name); // throws, listing the known names
    names.push_back(name);
  }
  return names;
}

MeshModel
BuildMeshModel(const RegistrationProblem & problem, const ::morea::ParameterSet & parameters)
{
  if (!problem.movingImage || !problem.fixedImage)
    itkGenericExceptionMacro("mesh model: the problem has no images");
  if (!SameGrid(problem.fixedImage, problem.movingImage))
    itkGenericExceptionMacro("mesh model: the problem must be preprocessed (both images on one grid)");
  MeshModel model;
  model.frame = DomainFrame::Of(problem.movingImage);
  const ::morea::MeshDomain domain = ::morea::MeshDomain::OfGrid(model.frame.GeometryOf(problem.movingImage));

  // The mesh lies on the moving (source) image: its structures' contours and masks.
  auto                                       start = Clock::now();
  std::vector<::morea::Volume<std::uint8_t>> masks;
  std::vector<::morea::MeshStructure>        structures;
  model.structureNames = GuidanceStructureNames(problem, parameters);
  masks.reserve(model.structureNames.size());
  for (const std::string & name : model.structureNames)
  {
    const Structure & s = problem.GetStructure(name);
    ::morea::MeshStructure m;
    m.name = name;
    PointListType points = s.movingPoints;
    if (points.empty() && s.movingMask)
      points = ExtractSurfacePoints(s.movingMask);
    for (const PointType & p : points)
      m.contourPoints.push_back(model.frame.ToFrame(p));
    if (s.movingMask)
    {
      masks.push_back(ToVolume(s.movingMask.GetPointer(), model.frame));
      m.mask = &masks.back();
    }
    structures.push_back(std::move(m));
  }
  model.report.secondsContourPoints = SecondsSince(start);

  try
  {
    const auto options = ::morea::MeshGeneratorOptions::FromParameters(parameters);
    model.base = ::morea::GenerateMesh(domain, structures, options, &model.report.generation);
    model.report.notes = model.report.generation.notes;

    start = Clock::now();
    model.topology = ::morea::MeshTopology(model.base.tetrahedra, model.base.NumberOfPoints());
    model.parallel = ::morea::BuildParallelStructure(model.topology);
    model.report.fosElements = model.parallel.elements.size();
    model.report.parallelGroups = model.parallel.groups.size();
    model.report.secondsParallelStructure = SecondsSince(start);

    // Elasticity from all structures with a factor, guidance or not (bones, say).
    start = Clock::now();
    std::vector<::morea::ElasticStructure>     elastic;
    std::vector<::morea::Volume<std::uint8_t>> elasticMasks;
    const auto factors = ::morea::ParseElasticityFactors(parameters.GetString("morea_elasticity_factors"));
    if (parameters.GetString("morea_magnitude_metric") == "biomechanical")
    {
      elasticMasks.reserve(factors.size());
      for (const auto & [name, factor] : factors)
      {
        const Structure * s = problem.FindStructure(name);
        if (!s || !s->movingMask)
        {
          model.report.notes.push_back("no mask for elasticity structure " + name + "; factor 1 there");
          continue;
        }
        elasticMasks.push_back(ToVolume(s->movingMask.GetPointer(), model.frame));
        elastic.push_back({ name, &elasticMasks.back(), factor });
      }
    }
    model.elasticity = ::morea::ComputeElasticityFactors(model.base, elastic);
    model.report.secondsElasticity = SecondsSince(start);
  }
  catch (const ::morea::Error & e)
  {
    itkGenericExceptionMacro("mesh model: " << e.what());
  }
  return model;
}

void
WriteSolutionMeshes(const MeshModel & model, const ::morea::DualMesh & solution, const std::string & movingPath,
                    const std::string & fixedPath)
{
  std::vector<double> origin, structure;
  for (std::size_t p = 0; p < model.base.NumberOfPoints(); ++p)
  {
    origin.push_back(static_cast<double>(model.base.origins[p]));
    structure.push_back(static_cast<double>(model.base.structures[p]));
  }
  const std::vector<::morea::VtuArray> pointData{ { "origin", origin }, { "structure", structure } };
  for (const auto & [points, path] : { std::make_pair(&solution.source, movingPath),
                                      std::make_pair(&solution.target, fixedPath) })
  {
    std::vector<double> volume;
    for (const auto & t : model.topology.Tetrahedra())
      volume.push_back(::morea::SignedVolume(t, *points));
    WriteMeshVtu(path, model.topology, *points, model.frame,
                 { { "elasticity", model.elasticity }, { "signed_volume", volume } }, pointData);
  }
}
} // namespace morea
} // namespace itk
