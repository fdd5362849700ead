// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration mesh export: VTK XML unstructured grids (.vtu)
// that ParaView and 3D Slicer read.
#ifndef morea_VtuWriter_h
#define morea_VtuWriter_h

#include "morea_core/TetrahedralMesh.h"

#include <string>
#include <vector>

namespace morea_core
{
/** One named scalar per cell (tetrahedron) or per point. */
struct VtuArray
{
  std::string         name;
  std::vector<double> values;
};

/** Writes a tetrahedral mesh as a binary (zlib-compressed) .vtu; the file
 *  appears atomically (temporary name, then rename). Throws morea_core::Error on bad
 *  sizes or an unwritable path. */
void
WriteVtu(const std::string & path, const std::vector<Vec3> & points, const std::vector<Tetrahedron> & tetrahedra,
         const std::vector<VtuArray> & cellData, const std::vector<VtuArray> & pointData = {});
} // namespace morea_core

#endif
