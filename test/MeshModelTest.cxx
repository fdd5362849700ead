// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The mesh model end to end on the phantom: random initial solutions
// rasterised in both directions compose to the identity.
#include "MeshTestSupport.h"

#include "morea_core/FoldConstraint.h"
#include "morea_core/InitialPopulation.h"
#include "morea_core/MeshRasterizer.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>

namespace
{
using morea_core::Vec3;

/** Trilinear interpolation of a displacement volume (clamped at the border). */
Vec3
Interpolate(const morea_core::Volume<Vec3> & field, const Vec3 & p)
{
  double      t[3];
  std::size_t i0[3], i1[3];
  for (int a = 0; a < 3; ++a)
  {
    const double c = std::clamp((p[a] - field.origin[a]) / field.spacing[a], 0.0, double(field.size[a] - 1));
    i0[a] = static_cast<std::size_t>(std::floor(c));
    i1[a] = std::min(i0[a] + 1, field.size[a] - 1);
    t[a] = c - double(i0[a]);
  }
  Vec3 r{ { 0, 0, 0 } };
  for (int corner = 0; corner < 8; ++corner)
  {
    const std::size_t i = (corner & 1) ? i1[0] : i0[0], j = (corner & 2) ? i1[1] : i0[1],
                      k = (corner & 4) ? i1[2] : i0[2];
    const double w = ((corner & 1) ? t[0] : 1 - t[0]) * ((corner & 2) ? t[1] : 1 - t[1]) * ((corner & 4) ? t[2] : 1 - t[2]);
    for (int a = 0; a < 3; ++a)
      r[a] += w * field(i, j, k)[a];
  }
  return r;
}

TEST(MeshModel, BothDirectionsOfRandomSolutionsComposeToIdentity)
{
  const auto &              pm = morea_test::PhantomMesh600();
  const morea_core::MeshTopology topology(pm.mesh.tetrahedra, pm.mesh.NumberOfPoints());
  morea_core::FoldConstraint     constraint(topology, pm.mesh.points);
  const auto                population = morea_core::GenerateInitialPopulation(pm.mesh, constraint, 9, 11);

  const double               h = 3.0; // the phantom's voxel size
  std::array<std::size_t, 3> size{};
  const Vec3                 e = pm.domain.Extent();
  for (int a = 0; a < 3; ++a)
    size[a] = static_cast<std::size_t>(std::lround(e[a] / h)) + 1;
  for (std::size_t s = 1; s < population.size(); ++s)
  {
    morea_core::Volume<Vec3> fixedToMoving(size, { { h, h, h } }, pm.domain.lower);
    morea_core::Volume<Vec3> movingToFixed = fixedToMoving;
    morea_core::RasterizationReport forward, backward;
    const auto start = std::chrono::steady_clock::now();
    morea_core::RasterizeDisplacement(topology, population[s].target, population[s].source, fixedToMoving, &forward);
    morea_core::RasterizeDisplacement(topology, population[s].source, population[s].target, movingToFixed, &backward);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(forward.outsideMesh, 0u);
    EXPECT_EQ(backward.outsideMesh, 0u);

    double worst = 0.0, largest = 0.0;
    for (std::size_t k = 0; k < size[2]; ++k)
      for (std::size_t j = 0; j < size[1]; ++j)
        for (std::size_t i = 0; i < size[0]; ++i)
        {
          const Vec3 x = fixedToMoving.PointAt(i, j, k);
          const Vec3 u = fixedToMoving(i, j, k);
          const Vec3 y{ { x[0] + u[0], x[1] + u[1], x[2] + u[2] } };
          const Vec3 v = Interpolate(movingToFixed, y);
          largest = std::max(largest, std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]));
          const double err = std::sqrt((y[0] + v[0] - x[0]) * (y[0] + v[0] - x[0]) +
                                            (y[1] + v[1] - x[1]) * (y[1] + v[1] - x[1]) +
                                            (y[2] + v[2] - x[2]) * (y[2] + v[2] - x[2]));
          worst = std::max(worst, err);
        }
    EXPECT_GT(largest, 0.5) << "solution " << s << " hardly deforms";
    EXPECT_LT(worst, 0.1 * h) << "solution " << s;
    std::cout << "solution " << s << ": largest displacement " << largest << " mm, worst inverse-consistency error "
              << worst << " mm, both fields in " << seconds << " s (" << fixedToMoving.NumberOfVoxels()
              << " voxels each)\n";
  }
}
} // namespace
