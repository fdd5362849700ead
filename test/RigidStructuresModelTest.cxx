// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Rigid structures in the mesh model: which structures morea_rigid_structures
// picks on the phantom, whether or not they are guidance structures, and that
// exactly the tetrahedra overlapping their masks get the rigidity term.
#include "itkMeshModel.h"
#include "itkPhantomImages.h"
#include "morea_core/ElasticityFactors.h"
#include "morea_core/ParameterSet.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace itk::morea;

namespace
{
const RegistrationProblem &
Phantom()
{
  static const RegistrationProblem problem = [] {
    morea_core::PhantomOptions options;
    options.spacing = 6.0;
    return MakePhantomProblem(morea_core::PelvisPhantom(options).Generate());
  }();
  return problem;
}

MeshModel
Model(const std::vector<std::pair<std::string, std::string>> & settings)
{
  morea_core::ParameterSet parameters;
  parameters.SetFromString("morea_mesh_num_points", "80");
  for (const auto & [key, value] : settings)
    parameters.SetFromString(key, value);
  return BuildMeshModel(Phantom(), parameters);
}

std::size_t
RigidTetrahedra(const MeshModel & model)
{
  std::size_t n = 0;
  for (double w : model.rigidity.weights)
    n += w > 0.0;
  return n;
}
} // namespace

TEST(RigidStructuresModel, BonesAreRigidByDefaultGuidanceOrNot)
{
  const MeshModel model = Model({});
  ASSERT_EQ(model.rigidStructureNames, (std::vector<std::string>{ "bones" }));
  ASSERT_FALSE(model.rigidity.Empty());
  // The rigid tetrahedra are those overlapping the bones' moving mask.
  const auto bones = ToVolume(Phantom().GetStructure("bones").movingMask.GetPointer(), model.frame);
  const auto fractions = morea_core::UnionOverlapFractions(model.base, { &bones });
  for (std::size_t t = 0; t < fractions.size(); ++t)
    EXPECT_EQ(model.rigidity.weights[t] > 0.0, fractions[t] > 0.0) << t;
  EXPECT_GT(RigidTetrahedra(model), 0u);
  EXPECT_LT(RigidTetrahedra(model), model.base.NumberOfTetrahedra());

  // Bones not among the guidance structures: still rigid, and the mesh
  // follows their contours too (their points come after the guidance ones').
  const MeshModel bladderOnly = Model({ { "problem_guidance_selection", "bladder" } });
  EXPECT_EQ(bladderOnly.rigidStructureNames, (std::vector<std::string>{ "bones" }));
  EXPECT_GT(RigidTetrahedra(bladderOnly), 0u);
  ASSERT_EQ(bladderOnly.structureNames, (std::vector<std::string>{ "bladder", "bones" }));
  const auto onBones = std::count(bladderOnly.base.structures.begin(), bladderOnly.base.structures.end(), 1);
  EXPECT_GT(onBones, 10);
  const MeshModel plain =
    Model({ { "problem_guidance_selection", "bladder" }, { "morea_rigid_weight", "0" } });
  EXPECT_EQ(plain.structureNames, (std::vector<std::string>{ "bladder" }));
  EXPECT_TRUE(plain.rigidStructureNames.empty());
}

TEST(RigidStructuresModel, TheKeysChooseOrSwitchOff)
{
  const MeshModel none = Model({ { "morea_rigid_structures", "none" } });
  EXPECT_TRUE(none.rigidStructureNames.empty());
  EXPECT_TRUE(none.rigidity.Empty());
  const MeshModel off = Model({ { "morea_rigid_weight", "0" } });
  EXPECT_TRUE(off.rigidity.Empty());
  // An elasticity factor of 10 or more makes a structure rigid under "auto".
  const MeshModel stiff = Model({ { "morea_elasticity_factors", "bones=2, rectum=12" } });
  EXPECT_EQ(stiff.rigidStructureNames, (std::vector<std::string>{ "bones", "rectum" }));
  const MeshModel named = Model({ { "morea_rigid_structures", "rectum" } });
  EXPECT_EQ(named.rigidStructureNames, (std::vector<std::string>{ "rectum" }));
  EXPECT_GT(RigidTetrahedra(named), 0u);
  EXPECT_THROW(Model({ { "morea_rigid_structures", "femur" } }), itk::ExceptionObject);
}
