// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Shared fixtures of the mesh model tests: a 600-point mesh of the phantom.
#ifndef MeshTestSupport_h
#define MeshTestSupport_h

#include "morea_core/MeshGenerator.h"
#include "morea_core/MeshPointPlacement.h"
#include "morea_core/Phantom.h"

#include <algorithm>
#include <memory>

namespace morea_test
{
struct PhantomMesh
{
  morea_core::PelvisPhantom::Case    phantomCase;
  morea_core::MeshDomain             domain;
  morea_core::TetrahedralMesh        mesh;
  morea_core::MeshGenerationReport   report;
  std::vector<std::string>      names;
  /** The mesh's structures (all but the body), pointing at phantomCase's masks. */
  std::vector<morea_core::MeshStructure> structures;
};

/** The phantom at 3 mm; the domain is the bladder's bounding box on the moving
 *  image plus 30 mm (as preprocessing would crop); the mesh is built on the
 *  moving image with the bladder surface as a constraint. Built once. */
inline const PhantomMesh &
PhantomMesh600()
{
  static const std::unique_ptr<PhantomMesh> cached = [] {
    auto                  pm = std::make_unique<PhantomMesh>();
    morea_core::PhantomOptions po;
    po.spacing = 3.0;
    pm->phantomCase = morea_core::PelvisPhantom(po).Generate();
    pm->names = morea_core::PelvisPhantom::StructureNames();
    const auto & bladder = pm->phantomCase.movingMasks[2];
    morea_core::Vec3  lo{ { 1e9, 1e9, 1e9 } }, hi{ { -1e9, -1e9, -1e9 } };
    for (const morea_core::Vec3 & p : morea_core::MaskBoundaryPoints(bladder))
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = std::min(lo[a], p[a]);
        hi[a] = std::max(hi[a], p[a]);
      }
    const morea_core::MeshDomain full = morea_core::MeshDomain::OfGrid(bladder);
    for (int a = 0; a < 3; ++a)
    {
      pm->domain.lower[a] = std::max(full.lower[a], lo[a] - 30.0);
      pm->domain.upper[a] = std::min(full.upper[a], hi[a] + 30.0);
    }
    for (std::size_t s = 1; s < pm->names.size(); ++s) // all but the body
    {
      pm->structures.push_back({ pm->names[s], morea_core::MaskBoundaryPoints(pm->phantomCase.movingMasks[s]),
                                 &pm->phantomCase.movingMasks[s] });
    }
    morea_core::MeshGeneratorOptions options; // 600 points, bladder surface
    options.seed = 7;
    pm->mesh = morea_core::GenerateMesh(pm->domain, pm->structures, options, &pm->report);
    return pm;
  }();
  return *cached;
}
} // namespace morea_test

#endif
