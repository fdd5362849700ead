// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Fuzz test of mesh generation: random crop boxes over real organ masks (the
// abdominal CBCT's stomach, bowel and lungs, the lung CT's lungs) and the
// phantom's, each box cutting the structures' surfaces somewhere else, at
// random voxel sizes, point counts and shares (so each surface is decimated
// to another level), with random sets of surfaces as constraints. Every case
// must give a valid mesh (positive tetrahedra that tile the domain) or a
// clear morea_core::Error, never a crash.
//
// CTest runs a fixed seed and MOREA_MESH_FUZZ_CASES cases (default 300);
// MOREA_MESH_FUZZ_SEED picks other boxes, MOREA_MESH_FUZZ_ONLY=N meshes case
// N alone (its notes printed). The real masks are read from
// MOREA_SHARED_DATA_DIR; without them the phantom's masks are used alone.
#include "itkMOREAImageIO.h"
#include "itkMeshModel.h"
#include "itkPreprocessing.h"
#include "itkRegistrationProblem.h"
#include "morea_core/ParameterSet.h"
#include "morea_core/Error.h"
#include "morea_core/MeshGenerator.h"
#include "morea_core/MeshPointPlacement.h"
#include "morea_core/Phantom.h"
#include "morea_core/Random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>
#include <string>

