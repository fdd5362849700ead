// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: a registration's results as a folder, the one
 *  layout that `morea register`, the filter's users and Python's
 *  RegistrationResult.save write.
 *=========================================================================*/
#ifndef itkRegistrationOutputs_h
#define itkRegistrationOutputs_h

#include "itkMultiObjectiveMeshRegistrationFilterSupport.h"
#include "itkRegistrationEvaluation.h"
#include "morea_core/ParameterSet.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <string>

namespace itk
{
namespace morea
{
/** Where a command's time went before its outputs, for summary.json. */
struct RegistrationOutputTimes
{
  std::chrono::steady_clock::time_point started; ///< the command's start
  double                                load{ 0.0 }; ///< reading the problem
};

/** The name of the file written last into a registration's folder: a folder
 *  without it holds no complete result. */
constexpr const char * RegistrationSummaryFileName = "summary.json";

/** Writes a registration's folder: parameters.toml, the pre-alignment
 *  (rigid_fixed_to_moving.tfm), front.csv, front.json, generations.csv and,
 *  per chosen solution, a folder with both fields (NIfTI, preprocessed
 *  frame), both transforms (.h5, original images' space), both meshes (.vtu)
 *  and, when the fixed structures are known, scores.json and renders.
 *
 *  Everything is written into a hidden staging folder first and moved in
 *  when whole; solution folders and temporary files of earlier runs are
 *  removed; summary.json (the scores, the rigid baseline, the backend and
 *  why, the labels and, where `times` is given, each stage's seconds) is
 *  written last and returned. A failure leaves no new file but the folder's
 *  earlier checkpoint. The caller owns the folder (morea_core::OutputFolderLock).
 *  `trueFixedToMoving`, when known (phantoms), adds the mean displacement
 *  error in the body. Throws morea_core::Error or itk::ExceptionObject. */
nlohmann::json
WriteRegistrationOutputs(const MultiObjectiveRegistrationRun & run, const morea_core::ParameterSet & parameters,
                         const std::string & folder, const DisplacementFieldType * trueFixedToMoving = nullptr,
                         const RegistrationOutputTimes * times = nullptr);

/** The scores as summary.json and scores.json write them. */
nlohmann::json
ScoresToJson(const EvaluationScores & scores);

/** Renders PREFIX_{axial,coronal,sagittal}.png: fixed contours (green) and
 *  moving contours warped by `field` (magenta; identity when null) on the
 *  fixed image, the slices through `focusStructure`. */
void
RenderComparison(const RegistrationProblem & problem, const DisplacementFieldType * field,
                 const std::string & focusStructure, const std::string & prefix);
} // namespace morea
} // namespace itk

#endif
