// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: one MOREA run on a preprocessed problem.
 *
 *  Mesh model, objective data, initial population, MO-RV-GOMEA on the chosen
 *  backend, with checkpoints; returns the approximation set. The template
 *  filter (itkMultiObjectiveMeshRegistrationFilter.h) and the command line
 *  both call this, so the heavy work is compiled once.
 *=========================================================================*/
#ifndef itkMeshRegistration_h
#define itkMeshRegistration_h

#include "itkMeshModel.h"
#include "itkRegistrationProblem.h"
#include "morea_core/EvaluationBackend.h"
#include "morea_core/MoRvGomea.h"
#include "morea_core/RunFingerprint.h"

#include <functional>
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
struct MeshRegistrationOptions
{
  /** Checkpoint file; empty: none. Written every `checkpointInterval`
   *  generations, at the first generation that ends `checkpointSeconds` or
   *  more after the last checkpoint (0: neither), and after the last one. */
  std::string checkpointPath;
  std::size_t checkpointInterval{ 0 };
  double      checkpointSeconds{ 0.0 };
  /** Continue from `checkpointPath` when it exists. */
  bool        resume{ false };
  std::size_t threads{ 0 }; ///< CPU backend threads (CUDA: host threads packing batches); 0: all
  /** Which evaluation backend: the CPU, CUDA (texture or exact
   *  interpolation), or auto: the texture path when a device is usable. */
  morea_core::BackendChoice backend{ morea_core::BackendChoice::Auto };
  int                    device{ 0 };              ///< CUDA device ordinal
  int                    minimumComputeLevel{ 0 }; ///< a device below this compute capability (x10) is not used
  /** Whether candidates that a bound shows refused go unsampled
   *  (morea/RefusalBound.h); the result is the same either way. */
  morea_core::RefusalBoundChoice refusalBounds{ morea_core::RefusalBoundChoice::Auto };
  /** Entries the caller adds to the run's fingerprint (what the checkpoint
   *  belongs to), before those RegisterMeshes adds itself: the parameters,
   *  the preprocessed images, body masks and structures (RunFingerprintOf),
   *  and the mesh. A resume whose fingerprint differs is refused, naming the
   *  first key that differs. */
  morea_core::RunFingerprint fingerprint;
  /** After each generation (also the resumed ones' replay is not called). May throw to abort. */
  std::function<void(const morea_core::GenerationRecord &, std::size_t generations)> onGeneration;
};

/** One solution of the approximation set. */
struct FrontSolution
{
  std::uint64_t       id{ 0 };
  morea_core::Fitness    fitness;
  morea_core::DualMesh   mesh;
};

struct MeshRegistrationResult
{
  MeshModel                              model;
  std::vector<FrontSolution>             front; ///< the elitist archive, by ascending guidance
  std::vector<morea_core::GenerationRecord> history;
  std::string                            backend;     ///< the backend's name: cpu, cuda-texture, cuda-exact
  std::string                            backendNote; ///< why it runs there ("" when asked for by name and used)
  std::string                            pathNote;    ///< a faster path the backend could not take, and why; "" when none
  std::size_t                            threads{ 0 };
  std::size_t                            resumedAtGeneration{ 0 }; ///< 0 when started afresh
  double                                 secondsModel{ 0.0 }; ///< the three below together
  double                                 secondsMesh{ 0.0 };          ///< mesh model (points, tetrahedra, groups)
  double                                 secondsObjectiveData{ 0.0 }; ///< images, distance maps: what the mesh's time did not hide
  double                                 secondsBackend{ 0.0 };       ///< the backend made (device set-up)
  double                                 secondsOptimisation{ 0.0 };
};

/** What the front of a run on the preprocessed `problem` depends on besides
 *  the mesh: the parameters that can change it (all but bookkeeping, the
 *  device and ea_num_generations: a resumed run may go on for longer), then
 *  the images' grids and a hash of their voxels, the body masks, and each
 *  structure's masks and points, in order. RegisterMeshes stores it in checkpoints; `morea benchmark
 *  --from-checkpoint` gives the same. */
morea_core::RunFingerprint
RunFingerprintOf(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters);

/** Registers a preprocessed problem (both images on one grid). */
MeshRegistrationResult
RegisterMeshes(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters,
               const MeshRegistrationOptions & options = {});
} // namespace morea
} // namespace itk

#endif