namespace
{
using morea_core::Vec3;
using Mask = morea_core::Volume<std::uint8_t>;

/** Masks on one grid, and where each one's boundary lies (crop centres). */
struct Source
{
  std::string                                  name;
  std::vector<std::pair<std::string, Mask>>    masks;
  std::vector<std::vector<Vec3>>               boundaries; ///< per mask, a subsample of its contour points
};

Mask
ToVolume(const itk::morea::MaskType * image)
{
  const auto region = image->GetLargestPossibleRegion();
  Mask       m;
  for (int a = 0; a < 3; ++a)
  {
    m.size[a] = region.GetSize()[a];
    m.spacing[a] = image->GetSpacing()[a];
    m.origin[a] = image->GetOrigin()[a];
    for (int b = 0; b < 3; ++b)
      if (std::abs(image->GetDirection()[a][b] - (a == b ? 1.0 : 0.0)) > 1e-6)
        throw std::runtime_error("fuzz test: masks with a rotated grid are not supported");
  }
  m.data.assign(image->GetBufferPointer(), image->GetBufferPointer() + m.NumberOfVoxels());
  return m;
}

void
AddBoundaries(Source & source)
{
  for (const auto & [name, mask] : source.masks)
  {
    std::vector<Vec3> all = morea_core::MaskBoundaryPoints(mask);
    std::vector<Vec3> some;
    for (std::size_t i = 0; i < all.size(); i += std::max<std::size_t>(1, all.size() / 2000))
      some.push_back(all[i]);
    source.boundaries.push_back(std::move(some));
  }
}

std::vector<Source>
LoadSources()
{
  std::vector<Source>         sources;
  const std::filesystem::path data(MOREA_SHARED_DATA_DIR);
  const auto                  read = [&](Source & s, const std::string & name, const std::filesystem::path & path) {
    if (std::filesystem::exists(path))
      s.masks.emplace_back(name, ToVolume(itk::morea::ReadMask(path.string())));
  };
  Source abdomen{ "abdomen CB02", {}, {} };
  for (const char * organ : { "Stomach_duo_CBCT", "Bowel_sm_CBCT", "LUNG_L", "LUNG_R" })
    read(abdomen, organ, data / "abdomen-cbct-pair" / "CB02_masks" / (std::string(organ) + ".mha"));
  for (const char * scan : { "baseline", "followup" })
  {
    Source lung{ std::string("lung ") + scan, {}, {} };
    read(lung, "lungs", data / "lung-ct-pair" / (std::string(scan) + "_lung_mask.mha"));
    sources.push_back(std::move(lung));
  }
  sources.push_back(std::move(abdomen));
  morea_core::PhantomOptions po;
  po.spacing = 2.0;
  auto   phantom = morea_core::PelvisPhantom(po).Generate();
  Source p{ "phantom", {}, {} };
  const auto & names = morea_core::PelvisPhantom::StructureNames();
  for (std::size_t s = 0; s < names.size(); ++s)
    if (names[s] != "body")
      p.masks.emplace_back(names[s], std::move(phantom.movingMasks[s]));
  sources.push_back(std::move(p));
  sources.erase(std::remove_if(sources.begin(), sources.end(), [](const Source & s) { return s.masks.empty(); }),
                sources.end());
  for (Source & s : sources)
    AddBoundaries(s);
  return sources;
}

/** `mask` resampled (nearest voxel) on the grid of spacing `spacing` from `lower` to `upper`. */
Mask
Crop(const Mask & mask, const Vec3 & lower, const Vec3 & upper, double spacing)
{
  Mask out;
  for (int a = 0; a < 3; ++a)
  {
    out.size[a] = static_cast<std::size_t>(std::floor((upper[a] - lower[a]) / spacing)) + 1;
    out.spacing[a] = spacing;
    out.origin[a] = lower[a];
  }
  out.data.assign(out.NumberOfVoxels(), 0);
  for (std::size_t k = 0; k < out.size[2]; ++k)
    for (std::size_t j = 0; j < out.size[1]; ++j)
      for (std::size_t i = 0; i < out.size[0]; ++i)
      {
        const Vec3 p = out.PointAt(i, j, k);
        long long  idx[3];
        bool       in = true;
        for (int a = 0; a < 3; ++a)
        {
          idx[a] = std::llround((p[a] - mask.origin[a]) / mask.spacing[a]);
          in = in && idx[a] >= 0 && idx[a] < static_cast<long long>(mask.size[a]);
        }
        if (in)
          out(i, j, k) = mask(static_cast<std::size_t>(idx[0]), static_cast<std::size_t>(idx[1]),
                              static_cast<std::size_t>(idx[2])) != 0;
      }
  return out;
}

/** Empty when the mesh is valid, else what is wrong with it. */
std::string
MeshProblem(const morea_core::TetrahedralMesh & mesh, const morea_core::MeshDomain & domain)
{
  const Vec3   e = domain.Extent();
  const double box = e[0] * e[1] * e[2];
  double       volume = 0.0;
  for (const auto & t : mesh.tetrahedra)
  {
    for (std::uint32_t v : t)
      if (v >= mesh.NumberOfPoints())
        return "a tetrahedron refers to a missing point";
    const double v = morea_core::SignedVolume(t, mesh.points);
    if (!(v > 0.0))
      return "a tetrahedron of volume " + std::to_string(v);
    volume += v;
  }
  if (std::abs(volume - box) > 1e-6 * box)
    return "the tetrahedra's volume " + std::to_string(volume) + " is not the domain's " + std::to_string(box);
  for (const Vec3 & p : mesh.points)
    for (int a = 0; a < 3; ++a)
      if (p[a] < domain.lower[a] - 1e-9 * e[a] || p[a] > domain.upper[a] + 1e-9 * e[a])
        return "a point outside the domain";
  if (mesh.origins.size() != mesh.NumberOfPoints() || mesh.pins.size() != mesh.NumberOfPoints())
    return "per-point data of the wrong size";
  return {};
}

std::size_t
FromEnvironment(const char * name, std::size_t fallback)
{
  const char * text = std::getenv(name);
  return text && *text ? static_cast<std::size_t>(std::stoull(text)) : fallback;
}

/** The kind of a note, for the counts: the text up to the structure's name varies. */
std::string
NoteKind(const std::string & note)
{
  for (const char * kind : { "closed", "meets another structure", "not a closed surface", "made again",
                             "surface constraint of", "is empty", "reaches the domain boundary;" })
    if (note.find(kind) != std::string::npos)
      return kind;
  return note;
}

TEST(MeshFuzz, RandomCropsOfRealMasksGiveValidMeshesOrClearErrors)
{
  const std::size_t cases = FromEnvironment("MOREA_MESH_FUZZ_CASES", 300);
  const std::size_t seed = FromEnvironment("MOREA_MESH_FUZZ_SEED", 20261128);
  // One case again (its number as printed), the others drawn but not meshed.
  const std::size_t only = FromEnvironment("MOREA_MESH_FUZZ_ONLY", ~std::size_t{ 0 });
  const auto        started = std::chrono::steady_clock::now();
  const auto        sources = LoadSources();
  const double      loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::cout << "mesh fuzz: " << cases << " cases, seed " << seed << "; sources:";
  for (const Source & s : sources)
    std::cout << " " << s.name << " (" << s.masks.size() << " masks)";
  std::cout << "; loaded in " << loadSeconds << " s\n";

  morea_core::RandomGenerator             random(seed);
  const auto                         pick = [&random](std::size_t n) { return static_cast<std::size_t>(random.NextU64() % n); };
  std::size_t                        meshes = 0, errors = 0, invalid = 0, allSurfaces = 0, someSurfacesLost = 0;
  std::size_t                        surfacesAsked = 0, surfacesUsed = 0;
  std::map<std::string, std::size_t> noteKinds, errorKinds, perSource;
  std::vector<std::string>           dropped; // the first few notes of surfaces TetGen failed on
  std::string                        slowestCase;
  double                             slowest = 0.0, surfaceSeconds = 0.0, tetgenSeconds = 0.0, otherSeconds = 0.0;
  const auto                         fuzzStart = std::chrono::steady_clock::now();
  for (std::size_t c = 0; c < cases; ++c)
  {
    const auto     drawStart = std::chrono::steady_clock::now();
    const Source & source = sources[pick(sources.size())];
    ++perSource[source.name];
    // A box around a random boundary point of a random structure: it cuts that surface there.
    const std::size_t primary = pick(source.masks.size());
    const auto &      boundary = source.boundaries[primary];
    const Vec3        at = boundary[pick(boundary.size())];
    const Mask &      grid = source.masks[primary].second;
    const double      spacings[] = { 1.5, 2.0, 2.5, 3.0, 4.0 };
    const double      spacing = spacings[pick(5)];
    Vec3              lower, upper;
    for (int a = 0; a < 3; ++a)
    {
      const double centre = at[a] + random.Uniform(-15.0, 15.0);
      const double half = random.Uniform(18.0, 70.0);
      const double first = grid.origin[a], last = grid.origin[a] + grid.spacing[a] * static_cast<double>(grid.size[a] - 1);
      lower[a] = std::max(first, centre - half);
      upper[a] = std::min(last, centre + half);
      if (upper[a] - lower[a] < 4.0 * spacing)
        upper[a] = std::min(last, lower[a] + 4.0 * spacing), lower[a] = std::max(first, upper[a] - 4.0 * spacing);
    }
    std::vector<Mask>        masks;
    std::vector<std::string> names;
    for (const auto & [name, mask] : source.masks)
    {
      Mask cropped = Crop(mask, lower, upper, spacing);
      if (std::any_of(cropped.data.begin(), cropped.data.end(), [](std::uint8_t v) { return v != 0; }))
      {
        masks.push_back(std::move(cropped));
        names.push_back(name);
      }
    }
    if (masks.empty())
    {
      --c; // a box of background only: draw again
      --perSource[source.name];
      continue;
    }
    const morea_core::MeshDomain           domain = morea_core::MeshDomain::OfGrid(masks.front());
    std::vector<morea_core::MeshStructure> structures;
    for (std::size_t s = 0; s < masks.size(); ++s)
      structures.push_back({ names[s], morea_core::MaskBoundaryPoints(masks[s]), &masks[s] });
    morea_core::MeshGeneratorOptions options;
    options.numberOfPoints = 60 + pick(641);
    options.seed = seed + c;
    options.tetrahedralization.isolated = std::getenv("MOREA_MESH_FUZZ_IN_PROCESS") == nullptr;
    options.surfaceStructures.clear();
    for (const std::string & name : names)
      if (random.Uniform() < 0.7)
        options.surfaceStructures.push_back(name);
    if (options.surfaceStructures.empty())
      options.surfaceStructures.push_back(names[pick(names.size())]);
    for (const std::string & name : names)
      options.shares[name] = random.Uniform(0.2, 3.0);
    surfacesAsked += options.surfaceStructures.size();

    const std::string what = source.name + " case " + std::to_string(c) + ": box [" + std::to_string(lower[0]) + ", " +
                             std::to_string(lower[1]) + ", " + std::to_string(lower[2]) + "] - [" +
                             std::to_string(upper[0]) + ", " + std::to_string(upper[1]) + ", " +
                             std::to_string(upper[2]) + "] at " + std::to_string(spacing) + " mm, " +
                             std::to_string(options.numberOfPoints) + " points";
    otherSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - drawStart).count();
    if (only != ~std::size_t{ 0 } && c != only)
    {
      ++meshes; // not meshed: counted as done
      continue;
    }
    const auto caseStart = std::chrono::steady_clock::now();
    try
    {
      morea_core::MeshGenerationReport report;
      const morea_core::TetrahedralMesh mesh = morea_core::GenerateMesh(domain, structures, options, &report);
      if (c == only)
        std::cout << what << ": " << mesh.NumberOfPoints() << " points (" << report.steinerPoints << " Steiner), "
                  << mesh.NumberOfTetrahedra() << " tetrahedra, " << report.surfaceTriangles
                  << " constraint triangles; surfaces " << report.secondsSurfaces << " s, tetrahedralisation "
                  << report.secondsTetrahedralization << " s\n";
      surfaceSeconds += report.secondsSurfaces;
      tetgenSeconds += report.secondsTetrahedralization;
      const std::string problem = MeshProblem(mesh, domain);
      if (!problem.empty())
      {
        ++invalid;
        ADD_FAILURE() << what << ": " << problem;
      }
      ++meshes;
      std::set<std::string> lost;
      for (const std::string & note : report.notes)
      {
        if (c == only)
          std::cout << what << ": note: " << note << "\n";
        ++noteKinds[NoteKind(note)];
        if (NoteKind(note) == "surface constraint of" && dropped.size() < 4)
          dropped.push_back(source.name + ": " + note);
        for (const std::string & name : options.surfaceStructures)
          if (note.rfind("surface of " + name + " ", 0) == 0 && note.find("instead") != std::string::npos)
            lost.insert(name);
          else if (note.rfind("surface constraint of " + name + " ", 0) == 0)
            lost.insert(name);
      }
      surfacesUsed += options.surfaceStructures.size() - lost.size();
      (lost.empty() ? allSurfaces : someSurfacesLost) += 1;
    }
    catch (const morea_core::Error & e)
    {
      ++errors;
      ++errorKinds[std::string(e.what()).substr(0, 60)];
      EXPECT_GT(std::string(e.what()).size(), 10u) << what;
    }
    catch (const std::exception & e)
    {
      ADD_FAILURE() << what << ": not a morea_core::Error: " << e.what();
    }
    const double caseSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - caseStart).count();
    if (caseSeconds > slowest)
    {
      slowest = caseSeconds;
      slowestCase = what;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - fuzzStart).count();
  std::cout << "mesh fuzz: " << cases << " cases in " << seconds << " s (slowest " << slowest << " s): " << meshes
            << " meshes (" << invalid << " invalid; " << allSurfaces << " with every surface asked for as a constraint, " << someSurfacesLost << " with a surface left out), " << errors << " clear errors; surfaces: "
            << surfacesAsked << " asked for, " << surfacesUsed << " constrained the mesh; seconds: crops and contour points "
            << otherSeconds << ", surfaces " << surfaceSeconds << ", tetrahedralisation (TetGen runs, refinement, slivers) "
            << tetgenSeconds << "\n";
  std::cout << "  slowest: " << slowestCase << "\n";
  for (const auto & [name, n] : perSource)
    std::cout << "  cases on " << name << ": " << n << "\n";
  for (const auto & [kind, n] : noteKinds)
    std::cout << "  note \"" << kind << "\": " << n << "\n";
  for (const auto & [kind, n] : errorKinds)
    std::cout << "  error \"" << kind << "...\": " << n << "\n";
  for (const std::string & note : dropped)
    std::cout << "  e.g. " << note << "\n";
  EXPECT_EQ(invalid, 0u);
  EXPECT_EQ(meshes + errors, cases);
}

