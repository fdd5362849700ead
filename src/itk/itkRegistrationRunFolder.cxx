// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkRegistrationRunFolder.h"

#include "itkLandmarkIO.h"
#include "itkMOREAImageIO.h"
#include "itkRegistrationEvaluation.h"
#include "itkRegistrationOutputs.h"
#include "itkRegistrationPlots.h"
#include "itkTransformFileReader.h"
#include "morea_core/Error.h"
#include "morea_core/OutputFolderLock.h"

#include <zlib.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace itk
{
namespace morea
{
namespace
{
namespace fs = std::filesystem;
using morea_core::Error;

constexpr char FrontMeshesMagic[8] = { 'M', 'O', 'R', 'E', 'A', 'F', 'M', '1' };

template <typename T>
void
Put(std::string & out, const T & value)
{
  out.append(reinterpret_cast<const char *>(&value), sizeof(T));
}

/** Reads values from a byte buffer, failing with the file's name when it ends early. */
class Reader
{
public:
  Reader(const std::string & bytes, const std::string & path)
    : m_Bytes(bytes)
    , m_Path(path)
  {}
  template <typename T>
  T
  Get()
  {
    T value;
    Need(sizeof(T));
    std::memcpy(&value, m_Bytes.data() + m_At, sizeof(T));
    m_At += sizeof(T);
    return value;
  }
  void
  Need(std::size_t n) const
  {
    if (m_Bytes.size() - m_At < n)
      throw Error("'" + m_Path + "' is truncated");
  }

private:
  const std::string & m_Bytes;
  std::string         m_Path;
  std::size_t         m_At{ 0 };
};

std::string
ReadWholeFile(const std::string & path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw Error("cannot read '" + path + "'");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::uint32_t
Checksum(const std::string & bytes, std::size_t length)
{
  return static_cast<std::uint32_t>(
    crc32(0L, reinterpret_cast<const Bytef *>(bytes.data()), static_cast<uInt>(length)));
}

/** What the folder holds of a run's files, for the messages. */
bool
Exists(const fs::path & p)
{
  std::error_code ec;
  return fs::exists(p, ec);
}
} // namespace

void
WriteFrontMeshes(const morea_core::MeshTopology & topology, const std::vector<FrontSolution> & front, const std::string & path)
{
  const std::uint64_t points = topology.NumberOfPoints(), tetrahedra = topology.NumberOfTetrahedra();
  std::string         out(FrontMeshesMagic, sizeof FrontMeshesMagic);
  Put(out, points);
  Put(out, tetrahedra);
  Put(out, static_cast<std::uint64_t>(front.size()));
  for (const auto & t : topology.Tetrahedra())
    for (const auto v : t)
      Put(out, static_cast<std::uint32_t>(v));
  for (const auto & s : front)
  {
    if (s.mesh.source.size() != points || s.mesh.target.size() != points)
      throw Error("front_meshes: a solution's meshes do not match the topology");
    Put(out, static_cast<std::uint64_t>(s.id));
    for (const double o : s.fitness.objectives)
      Put(out, o);
    Put(out, s.fitness.constraint);
    Put(out, static_cast<std::uint8_t>(s.fitness.feasible ? 1 : 0));
    for (const auto * mesh : { &s.mesh.source, &s.mesh.target })
      for (const auto & p : *mesh)
        for (const double c : p)
          Put(out, c);
  }
  Put(out, Checksum(out, out.size()));
  WriteTextFile(out, path);
}

void
WritePreprocessedProblem(const RegistrationProblem & problem, const std::string & folder)
{
  WriteProblemFolder(problem, folder, ".mha");
  nlohmann::json structures = nlohmann::json::array();
  for (const auto & s : problem.structures)
    structures.push_back({ { "name", s.name }, { "fixed_mask", bool(s.fixedMask) }, { "moving_mask", bool(s.movingMask) } });
  WriteTextFile(nlohmann::json{ { "structures", structures } }.dump(2) + "\n", (fs::path(folder) / "problem.json").string());
}

void
CheckRunFolder(const std::string & folder)
{
  const fs::path  root(folder);
  std::error_code ec;
  if (!fs::exists(root, ec))
    throw Error("'" + folder + "' does not exist");
  if (!fs::is_directory(root, ec))
    throw Error("'" + folder + "' is not a folder; give the output folder of a run (morea register -o FOLDER)");
  const bool hasSummary = Exists(root / RegistrationSummaryFileName);
  const bool hasFront = Exists(root / "front.json");
  const bool hasStaging = Exists(root / ".outputs.partial");
  const bool hasLock = Exists(root / morea_core::OutputFolderLock::FileName);
  if (!hasSummary && !hasFront && !hasStaging && !hasLock)
    throw Error("'" + folder + "' is not a MOREA run folder: it has neither summary.json nor front.json");
  if (hasLock)
  {
    // Taken and released at once: a run (or an export) holding it is still writing.
    try
    {
      const morea_core::OutputFolderLock probe(folder);
    }
    catch (const Error & e)
    {
      throw Error("'" + folder + "' is being written by a run right now (" + e.what() +
                  "); look at it when the run has finished");
    }
  }
  if (!hasSummary)
    throw Error("'" + folder + "' holds no complete run: summary.json, written last, is missing" +
                (hasStaging ? " and .outputs.partial holds half-written outputs" : "") +
                " (the run was stopped or failed while writing; run it again)");
  if (hasStaging)
    throw Error("'" + folder + "' holds half-written outputs (.outputs.partial) beside its summary; run it again");
  if (!hasFront)
    throw Error("'" + folder + "' has summary.json but no front.json: not a complete MOREA run");
  if (!Exists(root / FrontMeshesFileName) || !Exists(root / PreprocessedFolderName / "problem.json"))
    throw Error("'" + folder + "' was written without the saved front (" + FrontMeshesFileName + ", " +
                PreprocessedFolderName + "/) that looking at its solutions needs; run it again with this version");
}

SavedRegistrationRun
ReadRunFolder(const std::string & folder)
{
  CheckRunFolder(folder);
  const fs::path       root(folder);
  SavedRegistrationRun run;
  run.folder = folder;
  try
  {
    run.summary = nlohmann::json::parse(ReadWholeFile((root / RegistrationSummaryFileName).string()));
    run.parameters = morea_core::ParameterSet::FromFile((root / "parameters.toml").string());

    // The saved front.
    const std::string path = (root / FrontMeshesFileName).string();
    const std::string bytes = ReadWholeFile(path);
    if (bytes.size() < sizeof FrontMeshesMagic + 4 || std::memcmp(bytes.data(), FrontMeshesMagic, sizeof FrontMeshesMagic) != 0)
      throw Error("'" + path + "' is not a saved front");
    std::uint32_t stored;
    std::memcpy(&stored, bytes.data() + bytes.size() - 4, 4);
    if (stored != Checksum(bytes, bytes.size() - 4))
      throw Error("'" + path + "' is damaged (its checksum does not match)");
    Reader in(bytes, path);
    for (std::size_t i = 0; i < sizeof FrontMeshesMagic; ++i)
      in.Get<char>();
    const auto points = in.Get<std::uint64_t>();
    const auto tetrahedra = in.Get<std::uint64_t>();
    const auto solutions = in.Get<std::uint64_t>();
    in.Need(tetrahedra * 16);
    std::vector<morea_core::Tetrahedron> tets(tetrahedra);
    for (auto & t : tets)
      for (auto & v : t)
      {
        v = in.Get<std::uint32_t>();
        if (v >= points)
          throw Error("'" + path + "' is damaged (a tetrahedron names point " + std::to_string(v) + ")");
      }
    run.topology = morea_core::MeshTopology(tets, points);
    in.Need(solutions * (8 + 32 + 1));
    for (std::uint64_t s = 0; s < solutions; ++s)
    {
      FrontSolution f;
      f.id = in.Get<std::uint64_t>();
      for (auto & o : f.fitness.objectives)
        o = in.Get<double>();
      f.fitness.constraint = in.Get<double>();
      f.fitness.feasible = in.Get<std::uint8_t>() != 0;
      in.Need(points * 48);
      for (auto * mesh : { &f.mesh.source, &f.mesh.target })
      {
        mesh->resize(points);
        for (auto & p : *mesh)
          for (auto & c : p)
            c = in.Get<double>();
      }
      run.front.push_back(std::move(f));
    }

    // The chosen labels, from front.json.
    run.chosen.assign(run.front.size(), "");
    const auto front = nlohmann::json::parse(ReadWholeFile((root / "front.json").string()));
    for (const auto & s : front.at("solutions"))
      for (std::size_t i = 0; i < run.front.size(); ++i)
        if (run.front[i].id == s.at("id").get<std::uint64_t>())
          run.chosen[i] = s.value("chosen", "");

    // The preprocessed problem.
    const fs::path pre = root / PreprocessedFolderName;
    run.problem.LoadImages((pre / "fixed.mha").string(), (pre / "moving.mha").string());
    const auto problemJson = nlohmann::json::parse(ReadWholeFile((pre / "problem.json").string()));
    std::vector<RegistrationProblem::StructureSource> sources;
    for (const auto & s : problemJson.at("structures"))
    {
      const std::string name = s.at("name");
      if (s.value("fixed_mask", false))
        sources.push_back({ name, true, (pre / "fixed_masks" / (name + ".mha")).string() });
      if (s.value("moving_mask", false))
        sources.push_back({ name, false, (pre / "moving_masks" / (name + ".mha")).string() });
    }
    run.problem.LoadStructures(sources);
    if (Exists(pre / "fixed_body.mha"))
      run.problem.LoadBodyMask(true, (pre / "fixed_body.mha").string());
    if (Exists(pre / "moving_body.mha"))
      run.problem.LoadBodyMask(false, (pre / "moving_body.mha").string());
    if (Exists(pre / "fixed_landmarks.txt"))
      run.problem.LoadLandmarks((pre / "fixed_landmarks.txt").string(), (pre / "moving_landmarks.txt").string());

    // The pre-alignment.
    const std::string rigidPath = (root / "rigid_fixed_to_moving.tfm").string();
    auto              reader = TransformFileReaderTemplate<double>::New();
    reader->SetFileName(rigidPath);
    reader->Update();
    const auto * list = reader->GetTransformList();
    if (list->size() != 1)
      throw Error("'" + rigidPath + "' holds " + std::to_string(list->size()) + " transforms, not one");
    run.rigid = dynamic_cast<PreAlignmentTransformType *>(list->front().GetPointer());
    if (!run.rigid)
      throw Error("'" + rigidPath + "' does not hold a linear transform");
  }
  catch (const ExceptionObject & e)
  {
    throw Error("cannot read the run in '" + folder + "': " + e.GetDescription());
  }
  catch (const nlohmann::json::exception & e)
  {
    throw Error("cannot read the run in '" + folder + "': " + e.what());
  }
  if (run.front.empty())
    throw Error("the run in '" + folder + "' has an empty front");
  return run;
}

MeshFields
RasterizeSavedSolution(const SavedRegistrationRun & run, std::size_t index)
{
  if (index >= run.front.size())
    throw Error("solution " + std::to_string(index) + " of a front of " + std::to_string(run.front.size()));
  return RasterizeSolution(run.topology, run.front[index].mesh, run.problem.fixedImage, run.problem.movingImage);
}

std::string
ExportSavedSolution(const SavedRegistrationRun & run, std::size_t index, const MeshFields & fields)
{
  if (index >= run.front.size())
    throw Error("solution " + std::to_string(index) + " of a front of " + std::to_string(run.front.size()));
  const auto &                    s = run.front[index];
  const std::string               label = "solution_" + std::to_string(s.id);
  const morea_core::OutputFolderLock ownership(run.folder);
  const fs::path                  root(run.folder);
  if (!Exists(root / RegistrationSummaryFileName))
    throw Error("'" + run.folder + "' no longer holds a complete run");
  const fs::path  staging = root / ("." + label + ".tmp" + std::to_string(::getpid()) + "_0");
  std::error_code ec;
  fs::remove_all(staging, ec);
  fs::create_directories(staging, ec);
  if (ec)
    throw Error("cannot create '" + staging.string() + "': " + ec.message());
  try
  {
    const std::string dir = staging.string() + "/";
    WriteDisplacementField(fields.fixedToMoving, dir + "preprocessed_fixed_to_moving.nii.gz");
    WriteDisplacementField(fields.movingToFixed, dir + "preprocessed_moving_to_fixed.nii.gz");
    WriteSolutionTransforms(MakeOriginalFrameTransforms(fields, run.rigid), dir + "fixed_to_moving.h5",
                            dir + "moving_to_fixed.h5");
    nlohmann::json entry = { { "id", s.id },
                             { "magnitude", s.fitness.objectives[0] },
                             { "intensity", s.fitness.objectives[1] },
                             { "guidance", s.fitness.objectives[2] },
                             { "exported_from_front", true } };
    if (!run.problem.structures.empty() || !run.problem.fixedLandmarks.empty())
      entry["scores"] = ScoresToJson(EvaluateRegistration(run.problem, fields.fixedToMoving, fields.movingToFixed,
                                                          run.parameters.GetReal("evaluation_border_margin")));
    WriteTextFile(entry.dump(2) + "\n", dir + "scores.json");
    const SolutionSliceViews views(run.problem, fields.fixedToMoving);
    WriteSolutionPlots(views, label, dir + "plot");
    const fs::path target = root / label;
    fs::remove_all(target, ec);
    fs::rename(staging, target);
    return target.string();
  }
  catch (...)
  {
    fs::remove_all(staging, ec);
    throw;
  }
}
} // namespace morea
} // namespace itk
