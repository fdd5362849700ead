// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// `morea mesh`: builds the mesh model of a problem and writes it for inspection.
#include "CommandCommon.h"

#include "itkMOREAImageIO.h"
#include "itkMeshModel.h"
#include "itkObjectiveData.h"
#include "itkPreprocessing.h"
#include "itkVectorLinearInterpolateImageFunction.h"
#include "morea_core/Error.h"
#include "morea_core/FoldConstraint.h"
#include "morea_core/InitialPopulation.h"
#include "morea_core/TetrahedronObjectives.h"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <utility>

namespace morea_cli
{
namespace
{
nlohmann::json
ReportToJson(const itk::morea::MeshModel & model)
{
  const auto &   g = model.report.generation;
  nlohmann::json j;
  j["points"] = model.base.NumberOfPoints();
  j["points_by_origin"] = { { "corner", g.corners },   { "boundary_face", g.boundaryPoints },
                            { "random", g.randomPoints }, { "contour", g.contourPoints },
                            { "surface", g.surfacePoints }, { "steiner", g.steinerPoints } };
  nlohmann::json perStructure = nlohmann::json::object();
  for (const auto & [name, count] : g.pointsPerStructure)
    perStructure[name] = count;
  j["points_per_structure"] = perStructure;
  j["surface_triangles"] = g.surfaceTriangles;
  j["tetrahedra"] = model.base.NumberOfTetrahedra();
  j["slivers"] = g.slivers;
  j["worst_quality"] = g.worstQuality;
  j["points_by_origin"]["refinement"] = g.refinementPoints;
  j["points_by_origin"]["shell"] = g.shellPoints;
  j["edges"] = model.topology.Edges().size();
  j["fos_elements"] = model.report.fosElements;
  j["parallel_groups"] = model.report.parallelGroups;
  const auto [lo, hi] = std::minmax_element(model.elasticity.begin(), model.elasticity.end());
  j["elasticity_range"] = { model.elasticity.empty() ? 1.0 : *lo, model.elasticity.empty() ? 1.0 : *hi };
  j["rigid_structures"] = model.rigidStructureNames;
  j["rigid_tetrahedra"] = model.rigidity.Empty() ? 0 : std::count_if(model.rigidity.weights.begin(),
                                                                     model.rigidity.weights.end(),
                                                                     [](double w) { return w > 0.0; });
  j["seconds"] = { { "contour_points", model.report.secondsContourPoints },
                   { "placement", g.secondsPlacement },
                   { "surfaces", g.secondsSurfaces },
                   { "tetrahedralization", g.secondsTetrahedralization },
                   { "parallel_structure", model.report.secondsParallelStructure },
                   { "elasticity", model.report.secondsElasticity } };
  j["notes"] = model.report.notes;
  return j;
}

/** The mesh carried by a moving-to-fixed displacement field: the source
 *  (moving) points where the mesh has them, the target (fixed) points where
 *  the field takes them. Throws when a point lies outside the field. */
morea_core::DualMesh
CarriedByField(const itk::morea::MeshModel & model, const std::string & path)
{
  const auto field = itk::morea::ReadDisplacementField(path);
  using Interpolator = itk::VectorLinearInterpolateImageFunction<itk::morea::DisplacementFieldType, double>;
  auto interpolator = Interpolator::New();
  interpolator->SetInputImage(field);
  auto solution = morea_core::DualMesh::FromBase(model.base);
  for (std::size_t i = 0; i < solution.source.size(); ++i)
  {
    const auto point = model.frame.ToPhysical(solution.source[i]);
    if (!interpolator->IsInsideBuffer(point))
      throw morea_core::Error(path + ": mesh point " + std::to_string(i) + " lies outside the field");
    const auto u = interpolator->Evaluate(point);
    const auto displacement = model.frame.VectorToFrame(itk::morea::DisplacementVectorType(u.GetDataPointer()));
    for (int a = 0; a < 3; ++a)
      solution.target[i][a] = solution.source[i][a] + displacement[a];
  }
  return solution;
}

nlohmann::json
ObjectivesToJson(const morea_core::TetrahedronEvaluator & evaluator, const morea_core::DualMesh & solution,
                 std::size_t tetrahedra)
{
  morea_core::ObjectiveTotals totals;
  for (std::size_t t = 0; t < tetrahedra; ++t)
    totals.Add(evaluator.Evaluate(t, solution));
  const auto fitness = totals.ToFitness(tetrahedra);
  return { { "magnitude", fitness.objectives[0] },
           { "intensity", fitness.objectives[1] },
           { "guidance", fitness.objectives[2] },
           { "feasible", fitness.feasible },
           { "folded_tetrahedra", std::llround(totals.sum.folded) } };
}
} // namespace

void
AddMeshCommand(CLI::App & app)
{
  struct Options
  {
    ProblemOptions   problem;
    ParameterOptions parameters;
    std::string      output;
    std::size_t      samples{ 0 };
    std::vector<std::string> objectivesOf;
  };
  auto   options = std::make_shared<Options>();
  auto * cmd = app.add_subcommand("mesh", "build the mesh model of a problem and write it as .vtu (SPEC 4.3-4.5)");
  options->problem.AddTo(*cmd);
  options->parameters.AddTo(*cmd);
  cmd->add_option("-o,--output", options->output, "output folder")->required();
  cmd->add_option("--samples", options->samples,
                  "also write this many random initial solutions (meshes and displacement fields)")
    ->check(CLI::Range(0, 1000));
  cmd->add_option("--objectives-of", options->objectivesOf,
                  "NAME=FIELD: the objectives (as morea register scores a solution) of the map a moving-to-fixed "
                  "displacement field gives this mesh, e.g. another method's result or a known truth; written to "
                  "mesh.json with those of the identity");
  cmd->callback([options] {
    const auto parameters = options->parameters.Load();
    auto       problem = options->problem.Load();
    if (!itk::morea::SameGrid(problem.fixedImage, problem.movingImage))
    {
      std::cout << "the images are on different grids: preprocessing first\n";
      auto preprocessed = itk::morea::Preprocess(problem, itk::morea::PreprocessOptions::FromParameters(parameters));
      itk::morea::CheckGuidanceStructuresKept(preprocessed.report, parameters); // as morea register does
      problem = std::move(preprocessed.problem);
    }
    for (const auto & entry : options->objectivesOf)
      if (entry.find('=') == std::string::npos || entry.front() == '=' || entry.back() == '=')
        throw morea_core::Error("--objectives-of: expected NAME=FIELD, got '" + entry + "'");
    // As a registration scores them: on its preprocessed (windowed) images.
    if (!options->objectivesOf.empty() && !itk::morea::IsWindowedAlready(problem))
      throw morea_core::Error("--objectives-of scores a map as a registration does, on its preprocessed "
                              "images: give the problem `morea preprocess` wrote (or a registration's "
                              "preprocessed/ folder); these images have values outside [0, 1]");
    const auto model = itk::morea::BuildMeshModel(problem, parameters);
    const auto base = morea_core::DualMesh::FromBase(model.base);
    nlohmann::json objectives; // before anything is written: a field may be unreadable
    if (!options->objectivesOf.empty())
    {
      const auto data = itk::morea::BuildObjectiveData(problem, model.frame, parameters);
      const morea_core::FoldConstraint constraint(model.topology, model.base.points,
                                                  parameters.GetReal("morea_fold_volume_fraction"));
      const morea_core::TetrahedronEvaluator evaluator(model.topology, constraint, model.elasticity, model.rigidity,
                                                       data);
      const std::size_t tetrahedra = model.base.NumberOfTetrahedra();
      objectives["identity"] = ObjectivesToJson(evaluator, base, tetrahedra);
      for (const auto & entry : options->objectivesOf)
      {
        const std::string name = entry.substr(0, entry.find('='));
        const auto        carried = CarriedByField(model, entry.substr(entry.find('=') + 1));
        objectives[name] = ObjectivesToJson(evaluator, carried, tetrahedra);
      }
      for (const auto & [name, o] : objectives.items())
        std::cout << "objectives of " << name << ": magnitude " << o["magnitude"].get<double>() << ", intensity "
                  << o["intensity"].get<double>() << ", guidance " << o["guidance"].get<double>()
                  << (o["feasible"].get<bool>() ? "" : ", folded") << "\n";
    }
    std::filesystem::create_directories(options->output);
    const std::string out = options->output + "/";
    itk::morea::WriteSolutionMeshes(model, base, out + "mesh_moving.vtu", out + "mesh_fixed.vtu");

    nlohmann::json report = ReportToJson(model);
    if (!objectives.is_null())
      report["objectives"] = objectives;
    if (options->samples > 0)
    {
      const auto                  start = std::chrono::steady_clock::now();
      const morea_core::FoldConstraint constraint(model.topology, model.base.points,
                                                parameters.GetReal("morea_fold_volume_fraction"));
      const auto population = morea_core::GenerateInitialPopulation(
        model.base, constraint, options->samples + 1, static_cast<std::uint64_t>(parameters.GetInteger("seed")),
        morea_core::InitialPopulationOptions::FromParameters(parameters));
      for (std::size_t i = 1; i < population.size(); ++i)
      {
        const std::string prefix = out + "initial_" + std::to_string(i) + "_";
        itk::morea::WriteSolutionMeshes(model, population[i], prefix + "mesh_moving.vtu", prefix + "mesh_fixed.vtu");
        const auto fields = itk::morea::RasterizeSolution(model.topology, population[i], problem.fixedImage,
                                                          problem.movingImage);
        itk::morea::WriteDisplacementField(fields.fixedToMoving, prefix + "fixed_to_moving.nii.gz");
        itk::morea::WriteDisplacementField(fields.movingToFixed, prefix + "moving_to_fixed.nii.gz");
      }
      report["seconds"]["samples"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    WriteJson(report, out + "mesh.json");

    std::cout << "mesh: " << model.base.NumberOfPoints() << " points, " << model.base.NumberOfTetrahedra()
              << " tetrahedra, " << model.report.fosElements << " FOS elements in " << model.report.parallelGroups
              << " parallel groups\n";
    for (const auto & note : model.report.notes)
      std::cout << "note: " << note << "\n";
    std::cout << "written to " << options->output << "\n";
  });
}
} // namespace morea_cli