/** The case reported in the issue: the abdominal pair (moving CB07, fixed
 *  CB02) cropped to the small bowel with 5 mm to spare, which cuts the
 *  stomach, and both organs' surfaces as constraints. TetGen crashed the
 *  process (a double free after it found the surfaces crossing). */
TEST(MeshFuzz, TheAbdomenCropThatCrashedTetGenGivesAMesh)
{
  const std::filesystem::path dir = std::filesystem::path(MOREA_SHARED_DATA_DIR) / "abdomen-cbct-pair";
  if (!std::filesystem::exists(dir / "CB07.mha"))
    GTEST_SKIP() << dir << " is absent";
  itk::morea::RegistrationProblem problem;
  problem.LoadImages((dir / "CB02.mha").string(), (dir / "CB07.mha").string());
  for (const char * organ : { "Stomach_duo_CBCT", "Bowel_sm_CBCT" })
  {
    problem.LoadStructure(organ, true, (dir / "CB02_masks" / (std::string(organ) + ".mha")).string());
    problem.LoadStructure(organ, false, (dir / "CB07_masks" / (std::string(organ) + ".mha")).string());
  }
  morea_core::ParameterSet parameters;
  for (const auto & [key, value] : std::vector<std::pair<std::string, std::string>>{
         { "preprocess_isotropic_spacing", "3.0" },
         { "preprocess_rigid_structure", "none" },
         { "preprocess_crop_structure", "Bowel_sm_CBCT" },
         { "preprocess_crop_margin", "5" },
         { "morea_mesh_surface_structures", "Stomach_duo_CBCT, Bowel_sm_CBCT" },
         { "seed", "1" } })
    parameters.SetFromString(key, value);
  const auto preprocessed =
    itk::morea::Preprocess(problem, itk::morea::PreprocessOptions::FromParameters(parameters)).problem;
  for (const char * points : { "200", "300" })
  {
    parameters.SetFromString("morea_mesh_num_points", points);
    const auto model = itk::morea::BuildMeshModel(preprocessed, parameters);
    EXPECT_EQ(MeshProblem(model.base, model.base.domain), "") << points << " points";
    bool said = false;
    for (const std::string & note : model.report.notes)
    {
      std::cout << points << " points: note: " << note << "\n";
      said = said || note.find("Stomach_duo_CBCT") != std::string::npos;
    }
    EXPECT_TRUE(said) << "the stomach's surface is cut by the crop: a note says what became of it";
  }
}
} // namespace
