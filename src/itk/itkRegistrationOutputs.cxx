// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkRegistrationOutputs.h"

#include "itkContourOverlayRenderer.h"
#include "itkImageRegionConstIteratorWithIndex.h"
#include "itkMOREAImageIO.h"
#include "itkMeshTransforms.h"
#include "itkMinimumMaximumImageCalculator.h"
#include "itkRegistrationMetrics.h"
#include "itkRegistrationPlots.h"
#include "itkRegistrationRunFolder.h"
#include "morea_core/Error.h"
#include "itkMOREAFail.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <filesystem>
#include <functional>
#include <future>
#include <regex>
#include <set>
#include <sstream>

namespace itk
{
namespace morea
{
namespace
{
/** Where outputs are written before they are moved into the folder whole. */
constexpr const char * StagingFolderName = ".outputs.partial";

/** Mean |u - truth| in mm over the voxels inside the body (intensity > 0). */
double
MeanDisplacementError(const DisplacementFieldType * field, const DisplacementFieldType * truth,
                      const ImageType * fixed)
{
  using namespace itk::morea;
  double      sum = 0.0;
  std::size_t n = 0;
  for (itk::ImageRegionConstIteratorWithIndex<DisplacementFieldType> it(field, field->GetBufferedRegion()); !it.IsAtEnd();
       ++it)
  {
    if (!(fixed->GetPixel(it.GetIndex()) > 0.0f))
      continue;
    sum += (it.Get() - truth->GetPixel(it.GetIndex())).GetNorm();
    ++n;
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}
/** Another image object over the same pixel buffer: a writer on another
 *  thread updates only this object's pipeline state, while the rest of the
 *  outputs read the original. */
DisplacementFieldType::Pointer
SharingBuffer(const DisplacementFieldType * field)
{
  auto view = DisplacementFieldType::New();
  view->CopyInformation(field);
  view->SetRegions(field->GetBufferedRegion());
  view->SetPixelContainer(const_cast<DisplacementFieldType::PixelContainer *>(field->GetPixelContainer()));
  return view;
}

/** File writes that run beside the rest of the outputs: a field of doubles
 *  written as .nii.gz is mostly deflate (about a second of one core for a
 *  chosen solution's field here), and the outputs write two per solution.
 *  HDF5 is not built to be thread-safe, so transforms stay on the calling
 *  thread. */
class BackgroundWrites
{
public:
  ITK_DISALLOW_COPY_AND_MOVE(BackgroundWrites);
  BackgroundWrites() = default;
  ~BackgroundWrites()
  {
    for (auto & w : m_Writes) // after an error elsewhere: let them finish, errors dropped
      if (w.valid())
        w.wait();
  }

  /** Starts `write` on a thread of its own; with `MaximumInFlight` writes
   *  running, first waits for the oldest (each holds its field, and
   *  `--select all` may write hundreds). */
  void
  Add(std::function<void()> write)
  {
    if (m_Writes.size() - m_Done == MaximumInFlight)
      m_Writes[m_Done++].get(); // its error, if any, stops the outputs here
    m_Writes.push_back(std::async(std::launch::async, std::move(write)));
  }

  /** Waits for every write; the first error, if any, is thrown. */
  void
  Wait()
  {
    std::exception_ptr error;
    for (std::size_t i = m_Done; i < m_Writes.size(); ++i)
      try
      {
        m_Writes[i].get();
      }
      catch (...)
      {
        if (!error)
          error = std::current_exception();
      }
    m_Writes.clear();
    m_Done = 0;
    if (error)
      std::rethrow_exception(error);
  }

private:
  static constexpr std::size_t   MaximumInFlight{ 4 };
  std::vector<std::future<void>> m_Writes;
  std::size_t                    m_Done{ 0 }; ///< m_Writes[0, m_Done) are waited for
};

void
WriteJson(const nlohmann::json & json, const std::string & path)
{
  WriteTextFile(json.dump(2) + "\n", path);
}
} // namespace

nlohmann::json
ScoresToJson(const EvaluationScores & scores)
{
  nlohmann::json j;
  j["border_margin_mm"] = scores.borderMargin;
  for (const auto & s : scores.structures)
    j["structures"][s.name] = { { "dice", s.dice },
                                { "hausdorff_mm", s.hausdorff },
                                { "hausdorff95_mm", s.hausdorff95 },
                                { "mean_surface_distance_mm", s.meanSurfaceDistance } };
  if (scores.hasLandmarks)
    j["landmarks"] = { { "count", scores.landmarks.errors.size() },
                       { "outside_domain", scores.landmarksOutside },
                       { "tre_mean_mm", scores.landmarks.mean },
                       { "tre_sd_mm", scores.landmarks.standardDeviation },
                       { "tre_max_mm", scores.landmarks.maximum },
                       { "tre_mm", scores.landmarks.errors } };
  j["jacobian_nonpositive_fraction"] = scores.nonPositiveJacobianFraction;
  if (scores.hasInverse)
    j["inverse_consistency"] = { { "mean_mm", scores.inverseConsistency.mean },
                                 { "max_mm", scores.inverseConsistency.maximum } };
  return j;
}

void
RenderComparison(const RegistrationProblem & problem, const DisplacementFieldType * field,
                 const std::string & focusStructure, const std::string & prefix)
{
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

namespace
{
/** Every output but summary.json, written into `folder`; returns the summary. */
nlohmann::json
WriteOutputFiles(const MultiObjectiveRegistrationRun & run, const morea_core::ParameterSet & parameters,
                 const std::string & folder, const DisplacementFieldType * trueFixedToMoving,
                 const RegistrationOutputTimes * times)
{
  namespace fs = std::filesystem;
  using Clock = std::chrono::steady_clock;
  const auto outputsStarted = Clock::now();
  // Seconds of the outputs' parts, summed over the chosen solutions.
  double fileSeconds = 0.0, scoreSeconds = 0.0, renderSeconds = 0.0;
  auto   lap = [last = Clock::now()](double & into) mutable {
    const auto now = Clock::now();
    into += std::chrono::duration<double>(now - last).count();
    last = now;
  };
  const auto & preprocessed = run.preprocessed;
  const auto & result = run.registration;
  const auto & problem = preprocessed.problem;
  const double borderMargin = parameters.GetReal("evaluation_border_margin");
  const std::string out = folder + "/";
  WriteTextFile(parameters.ToToml(), out + "parameters.toml");
  WriteRigidTransform(preprocessed.rigidTransform, out + "rigid_fixed_to_moving.tfm");

  // The front.
  std::ostringstream csv;
  csv.precision(10);
  csv << "id,magnitude,intensity,guidance,constraint,chosen\n";
  nlohmann::json front = nlohmann::json::array();
  for (std::size_t i = 0; i < result.front.size(); ++i)
  {
    const auto & s = result.front[i];
    std::string  labels;
    for (const auto & c : run.selected)
      if (c.choice.index == i)
        labels += (labels.empty() ? "" : ";") + c.choice.label;
    csv << s.id << "," << s.fitness.objectives[0] << "," << s.fitness.objectives[1] << "," << s.fitness.objectives[2]
        << "," << s.fitness.constraint << "," << labels << "\n";
    front.push_back({ { "id", s.id },
                      { "magnitude", s.fitness.objectives[0] },
                      { "intensity", s.fitness.objectives[1] },
                      { "guidance", s.fitness.objectives[2] },
                      { "constraint", s.fitness.constraint },
                      { "feasible", s.fitness.feasible },
                      { "chosen", labels } });
  }
  WriteTextFile(csv.str(), out + "front.csv");
  WriteJson({ { "objectives", { "magnitude", "intensity", "guidance" } }, { "solutions", front } }, out + "front.json");

  // The per-generation log.
  std::ostringstream log;
  log.precision(10);
  log << "generation,hypervolume,best_guidance,archive_size,feasible,candidates,folded,accepted,repaired,forced_improvements,"
         "mean_multiplier,tetrahedron_evaluations,seconds,seconds_sampling,seconds_fold_checks,seconds_evaluation,"
         "seconds_acceptance,seconds_forced_improvements,seconds_modelling,seconds_bookkeeping,seconds_device_kernels,"
         "seconds_device_span,samples,bound_skipped,bound_skipped_samples,bound_sampled_later,"
         "bound_sample_later_calls,seconds_bound_sample_later,seconds_parent_state\n";
  for (const auto & r : result.history)
    log << r.generation << "," << r.hypervolume << "," << r.bestGuidance << "," << r.archiveSize << "," << r.feasible
        << "," << r.candidates << "," << r.folded << "," << r.accepted << "," << r.repaired << "," << r.forcedImprovements << "," << r.meanMultiplier << ","
        << r.tetrahedronEvaluations << "," << r.seconds << "," << r.phaseSeconds.sampling << ","
        << r.phaseSeconds.foldChecks << "," << r.phaseSeconds.evaluation << "," << r.phaseSeconds.acceptance << ","
        << r.phaseSeconds.forcedImprovements << "," << r.phaseSeconds.modelling << "," << r.phaseSeconds.bookkeeping
        << "," << r.deviceKernelSeconds << "," << r.deviceSpanSeconds << "," << r.samples << "," << r.boundSkipped
        << "," << r.boundSkippedSamples << "," << r.boundSampledLater << "," << r.boundSampleLaterCalls << ","
        << r.boundSampleLaterSeconds << "," << r.phaseSeconds.parentState << "\n";
  WriteTextFile(log.str(), out + "generations.csv");

  // What looking at any front solution later needs (itkRegistrationRunFolder.h),
  // and the front's and the convergence's plots.
  WriteFrontMeshes(result.model.topology, result.front, out + FrontMeshesFileName);
  WritePreprocessedProblem(problem, out + PreprocessedFolderName);
  {
    std::vector<std::array<double, 3>>               objectives;
    std::vector<std::pair<std::size_t, std::string>> marked;
    for (const auto & s : result.front)
      objectives.push_back(s.fitness.objectives);
    for (const auto & c : run.selected)
      marked.emplace_back(c.choice.index, c.choice.label);
    WriteFrontPlot(objectives, marked, out + "plot_front.png");
    std::vector<double> generations, hypervolume, bestGuidance;
    for (const auto & r : result.history)
    {
      generations.push_back(static_cast<double>(r.generation));
      hypervolume.push_back(r.hypervolume);
      bestGuidance.push_back(r.bestGuidance);
    }
    WriteConvergencePlot(generations, hypervolume, bestGuidance, out + "plot_convergence.png");
  }

  // The chosen solutions.
  const bool       scored = !problem.structures.empty() || !problem.fixedLandmarks.empty();
  nlohmann::json   summary;
  BackgroundWrites writes;
  lap(fileSeconds);
  // The rigid baseline's scores while the first solutions' files are written
  // (they read the images' grids only); waited for before the solutions' own
  // scores, so that no two pipelines share a mask.
  std::future<EvaluationScores> baseline;
  if (scored)
    baseline = std::async(std::launch::async,
                          [&problem, borderMargin] { return EvaluateRegistration(problem, nullptr, nullptr, borderMargin); });
  for (const auto & selected : run.selected)
  {
    const auto &      c = selected.choice;
    const auto &      fields = selected.fields;
    const auto &      s = result.front[c.index];
    const std::string dir = out + c.label + "/";
    fs::create_directories(dir);
    for (const auto & [field, name] : { std::make_pair(fields.fixedToMoving, "preprocessed_fixed_to_moving.nii.gz"),
                                        std::make_pair(fields.movingToFixed, "preprocessed_moving_to_fixed.nii.gz") })
      writes.Add([view = SharingBuffer(field), path = dir + name] { WriteDisplacementField(view, path); });
    WriteSolutionTransforms(selected.original, dir + "fixed_to_moving.h5", dir + "moving_to_fixed.h5");
    WriteSolutionMeshes(result.model, s.mesh, dir + "mesh_moving.vtu", dir + "mesh_fixed.vtu");
    lap(fileSeconds);
    nlohmann::json entry = { { "id", s.id },
                             { "magnitude", s.fitness.objectives[0] },
                             { "intensity", s.fitness.objectives[1] },
                             { "guidance", s.fitness.objectives[2] } };
    auto repairJson = [](const morea_core::FieldFoldRepairReport & r, const morea_core::RasterizationReport & raster) {
      return nlohmann::json{ { "folded_voxels_before", r.foldedBefore },
                             { "folded_voxels_after", r.foldedAfter },
                             { "voxels_changed", r.voxelsChanged },
                             { "voxels_changed_over_1mm", r.voxelsChangedOver1mm },
                             { "maximum_change_mm", r.maximumChange },
                             { "projection_rounds", r.projectionRounds },
                             { "smoothing_rounds", r.smoothingRounds },
                             { "voxels_outside_mesh", raster.outsideMesh },
                             { "folded_voxels_before_outside_mesh", r.foldedBeforeOutsideMesh },
                             { "maximum_change_inside_mesh_mm", r.maximumChangeInsideMesh } };
    };
    entry["voxel_fold_repair"] = { { "fixed_to_moving", repairJson(fields.fixedFoldRepair, fields.fixedReport) },
                                   { "moving_to_fixed", repairJson(fields.movingFoldRepair, fields.movingReport) } };
    if (scored)
    {
      baseline.wait();
      const auto scores = EvaluateRegistration(problem, fields.fixedToMoving, fields.movingToFixed, borderMargin);
      entry["scores"] = ScoresToJson(scores);
      if (trueFixedToMoving)
        entry["mean_displacement_error_in_body_mm"] =
          MeanDisplacementError(fields.fixedToMoving, trueFixedToMoving, problem.fixedImage);
      WriteJson(entry, dir + "scores.json");
      lap(scoreSeconds);
      RenderComparison(problem, fields.fixedToMoving, preprocessed.report.cropStructure, dir + "render");
      lap(renderSeconds);
    }
    WriteSolutionPlots(SolutionSliceViews(problem, fields.fixedToMoving), c.label + " (solution " + std::to_string(s.id) + ")",
                       dir + "plot");
    lap(renderSeconds);
    summary["solutions"][c.label] = entry;
  }
  if (scored)
    summary["rigid_baseline"] = ScoresToJson(baseline.get());
  lap(scoreSeconds);
  writes.Wait();
  lap(fileSeconds);
  summary["problem_id"] = parameters.GetString("problem_id");
  summary["sweep_descriptor"] = parameters.GetString("sweep_descriptor");
  summary["seed"] = parameters.GetInteger("seed");
  summary["backend_note"] = result.backendNote;
  summary["backend_path_note"] = result.pathNote;
  summary["front_size"] = result.front.size();
  summary["generations"] = result.history.empty() ? 0 : result.history.back().generation;
  summary["backend"] = result.backend;
  summary["threads"] = result.threads;
  summary["seconds"] = { { "preprocessing", run.secondsPreprocessing },
                         { "model", result.secondsModel },
                         { "optimisation", result.secondsOptimisation },
                         { "fields", run.secondsSelection } };
  auto & seconds = summary["seconds"];
  seconds["model_parts"] = { { "mesh", result.secondsMesh },
                             { "objective_data", result.secondsObjectiveData },
                             { "backend", result.secondsBackend } };
  seconds["registration_other"] = run.secondsRegistration - result.secondsModel - result.secondsOptimisation;
  seconds["outputs"] = std::chrono::duration<double>(Clock::now() - outputsStarted).count();
  seconds["outputs_parts"] = { { "files", fileSeconds }, { "scores", scoreSeconds }, { "renders", renderSeconds } };
  if (times)
  {
    // summary.json's own writing is the only part left out.
    seconds["load"] = times->load;
    seconds["command"] = std::chrono::duration<double>(Clock::now() - times->started).count();
  }
  return summary;
}

/** Whether `entry`, a folder inside a registration's folder, is a chosen
 *  solution's folder (of this layout). */
bool
IsSolutionFolder(const std::filesystem::path & entry)
{
  std::error_code ec;
  return std::filesystem::is_directory(entry, ec) &&
         (std::filesystem::exists(entry / "fixed_to_moving.h5", ec) ||
          std::filesystem::exists(entry / "mesh_fixed.vtu", ec));
}

/** A temporary file or folder of an atomic write (WriteTextFile's
 *  ".NAME.tmpPID_N.EXT"), or an earlier staging folder. */
bool
IsTemporary(const std::string & name)
{
  static const std::regex temporary(R"(\..*\.tmp[0-9]+_[0-9]+.*)");
  return name == StagingFolderName || std::regex_match(name, temporary);
}
} // namespace

nlohmann::json
WriteRegistrationOutputs(const MultiObjectiveRegistrationRun & run, const morea_core::ParameterSet & parameters,
                         const std::string & folder, const DisplacementFieldType * trueFixedToMoving,
                         const RegistrationOutputTimes * times)
{
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec)
    Fail("cannot create the output folder '" + folder + "': " + ec.message());
  const fs::path root(folder);
  // From here on the folder holds no complete result until the new summary.
  fs::remove(root / RegistrationSummaryFileName, ec);
  if (ec)
    Fail("cannot remove the earlier '" + (root / RegistrationSummaryFileName).string() + "': " + ec.message());
  // Leftovers of earlier runs that stopped while writing: the caller owns the folder.
  for (const auto & entry : fs::directory_iterator(root))
    if (IsTemporary(entry.path().filename().string()))
      fs::remove_all(entry.path(), ec);
  const fs::path staging = root / StagingFolderName;
  fs::create_directory(staging, ec);
  if (ec)
    Fail("cannot create '" + staging.string() + "': " + ec.message());
  nlohmann::json summary;
  try
  {
    summary = WriteOutputFiles(run, parameters, staging.string(), trueFixedToMoving, times);
  }
  catch (...)
  {
    fs::remove_all(staging, ec);
    throw;
  }
  // Publish: earlier solution folders go, the staged files move in (renames
  // within one folder), and the summary marks the result whole.
  for (const auto & entry : fs::directory_iterator(root))
    if (entry.path() != staging && IsSolutionFolder(entry.path()))
      fs::remove_all(entry.path());
  for (const auto & entry : fs::directory_iterator(staging))
  {
    const fs::path target = root / entry.path().filename();
    if (fs::is_directory(target))
      fs::remove_all(target);
    fs::rename(entry.path(), target);
  }
  fs::remove(staging);
  WriteJson(summary, (root / RegistrationSummaryFileName).string());
  return summary;
}
} // namespace morea
} // namespace itk
