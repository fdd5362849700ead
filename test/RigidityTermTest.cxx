// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The rigidity term of rigid structures (bones): a rigid motion of a rigid
// region costs nothing, a bend, a squash or a scaling costs more, whichever
// mesh moves; and the choice of rigid structures by name.
#include "BoxMesh.h"

#include "morea_core/Error.h"
#include "morea_core/ParameterSet.h"
#include "morea_core/RigidityTerm.h"
#include "morea_core/RunFingerprint.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace morea_core;
using morea_test::MakeBoxMesh;

namespace
{
TetrahedralMesh
Box()
{
  MeshDomain domain;
  domain.lower = { 0.0, 0.0, 0.0 };
  domain.upper = { 40.0, 20.0, 20.0 };
  const auto      box = MakeBoxMesh(domain, { 4, 2, 2 });
  TetrahedralMesh mesh;
  mesh.domain = domain;
  mesh.points = box.points;
  mesh.tetrahedra = box.tetrahedra;
  return mesh;
}

/** Rotation by `angle` about the axis (1, 2, 2) / 3, then a shift. */
Vec3
RigidMotion(const Vec3 & p, double angle, const Vec3 & shift)
{
  const double u[3] = { 1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0 };
  const double c = std::cos(angle), s = std::sin(angle), dot = u[0] * p[0] + u[1] * p[1] + u[2] * p[2];
  const double cross[3] = { u[1] * p[2] - u[2] * p[1], u[2] * p[0] - u[0] * p[2], u[0] * p[1] - u[1] * p[0] };
  Vec3         q;
  for (int a = 0; a < 3; ++a)
    q[a] = p[a] * c + cross[a] * s + u[a] * dot * (1.0 - c) + shift[a];
  return q;
}

/** The whole term of a solution: the sum over tetrahedra. */
double
Total(const RigidityModel & model, const TetrahedralMesh & mesh, const std::vector<Vec3> & source,
      const std::vector<Vec3> & target)
{
  double sum = 0.0;
  for (std::size_t t = 0; t < mesh.NumberOfTetrahedra(); ++t)
  {
    const Tetrahedron & tet = mesh.tetrahedra[t];
    sum += TetrahedronRigidity(model, t, { source[tet[0]], source[tet[1]], source[tet[2]], source[tet[3]] },
                               { target[tet[0]], target[tet[1]], target[tet[2]], target[tet[3]] });
  }
  return sum;
}

template <typename Map>
std::vector<Vec3>
Moved(const std::vector<Vec3> & points, Map map)
{
  std::vector<Vec3> out;
  for (const Vec3 & p : points)
    out.push_back(map(p));
  return out;
}
} // namespace

TEST(RigidityTerm, RigidMotionsCostNothingAndBendsCostMore)
{
  const TetrahedralMesh     mesh = Box();
  const std::vector<double> all(mesh.NumberOfTetrahedra(), 1.0);
  const RigidityModel       model = BuildRigidityModel(mesh, all, 1000.0);
  ASSERT_FALSE(model.Empty());
  const auto & base = mesh.points;
  // Either mesh, or both, moved rigidly: nothing beyond rounding.
  const auto rotated = Moved(base, [](const Vec3 & p) { return RigidMotion(p, 0.7, { { 5.0, -3.0, 12.0 } }); });
  const auto other = Moved(base, [](const Vec3 & p) { return RigidMotion(p, -1.9, { { -8.0, 2.0, 1.0 } }); });
  EXPECT_LT(Total(model, mesh, base, rotated), 1e-18);
  EXPECT_LT(Total(model, mesh, rotated, base), 1e-18);
  EXPECT_LT(Total(model, mesh, other, rotated), 1e-18);

  // A bend of the bar along x by 2 mm at its end costs; so does it after a rigid motion of both.
  const auto bent = Moved(base, [](const Vec3 & p) {
    return Vec3{ { p[0], p[1], p[2] + 2.0 * (p[0] / 40.0) * (p[0] / 40.0) } };
  });
  const double bend = Total(model, mesh, base, bent);
  EXPECT_GT(bend, 1e-3);
  const auto bentRotated = Moved(bent, [](const Vec3 & p) { return RigidMotion(p, 0.7, { { 5.0, -3.0, 12.0 } }); });
  EXPECT_NEAR(Total(model, mesh, rotated, bentRotated), bend, 1e-9 * bend);
  // A larger bend costs more; a uniform 5 % growth costs too.
  const auto bentMore = Moved(base, [](const Vec3 & p) {
    return Vec3{ { p[0], p[1], p[2] + 4.0 * (p[0] / 40.0) * (p[0] / 40.0) } };
  });
  EXPECT_GT(Total(model, mesh, base, bentMore), 3.0 * bend);
  const auto grown = Moved(base, [](const Vec3 & p) { return Vec3{ { 1.05 * p[0], 1.05 * p[1], 1.05 * p[2] } }; });
  EXPECT_GT(Total(model, mesh, base, grown), 0.0);
}

