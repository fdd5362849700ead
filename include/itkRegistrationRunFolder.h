// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: a finished run's folder read back, so that
 *  any solution of its front can be looked at and exported after the run.
 *
 *  The outputs writer (itkRegistrationOutputs.h) saves what that needs:
 *  front_meshes.bin (the mesh topology and every front solution's two
 *  meshes, exact) and preprocessed/ (the preprocessed problem as a problem
 *  folder, with problem.json naming its structures in order). With the
 *  pre-alignment (rigid_fixed_to_moving.tfm) and parameters.toml, any
 *  solution is rasterised again exactly as the run would have.
 *=========================================================================*/
#ifndef itkRegistrationRunFolder_h
#define itkRegistrationRunFolder_h

#include "itkMeshRegistration.h"
#include "itkMeshTransforms.h"
#include "itkRegistrationProblem.h"
#include "itkRigidPreAlignment.h"
#include "morea_core/ParameterSet.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace itk
{
namespace morea
{
/** File names inside a run's folder. */
constexpr const char * FrontMeshesFileName = "front_meshes.bin";
constexpr const char * PreprocessedFolderName = "preprocessed";

/** Writes FOLDER/front_meshes.bin: `topology`'s tetrahedra and, per front
 *  solution, its id, objectives, constraint and both meshes (atomically). */
void
WriteFrontMeshes(const morea_core::MeshTopology & topology, const std::vector<FrontSolution> & front,
                 const std::string & path);

/** Writes a preprocessed problem as a problem folder (WriteProblemFolder
 *  with MetaImage, which keeps the grids' geometry exact) plus problem.json
 *  (the structures in order). Reading it back for a solution's scores takes
 *  the masks only. */
void
WritePreprocessedProblem(const RegistrationProblem & problem, const std::string & folder);

/** Throws morea_core::Error, saying what is wrong, unless `folder` holds a
 *  complete run that can be looked at: it exists, is a run's folder
 *  (front.json), no run is writing it now (.morea.lock), its outputs are
 *  whole (summary.json, no staging folder left) and it keeps the saved front
 *  (front_meshes.bin, preprocessed/). */
void
CheckRunFolder(const std::string & folder);

/** A finished run read back from its folder. */
struct SavedRegistrationRun
{
  std::string                           folder;
  RegistrationProblem                   problem; ///< preprocessed
  PreAlignmentTransformType::Pointer    rigid;   ///< original fixed -> original moving before the field
  morea_core::ParameterSet                 parameters;
  morea_core::MeshTopology                 topology;
  std::vector<FrontSolution>            front;   ///< by ascending guidance, as front.json
  std::vector<std::string>              chosen;  ///< per front solution: its labels in the run ("" none)
  nlohmann::json                        summary;
};

/** Reads a run's folder (CheckRunFolder first). Throws morea_core::Error. */
SavedRegistrationRun
ReadRunFolder(const std::string & folder);

/** Solution `index` of the saved front rasterised on the preprocessed grid. */
MeshFields
RasterizeSavedSolution(const SavedRegistrationRun & run, std::size_t index);

/** Writes solution `index` (with `fields`, from RasterizeSavedSolution) into
 *  RUN/solution_<id>/ like the run's chosen solutions: both fields
 *  (preprocessed frame), both transforms between the original images (.h5),
 *  scores.json and the slice plots; staged and moved in whole, under the
 *  folder's lock. Returns the folder written. */
std::string
ExportSavedSolution(const SavedRegistrationRun & run, std::size_t index, const MeshFields & fields);
} // namespace morea
} // namespace itk

#endif
