// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkMeshModel.h"

#include "itkMOREAImageIO.h"
#include "itkPreprocessing.h"
#include "morea_core/ElasticityFactors.h"
#include "morea_core/MeshRefinement.h"
#include "morea_core/Error.h"
#include "morea_core/ParameterSet.h"
#include "morea_core/RigidityTerm.h"

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

namespace
{
/** The rigid structures with a moving mask (morea_rigid_structures; none when
 *  morea_rigid_weight is 0); `notes` tells of those without one. */
std::vector<std::string>
RigidStructureNames(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters,
                    std::vector<std::string> & notes)
{
  std::vector<std::string> names, available;
  for (const Structure & s : problem.structures)
    available.push_back(s.name);
  const auto factors = morea_core::ParseElasticityFactors(parameters.GetString("morea_elasticity_factors"));
  const auto rigid = morea_core::SelectRigidStructures(parameters.GetString("morea_rigid_structures"), available, factors);
  if (parameters.GetReal("morea_rigid_weight") == 0.0)
    return names;
  for (const std::string & name : rigid)
  {
    if (problem.GetStructure(name).movingMask)
      names.push_back(name);
    else
      notes.push_back("no mask for rigid structure " + name + "; not rigid");
  }
  return names;
}
/** What follows from the base mesh: topology, parallel structure,
 *  elasticity factors and the rigidity model. `fosElements` > 0: the FOS
 *  elements are about that many groups of points (morea_fos_type
 *  coarse-groups on a refined level), else edges. */
void
DeriveMeshModelParts(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters, MeshModel & model,
                     std::size_t fosElements = 0)
{
  auto start = Clock::now();
  model.topology = morea_core::MeshTopology(model.base.tetrahedra, model.base.NumberOfPoints());
  if (fosElements == 0)
    model.parallel = morea_core::BuildParallelStructure(model.topology);
  else
  {
    const std::size_t points = model.base.NumberOfPoints();
    // At most 16 points (96 variables) per group, so that merged groups stay
    // within what the CUDA fold check handles (MaxRepairElementPoints, 64).
    const std::size_t size = std::clamp<std::size_t>((points + fosElements - 1) / fosElements, 2, 16);
    model.parallel = morea_core::BuildParallelStructure(
      model.topology, morea_core::GreedyPointGroups(model.topology, model.base.points, size));
    model.report.notes.push_back("FOS elements: " + std::to_string(model.parallel.elements.size()) +
                                 " groups of about " + std::to_string(size) + " points (morea_fos_type = coarse-groups)");
  }
  model.report.fosElements = model.parallel.elements.size();
  model.report.parallelGroups = model.parallel.groups.size();
  model.report.secondsParallelStructure = SecondsSince(start);

  // Elasticity from all structures with a factor, guidance or not (bones, say).
  start = Clock::now();
  std::vector<morea_core::ElasticStructure>     elastic;
  std::vector<morea_core::Volume<std::uint8_t>> elasticMasks;
  const auto factors = morea_core::ParseElasticityFactors(parameters.GetString("morea_elasticity_factors"));
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
  model.elasticity = morea_core::ComputeElasticityFactors(model.base, elastic);

  // Rigid structures, guidance or not: the tetrahedra inside their masks.
  std::vector<morea_core::Volume<std::uint8_t>>         rigidMasks;
  std::vector<const morea_core::Volume<std::uint8_t> *> rigidMaskPointers;
  rigidMasks.reserve(model.rigidStructureNames.size());
  for (const std::string & name : model.rigidStructureNames)
  {
    rigidMasks.push_back(ToVolume(problem.GetStructure(name).movingMask.GetPointer(), model.frame));
    rigidMaskPointers.push_back(&rigidMasks.back());
  }
  if (!rigidMaskPointers.empty())
    model.rigidity = morea_core::BuildRigidityModel(model.base, morea_core::UnionOverlapFractions(model.base, rigidMaskPointers),
                                                 parameters.GetReal("morea_rigid_weight"),
                                                 parameters.GetReal("morea_rigid_strain_limit"));
  model.report.secondsElasticity = SecondsSince(start);
}
} // namespace

std::vector<std::string>
GuidanceStructureNames(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters)
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
  for (const std::string & name : morea_core::ParseNameList(selection))
  {
    problem.GetStructure(name); // throws, listing the known names
    names.push_back(name);
  }
  return names;
}