TEST(RigidityTerm, OnlyRigidTetrahedraCountByTheirShareAndWeight)
{
  const TetrahedralMesh mesh = Box();
  std::vector<double>   fraction(mesh.NumberOfTetrahedra(), 0.0);
  fraction[3] = 1.0;
  fraction[7] = 0.5;
  const RigidityModel model = BuildRigidityModel(mesh, fraction, 10.0);
  ASSERT_FALSE(model.Empty());
  for (std::size_t t = 0; t < fraction.size(); ++t)
    EXPECT_EQ(model.weights[t] > 0.0, fraction[t] > 0.0) << t;
  // Equal volumes (Kuhn split of equal cubes): half the share, half the weight.
  EXPECT_NEAR(model.weights[7], 0.5 * model.weights[3], 1e-12 * model.weights[3]);
  const RigidityModel doubled = BuildRigidityModel(mesh, fraction, 20.0);
  EXPECT_NEAR(doubled.weights[3], 2.0 * model.weights[3], 1e-12 * model.weights[3]);

  // Squashing a tetrahedron that is not rigid costs nothing.
  const auto & base = mesh.points;
  const Tetrahedron & soft = mesh.tetrahedra[0];
  const Tetrahedron & hard = mesh.tetrahedra[3];
  std::array<Vec3, 4> s{ base[soft[0]], base[soft[1]], base[soft[2]], base[soft[3]] }, squashed = s;
  squashed[0][2] += 3.0;
  EXPECT_EQ(TetrahedronRigidity(model, 0, s, squashed), 0.0);
  std::array<Vec3, 4> r{ base[hard[0]], base[hard[1]], base[hard[2]], base[hard[3]] }, pushed = r;
  pushed[0][2] += 3.0;
  EXPECT_GT(TetrahedronRigidity(model, 3, r, pushed), 0.0);

  // No rigid share or weight 0: no model at all.
  EXPECT_TRUE(BuildRigidityModel(mesh, std::vector<double>(mesh.NumberOfTetrahedra(), 0.0), 10.0).Empty());
  EXPECT_TRUE(BuildRigidityModel(mesh, fraction, 0.0).Empty());
  EXPECT_THROW(BuildRigidityModel(mesh, fraction, -1.0), Error);
  EXPECT_THROW(BuildRigidityModel(mesh, { 1.0 }, 1.0), Error);
}

TEST(RigidityTerm, TheStrainLimitViolatesLikeAFoldOnlyBeyondItAndOnlyInsideRigidStructures)
{
  const TetrahedralMesh mesh = Box();
  std::vector<double>   fraction(mesh.NumberOfTetrahedra(), 0.0);
  fraction[3] = 1.0;
  fraction[7] = 0.4; // mostly outside: the term, but no limit
  const RigidityModel model = BuildRigidityModel(mesh, fraction, 10.0, 0.05);
  ASSERT_EQ(model.limitVolumes.size(), mesh.NumberOfTetrahedra());
  EXPECT_GT(model.limitVolumes[3], 0.0);
  EXPECT_EQ(model.limitVolumes[7], 0.0);
  EXPECT_EQ(model.limitVolumes[0], 0.0);
  EXPECT_DOUBLE_EQ(model.strainLimitSquared, 0.0025);
  EXPECT_TRUE(BuildRigidityModel(mesh, fraction, 10.0).limitVolumes.empty()); // no limit
  EXPECT_THROW(BuildRigidityModel(mesh, fraction, 10.0, -0.1), Error);

  const auto & base = mesh.points;
  const Tetrahedron & hard = mesh.tetrahedra[3];
  const std::array<Vec3, 4> r{ base[hard[0]], base[hard[1]], base[hard[2]], base[hard[3]] };
  // A rigid motion and a 2 % stretch stay within 0.05; a 20 % stretch does not.
  std::array<Vec3, 4> moved, small, large;
  for (int i = 0; i < 4; ++i)
  {
    moved[i] = RigidMotion(r[i], 0.9, { { 4.0, 1.0, -2.0 } });
    small[i] = Vec3{ { 1.02 * r[i][0], r[i][1], r[i][2] } };
    large[i] = Vec3{ { 1.2 * r[i][0], r[i][1], r[i][2] } };
  }
  double violated = 0.0;
  EXPECT_EQ(TetrahedronRigidViolation(model, 3, r, moved, violated), 0.0);
  EXPECT_EQ(TetrahedronRigidViolation(model, 3, r, small, violated), 0.0);
  EXPECT_EQ(violated, 0.0);
  const double value = TetrahedronRigidViolation(model, 3, r, large, violated);
  EXPECT_EQ(violated, 1.0);
  // (E_xx = (1.2^2 - 1) / 2 = 0.22)^2 beyond 0.05^2, times the volume.
  EXPECT_NEAR(value, (0.22 * 0.22 - 0.0025) * model.limitVolumes[3], 1e-9);
  // Outside the limit's tetrahedra nothing, however large the strain.
  const Tetrahedron & soft = mesh.tetrahedra[7];
  const std::array<Vec3, 4> s{ base[soft[0]], base[soft[1]], base[soft[2]], base[soft[3]] };
  std::array<Vec3, 4>       stretched = s;
  for (auto & p : stretched)
    p[0] *= 1.5;
  EXPECT_EQ(TetrahedronRigidViolation(model, 7, s, stretched, violated), 0.0);
  EXPECT_EQ(violated, 1.0);
}

