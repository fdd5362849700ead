// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration mesh generation: the base mesh of a registration
// problem (SPEC 4.3): spread-out contour points per structure, optional
// structure surfaces as constraints, random points, the domain's corners, and
// a constrained Delaunay tetrahedralisation covering the whole domain.
#ifndef morea_MeshGenerator_h
#define morea_MeshGenerator_h

#include "morea_core/TetrahedralMesh.h"
#include "morea_core/Tetrahedralization.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace morea_core
{
class ParameterSet;

/** One structure on the image the mesh is built on (the moving image). */
struct MeshStructure
{
  std::string                   name;
  std::vector<Vec3>             contourPoints; ///< surface points, domain frame
  const Volume<std::uint8_t> *  mask{ nullptr }; ///< needed only for surface constraints
};

struct MeshGeneratorOptions
{
  std::size_t                   numberOfPoints{ 600 };
  bool                          useContourPoints{ true };  ///< "annotation-group"
  double                        randomFraction{ 0.10 };    ///< of all points
  double                        boundaryFraction{ 0.25 };  ///< of the random points, on the faces
  /** Of the inner random points, the share placed instead at circumcentres of
   *  the worst-shaped tetrahedra: contour points lie on smooth, often nearly
   *  spherical surfaces, and their Delaunay mesh has slivers (flat
   *  tetrahedra) that fold at the slightest move. */
  double                        refinementFraction{ 0.5 };
  std::vector<std::string>      surfaceStructures{ "bladder" };
  /** Shells around the deforming organs: points at these distances (mm)
   *  outside each of shellStructures, a share shellFraction of all points.
   *  Soft tissue next to an organ that fills or empties moves with it, and
   *  its motion decays within a few centimetres; without points there, one
   *  tetrahedron spans from the organ's wall to tissue far away and carries
   *  the wall's motion into it (bench/results/mesh-shells.md). Empty: no shells. */
  std::vector<double>           shellOffsets{ 8.0, 20.0 };
  double                        shellFraction{ 0.15 };
  std::vector<std::string>      shellStructures{ "bladder" };
  std::map<std::string, double> shares;                    ///< per structure, default 1
  std::uint64_t                 seed{ 0 };
  /** How TetGen runs (by default each run in a child process, so that its
   *  crash on bad surfaces drops the surfaces instead of ending the program). */
  TetrahedralizationOptions     tetrahedralization;

  /** From morea_mesh_generation_method ("annotation-group-random-bladder-10":
   *  contour points, 10 % random points, surfaces of morea_mesh_surface_structures
   *  as constraints; "annotation-group-random-10": no surfaces; "random": random
   *  points only), morea_mesh_num_points, morea_mesh_structure_shares,
   *  morea_mesh_boundary_fraction and seed. */
  static MeshGeneratorOptions
  FromParameters(const ParameterSet & parameters);
};

struct MeshGenerationReport
{
  std::size_t                                       corners{ 0 };
  std::size_t                                       boundaryPoints{ 0 };
  std::size_t                                       randomPoints{ 0 };
  std::size_t                                       refinementPoints{ 0 };
  double                                            worstQuality{ 0.0 }; ///< lowest TetrahedronQuality
  std::size_t                                       slivers{ 0 };        ///< tetrahedra of quality < 0.05
  std::size_t                                       contourPoints{ 0 };
  std::size_t                                       shellPoints{ 0 };
  std::size_t                                       surfacePoints{ 0 };
  std::size_t                                       surfaceTriangles{ 0 };
  std::size_t                                       steinerPoints{ 0 };
  std::size_t                                       tetrahedra{ 0 };
  std::vector<std::pair<std::string, std::size_t>> pointsPerStructure;
  /** e.g. a surface that could not be used, or a surface constraint dropped
   *  because TetGen failed on it (and why) */
  std::vector<std::string>                          notes;
  double                                            secondsPlacement{ 0.0 };
  double                                            secondsSurfaces{ 0.0 };
  double                                            secondsTetrahedralization{ 0.0 };
};

/** Builds the base mesh over `domain`. The point count is
 *  options.numberOfPoints plus any Steiner points TetGen adds to recover the
 *  surfaces. Deterministic for a given seed. Throws morea_core::Error on failure. */
TetrahedralMesh
GenerateMesh(const MeshDomain & domain, const std::vector<MeshStructure> & structures,
             const MeshGeneratorOptions & options, MeshGenerationReport * report = nullptr);
} // namespace morea_core

#endif