MeshModel
BuildMeshModel(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters)
{
  if (!problem.movingImage || !problem.fixedImage)
    itkGenericExceptionMacro("mesh model: the problem has no images");
  if (!SameGrid(problem.fixedImage, problem.movingImage))
    itkGenericExceptionMacro("mesh model: the problem must be preprocessed (both images on one grid)");
  MeshModel model;
  model.frame = DomainFrame::Of(problem.movingImage);
  const morea_core::MeshDomain domain = morea_core::MeshDomain::OfGrid(model.frame.GeometryOf(problem.movingImage));

  // The mesh lies on the moving (source) image: its structures' contours and
  // masks. Rigid structures that do not guide get contour points too, so
  // that tetrahedra can lie inside a bone and stay rigid while those beside
  // it deform.
  auto                                       start = Clock::now();
  std::vector<morea_core::Volume<std::uint8_t>> masks;
  std::vector<morea_core::MeshStructure>        structures;
  std::vector<std::string>                   rigidNotes;
  try
  {
    model.rigidStructureNames = RigidStructureNames(problem, parameters, rigidNotes);
  }
  catch (const morea_core::Error & e)
  {
    itkGenericExceptionMacro("mesh model: " << e.what());
  }
  model.structureNames = GuidanceStructureNames(problem, parameters);
  for (const std::string & name : model.rigidStructureNames)
    if (std::find(model.structureNames.begin(), model.structureNames.end(), name) == model.structureNames.end())
      model.structureNames.push_back(name);
  masks.reserve(model.structureNames.size());
  for (const std::string & name : model.structureNames)
  {
    const Structure & s = problem.GetStructure(name);
    morea_core::MeshStructure m;
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
    const auto options = morea_core::MeshGeneratorOptions::FromParameters(parameters);
    model.base = morea_core::GenerateMesh(domain, structures, options, &model.report.generation);
    model.report.notes = model.report.generation.notes;
    model.report.notes.insert(model.report.notes.end(), rigidNotes.begin(), rigidNotes.end());

    DeriveMeshModelParts(problem, parameters, model);
  }
  catch (const morea_core::Error & e)
  {
    itkGenericExceptionMacro("mesh model: " << e.what());
  }
  return model;
}

MeshModel
RefineMeshModel(const MeshModel & coarse, const RegistrationProblem & problem, const morea_core::ParameterSet & parameters,
                const std::vector<double> & density, std::size_t targetPoints, morea_core::MeshRefinement & refinement)
{
  MeshModel model;
  model.frame = coarse.frame;
  model.rigidStructureNames = coarse.rigidStructureNames;
  model.structureNames = coarse.structureNames;
  try
  {
    refinement = morea_core::RefineMesh(coarse.base, density, targetPoints);
    model.base = refinement.mesh;
    model.report.generation = coarse.report.generation;
    model.report.notes = coarse.report.notes;
    model.report.generation.tetrahedra = model.base.NumberOfTetrahedra();
    model.report.generation.worstQuality = 1.0;
    model.report.generation.slivers = 0;
    for (const auto & t : model.base.tetrahedra)
    {
      const double q = morea_core::TetrahedronQuality(model.base.points[t[0]], model.base.points[t[1]],
                                                   model.base.points[t[2]], model.base.points[t[3]]);
      model.report.generation.worstQuality = std::min(model.report.generation.worstQuality, q);
      model.report.generation.slivers += q < 0.05 ? 1 : 0;
    }
    model.report.notes.push_back("mesh refined from " + std::to_string(coarse.base.NumberOfPoints()) + " to " +
                                 std::to_string(model.base.NumberOfPoints()) + " points");
    const bool grouped = parameters.GetString("morea_fos_type") == "coarse-groups";
    DeriveMeshModelParts(problem, parameters, model, grouped ? coarse.parallel.elements.size() : 0);
  }
  catch (const morea_core::Error & e)
  {
    itkGenericExceptionMacro("mesh model: " << e.what());
  }
  return model;
}

void
WriteSolutionMeshes(const MeshModel & model, const morea_core::DualMesh & solution, const std::string & movingPath,
                    const std::string & fixedPath)
{
  std::vector<double> origin, structure;
  for (std::size_t p = 0; p < model.base.NumberOfPoints(); ++p)
  {
    origin.push_back(static_cast<double>(model.base.origins[p]));
    structure.push_back(static_cast<double>(model.base.structures[p]));
  }
  const std::vector<morea_core::VtuArray> pointData{ { "origin", origin }, { "structure", structure } };
  for (const auto & [points, path] : { std::make_pair(&solution.source, movingPath),
                                      std::make_pair(&solution.target, fixedPath) })
  {
    std::vector<double> volume;
    for (const auto & t : model.topology.Tetrahedra())
      volume.push_back(morea_core::SignedVolume(t, *points));
    const std::vector<double> rigidity =
      model.rigidity.Empty() ? std::vector<double>(model.topology.NumberOfTetrahedra(), 0.0) : model.rigidity.weights;
    WriteMeshVtu(path, model.topology, *points, model.frame,
                 { { "elasticity", model.elasticity }, { "rigidity", rigidity }, { "signed_volume", volume } },
                 pointData);
  }
}
} // namespace morea
} // namespace itk