TEST(RigidityTerm, FlatTetrahedraSquashedAcrossTheirThinSideCostMoreThanTheirEdgesChange)
{
  // A sliver: its apex 0.2 mm above the base triangle. Pushing the apex
  // through half its height barely changes an edge's length, but halves
  // the volume: the strain is large.
  TetrahedralMesh mesh;
  mesh.points = { { { 0.0, 0.0, 0.0 } }, { { 10.0, 0.0, 0.0 } }, { { 0.0, 10.0, 0.0 } }, { { 3.0, 3.0, 0.2 } } };
  mesh.tetrahedra = { { 0, 1, 2, 3 } };
  const RigidityModel model = BuildRigidityModel(mesh, { 1.0 }, 1.0);
  std::array<Vec3, 4> base{ mesh.points[0], mesh.points[1], mesh.points[2], mesh.points[3] }, squashed = base;
  squashed[3][2] = 0.1;
  double edgeChange = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
    {
      const auto length = [](const Vec3 & a, const Vec3 & b) {
        return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
      };
      edgeChange = std::max(edgeChange, std::abs(length(base[i], base[j]) - length(squashed[i], squashed[j])));
    }
  EXPECT_LT(edgeChange, 0.01);
  EXPECT_GT(TetrahedronRigidDeviation(base, squashed, model.inverseEdges.data()), 0.1); // (0.5^2 - 1)^2 / 4 = 0.14
}

TEST(RigidityTerm, RigidStructuresByNameOrByElasticity)
{
  for (const char * name : { "bones", "Bone_Pelvis", "femoral_head_l", "FemoralHeadRight", "Femur_R", "sacrum",
                             "Vertebra_L5", "rib_3", "Spine" })
    EXPECT_TRUE(NameLooksRigid(name)) << name;
  for (const char * name : { "bladder", "rectum", "bowel", "body", "distribution", "prostate", "spinal_cord" })
    EXPECT_FALSE(NameLooksRigid(name)) << name;

  const std::vector<std::string> available{ "body", "bladder", "bones_left", "implant", "rectum" };
  EXPECT_EQ(SelectRigidStructures("auto", available, { { "implant", 25.0 }, { "bladder", 0.5 } }),
            (std::vector<std::string>{ "bones_left", "implant" }));
  EXPECT_EQ(SelectRigidStructures("auto", available, { { "implant", 9.0 } }), (std::vector<std::string>{ "bones_left" }));
  EXPECT_TRUE(SelectRigidStructures("none", available, {}).empty());
  EXPECT_TRUE(SelectRigidStructures("", available, {}).empty());
  EXPECT_EQ(SelectRigidStructures("rectum, implant, rectum", available, {}),
            (std::vector<std::string>{ "rectum", "implant" }));
  try
  {
    SelectRigidStructures("femur", available, {});
    FAIL() << "an unknown name must be an error";
  }
  catch (const Error & e)
  {
    EXPECT_NE(std::string(e.what()).find("morea_rigid_structures"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bones_left"), std::string::npos) << e.what();
  }
}

TEST(RigidityTerm, CheckpointsOfOtherRigidSettingsAreRefusedNamingTheKey)
{
  const auto firstDifference = [](const std::string & key, const std::string & value) {
    ParameterSet saved, now;
    now.SetFromString(key, value);
    RunFingerprint a, b;
    a.AddParameters(saved);
    b.AddParameters(now);
    return a.FirstDifference(b);
  };
  EXPECT_EQ(firstDifference("morea_rigid_structures", "none").rfind("morea_rigid_structures: \"auto\" in the checkpoint", 0), 0u);
  EXPECT_EQ(firstDifference("morea_rigid_weight", "10").rfind("morea_rigid_weight: 1000 in the checkpoint, 10 in this run", 0), 0u);
}
