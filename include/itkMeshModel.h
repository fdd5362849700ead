// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: the mesh model of a preprocessed problem.
 *
 *  Builds, on the moving (source) image of a preprocessed problem (both
 *  images on one grid), the base tetrahedral mesh (SPEC 4.3), its parallel
 *  structure (4.4) and the per-tetrahedron elasticity factors (4.5), and
 *  exports solutions' meshes for ParaView.
 *=========================================================================*/
#ifndef itkMeshModel_h
#define itkMeshModel_h

#include "itkMeshTransforms.h"
#include "itkRegistrationProblem.h"
#include "morea_core/MeshGenerator.h"
#include "morea_core/MeshRefinement.h"
#include "morea_core/ParallelStructure.h"
#include "morea_core/RigidityTerm.h"

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
struct MeshModelReport
{
  morea_core::MeshGenerationReport generation;
  std::size_t                   fosElements{ 0 };
  std::size_t                   parallelGroups{ 0 };
  double                        secondsContourPoints{ 0.0 };
  double                        secondsParallelStructure{ 0.0 };
  double                        secondsElasticity{ 0.0 };
  std::vector<std::string>      notes;
};

struct MeshModel
{
  DomainFrame                     frame;
  morea_core::TetrahedralMesh        base;
  morea_core::MeshTopology           topology;
  morea_core::ParallelStructure      parallel;
  std::vector<double>             elasticity;      ///< per tetrahedron
  morea_core::RigidityModel          rigidity;        ///< empty without rigid structures
  std::vector<std::string>        rigidStructureNames; ///< morea_rigid_structures as resolved
  std::vector<std::string>        structureNames;  ///< indices of base.structures: guidance, then other rigid ones
  MeshModelReport                 report;
};

/** The structures the mesh follows: those named by problem_guidance_selection
 *  ("-1": all but "body"). Throws on a name the problem does not have. */
std::vector<std::string>
GuidanceStructureNames(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters);

/** Builds the mesh model of a preprocessed problem (both images on one grid)
 *  from the morea_mesh_* keys, morea_elasticity_factors (used when
 *  morea_magnitude_metric is "biomechanical"), morea_rigid_structures with
 *  morea_rigid_weight (tetrahedra inside those structures' moving masks, by
 *  the fraction of their elasticity sample points there; rigid structures
 *  that do not guide contribute contour points to the mesh like guidance
 *  structures) and seed. */
MeshModel
BuildMeshModel(const RegistrationProblem & problem, const morea_core::ParameterSet & parameters);

/** The next mesh level: `coarse`'s base mesh bisected to `targetPoints`
 *  points where `density` (per coarse tetrahedron, morea_core::RefinementDensity)
 *  is highest, with its topology, parallel structure, elasticity and
 *  rigidity derived afresh from the problem's masks; `refinement` receives
 *  what carries solutions over (morea_core::CarryOver). */
MeshModel
RefineMeshModel(const MeshModel & coarse, const RegistrationProblem & problem, const morea_core::ParameterSet & parameters,
                const std::vector<double> & density, std::size_t targetPoints, morea_core::MeshRefinement & refinement);

/** Writes both meshes of `solution` as .vtu files in physical space with cell
 *  data "elasticity", "rigidity" (the rigidity term's weight, 0 outside
 *  rigid structures) and "signed_volume" and point data "origin" (corner,
 *  face, random, contour, surface, Steiner, refinement, midpoint as 0..7) and "structure". */
void
WriteSolutionMeshes(const MeshModel & model, const morea_core::DualMesh & solution, const std::string & movingPath,
                    const std::string & fixedPath);
} // namespace morea
} // namespace itk

#endif
