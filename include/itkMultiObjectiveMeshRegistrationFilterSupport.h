// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: the non-template half of
 *  itk::MultiObjectiveMeshRegistrationFilter.
 *
 *  Preprocessing, the MOREA run, choosing solutions and rasterising them are
 *  compiled once here; the template filter only converts its inputs and
 *  wires the results to its outputs.
 *=========================================================================*/
#ifndef itkMultiObjectiveMeshRegistrationFilterSupport_h
#define itkMultiObjectiveMeshRegistrationFilterSupport_h

#include "itkIndent.h"
#include "itkMeshRegistration.h"
#include "itkMeshTransforms.h"
#include "itkPreprocessing.h"

#include <array>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace morea_core
{
class ParameterSet;
}

namespace itk
{
namespace morea
{
/** One solution of the approximation set, without its meshes. */
struct ApproximationSolution
{
  std::uint64_t         id{ 0 };
  std::array<double, 3> objectives{ { 0.0, 0.0, 0.0 } }; ///< magnitude, intensity, guidance (minimised)
  double                constraint{ 0.0 };               ///< fold constraint; 0 for the archive's solutions
};

bool
operator==(const ApproximationSolution & a, const ApproximationSolution & b);
bool
operator!=(const ApproximationSolution & a, const ApproximationSolution & b);
std::ostream &
operator<<(std::ostream & os, const ApproximationSolution & s);

/** The approximation set, by ascending guidance. */
using ApproximationSet = std::vector<ApproximationSolution>;

ApproximationSet
ToApproximationSet(const std::vector<FrontSolution> & front);

/** A chosen solution: why it was chosen and where it is in the approximation set. */
struct SolutionChoice
{
  std::string label; ///< "best_guidance", "knee", "weighted", "nearest", "solution_<id>"
  std::size_t index{ 0 };
};

/** Throws morea_core::Error unless `selection` is a comma-separated list of
 *  best-guidance, knee, weighted:a:b:c, nearest:m:i:g, spread:N and all, with at least one item. */
void
CheckSolutionSelection(const std::string & selection);

/** The solutions `selection` names, in its order; a label chosen twice counts
 *  once. Throws morea_core::Error on an empty set or a bad selection. */
std::vector<SolutionChoice>
SelectSolutions(const ApproximationSet & set, const std::string & selection);

/** A chosen solution: its fields and transforms in the preprocessed frame
 *  and its transforms between the original images. */
struct SelectedSolution
{
  SolutionChoice          choice;
  MeshFields              fields;
  OriginalFrameTransforms original;
};

/** Everything one registration makes, from reading the inputs to the chosen
 *  solutions' transforms: what the filter outputs and what
 *  `morea register` writes. */
struct MultiObjectiveRegistrationRun
{
  PreprocessResult              preprocessed; ///< the problem on the preprocessed grid, the rigid pre-alignment
  MeshRegistrationResult        registration; ///< mesh model, front with meshes, history, backend
  ApproximationSet              approximationSet;
  std::vector<SelectedSolution> selected;
  double                        secondsPreprocessing{ 0.0 };
  double                        secondsRegistration{ 0.0 }; ///< model and optimisation
  double                        secondsSelection{ 0.0 };    ///< rasterising the chosen solutions
};

/** Shares of the progress range: preprocessing and mesh model up to the first,
 *  generations up to the second, rasterising the chosen solutions the rest. */
constexpr double PreprocessingProgressShare = 0.05;
constexpr double OptimisationProgressEnd = 0.95;

/** Refuses, with a message naming the key, parameter values one
 *  registration cannot honour: num_runs > 1 (the command line runs several)
 *  and zip = true (the filter writes no folder). Throws morea_core::Error. */
void
CheckSingleRunParameters(const morea_core::ParameterSet & parameters);

/** Validates `problem`, preprocesses it (pre-aligned by `initialTransform`
 *  when given, else as the parameters say), runs MOREA and rasterises the
 *  solutions `selection` names on the preprocessed grid. The CUDA device and
 *  its lowest compute level come from the parameters (cuda_gpu_id,
 *  cuda_compute_level). `progress` (may be empty) gets the cumulative
 *  fraction done; it and `options.onGeneration` may throw to abort. Throws
 *  morea_core::Error (or what the callbacks throw). */
MultiObjectiveRegistrationRun
RunMultiObjectiveRegistration(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters,
                              const MeshRegistrationOptions & options, const std::string & selection,
                              const std::function<void(double)> & progress,
                              const PreAlignmentTransformType * initialTransform = nullptr);

/** An ITK exception's description without the "ITK ERROR: Class(0x...): "
 *  prefix that itkExceptionMacro adds: the message as a user should read it. */
std::string
UserMessage(const std::string & description);

/** Prints the explicitly set parameters and the main run keys, one per line. */
void
PrintParameters(std::ostream & os, const morea_core::ParameterSet & parameters, Indent indent);
} // namespace morea
} // namespace itk

#endif
