// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkMeshTransforms.h"

#include "itkMOREAImageIO.h"

#include "BoxMesh.h"

#include <gtest/gtest.h>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <filesystem>
#include <random>

namespace fs = std::filesystem;
using itk::morea::DomainFrame;
using itk::morea::PointType;
using morea_core::Vec3;

namespace
{
using Mat3 = std::array<Vec3, 3>; // rows

const Mat3 AffineMatrix{ { { { 1.05, 0.08, -0.03 } }, { { -0.06, 0.95, 0.05 } }, { { 0.04, -0.02, 1.10 } } } };
const Vec3 AffineOffset{ { 2.0, -1.5, 1.0 } };

Vec3
AffineImage(const Vec3 & x)
{
  Vec3 y;
  for (int r = 0; r < 3; ++r)
    y[r] = AffineMatrix[r][0] * x[0] + AffineMatrix[r][1] * x[1] + AffineMatrix[r][2] * x[2] + AffineOffset[r];
  return y;
}

/** Solves A x = y - b by Cramer's rule. */
Vec3
InverseAffineImage(const Vec3 & y)
{
  const Vec3 r{ { y[0] - AffineOffset[0], y[1] - AffineOffset[1], y[2] - AffineOffset[2] } };
  auto       det = [](const Vec3 & c0, const Vec3 & c1, const Vec3 & c2) {
    return c0[0] * (c1[1] * c2[2] - c1[2] * c2[1]) - c1[0] * (c0[1] * c2[2] - c0[2] * c2[1]) +
           c2[0] * (c0[1] * c1[2] - c0[2] * c1[1]);
  };
  Vec3 columns[3];
  for (int c = 0; c < 3; ++c)
    columns[c] = { { AffineMatrix[0][c], AffineMatrix[1][c], AffineMatrix[2][c] } };
  const double d = det(columns[0], columns[1], columns[2]);
  return { det(r, columns[1], columns[2]) / d, det(columns[0], r, columns[2]) / d, det(columns[0], columns[1], r) / d };
}

/** 90 degrees about z: the first grid axis points along physical +y. */
DomainFrame::DirectionType
RotationAboutZ()
{
  DomainFrame::DirectionType d;
  d.Fill(0.0);
  d[0][1] = -1.0;
  d[1][0] = 1.0;
  d[2][2] = 1.0;
  return d;
}

itk::morea::ImageType::Pointer
MakeGrid(const DomainFrame & frame, const Vec3 & frameOrigin, itk::Size<3> size, const Vec3 & spacing)
{
  auto                               image = itk::morea::ImageType::New();
  itk::morea::ImageType::SpacingType s;
  for (int a = 0; a < 3; ++a)
    s[a] = spacing[a];
  image->SetRegions(itk::morea::ImageType::RegionType(size));
  image->SetSpacing(s);
  image->SetOrigin(frame.ToPhysical(frameOrigin));
  image->SetDirection(frame.GetDirection());
  image->Allocate(true);
  return image;
}

double
Distance(const PointType & a, const PointType & b)
{
  return a.EuclideanDistanceTo(b);
}

class MeshTransforms : public ::testing::Test
{
protected:
  DomainFrame                    frame{ RotationAboutZ() };
  itk::morea::ImageType::Pointer fixed =
    MakeGrid(frame, { { 35.0, 20.0, 10.0 } }, { { 36, 34, 30 } }, { { 1.2, 1.0, 1.1 } });
  // The moving grid covers the fixed one with a margin, on other voxels.
  itk::morea::ImageType::Pointer moving =
    MakeGrid(frame, { { 32.0, 17.0, 7.0 } }, { { 44, 41, 36 } }, { { 1.1, 0.95, 1.05 } });
  morea_test::BoxMesh box = morea_test::MakeBoxMesh(morea_core::MeshDomain::OfGrid(frame.FieldGridOf(fixed)), { 4, 4, 3 });
  morea_core::MeshTopology topology{ box.tetrahedra, box.points.size() };

  std::vector<PointType>
  FixedVoxelCentres() const
  {
    std::vector<PointType>           points;
    itk::morea::ImageType::IndexType index;
    const auto                       size = fixed->GetLargestPossibleRegion().GetSize();
    for (index[2] = 0; index[2] < static_cast<long>(size[2]); ++index[2])
      for (index[1] = 0; index[1] < static_cast<long>(size[1]); ++index[1])
        for (index[0] = 0; index[0] < static_cast<long>(size[0]); ++index[0])
        {
          PointType p;
          fixed->TransformIndexToPhysicalPoint(index, p);
          points.push_back(p);
        }
    return points;
  }
};
} // namespace

TEST_F(MeshTransforms, FrameIsTheRotatedGrid)
{
  // Grid axis 0 runs along physical +y, so one step along it moves the frame's x.
  const PointType p = frame.ToPhysical({ { 1.0, 2.0, 3.0 } });
  EXPECT_DOUBLE_EQ(p[0], -2.0);
  EXPECT_DOUBLE_EQ(p[1], 1.0);
  EXPECT_DOUBLE_EQ(p[2], 3.0);
  const Vec3 q = frame.ToFrame(p);
  EXPECT_NEAR(q[0], 1.0, 1e-12);
  EXPECT_NEAR(q[1], 2.0, 1e-12);
  EXPECT_NEAR(q[2], 3.0, 1e-12);

  const auto                       grid = frame.FieldGridOf(fixed);
  itk::morea::ImageType::IndexType index{ { 3, 5, 7 } };
  PointType                        expected;
  fixed->TransformIndexToPhysicalPoint(index, expected);
  EXPECT_LT(Distance(frame.ToPhysical(grid.PointAt(3, 5, 7)), expected), 1e-9);

  DomainFrame::DirectionType sheared = RotationAboutZ();
  sheared[0][2] = 0.3;
  EXPECT_THROW(DomainFrame{ sheared }, itk::ExceptionObject);
}

TEST_F(MeshTransforms, VolumeConversionsKeepGeometry)
{
  morea_core::Volume<float> volume({ 6, 5, 4 }, { 1.5, 1.0, 2.5 }, { 10.0, -4.0, 7.0 });
  for (std::size_t i = 0; i < volume.data.size(); ++i)
    volume.data[i] = static_cast<float>(i) * 0.5f;
  const auto                       image = itk::morea::ToImage(volume, frame);
  itk::morea::ImageType::IndexType index{ { 4, 1, 3 } };
  PointType                        p;
  image->TransformIndexToPhysicalPoint(index, p);
  EXPECT_LT(Distance(p, frame.ToPhysical(volume.PointAt(4, 1, 3))), 1e-9);
  EXPECT_EQ(image->GetPixel(index), volume(4, 1, 3));
  const auto back = itk::morea::ToVolume(image, frame);
  EXPECT_EQ(back.size, volume.size);
  EXPECT_EQ(back.data, volume.data);
  for (int a = 0; a < 3; ++a)
  {
    EXPECT_NEAR(back.origin[a], volume.origin[a], 1e-12);
    EXPECT_EQ(back.spacing[a], volume.spacing[a]);
  }

  morea_core::Volume<std::uint8_t> mask = volume.Like<std::uint8_t>(0);
  mask(2, 2, 2) = 1;
  const auto maskImage = itk::morea::ToMask(mask, frame);
  EXPECT_EQ(itk::morea::ToVolume(maskImage, frame).data, mask.data);
  EXPECT_THROW(itk::morea::ToVolume(maskImage, DomainFrame()), itk::ExceptionObject) << "not aligned";
}

TEST_F(MeshTransforms, AffineTargetMapsPhysicalPoints)
{
  morea_core::DualMesh solution;
  solution.source = box.points;
  for (const auto & q : box.points)
    solution.target.push_back(AffineImage(q));
  const auto fields = itk::morea::RasterizeSolution(topology, solution, fixed, moving);
  EXPECT_TRUE(itk::morea::SameGrid(fields.fixedToMoving, fixed, 1e-9));
  EXPECT_TRUE(itk::morea::SameGrid(fields.movingToFixed, moving, 1e-9));
  EXPECT_EQ(fields.fixedReport.voxels, fixed->GetLargestPossibleRegion().GetNumberOfPixels());

  // Expected maps in physical space: fixed p -> D A^-1 (D^T p - b), moving y -> D (A D^T y + b).
  auto expectedMoving = [&](const PointType & p) { return frame.ToPhysical(InverseAffineImage(frame.ToFrame(p))); };
  auto expectedFixed = [&](const PointType & y) { return frame.ToPhysical(AffineImage(frame.ToFrame(y))); };

  std::vector<PointType> samples = FixedVoxelCentres();
  std::mt19937           random(5);
  const auto             size = fixed->GetLargestPossibleRegion().GetSize();
  for (int n = 0; n < 500; ++n)
  {
    itk::ContinuousIndex<double, 3> index;
    for (int a = 0; a < 3; ++a)
      index[a] = std::uniform_real_distribution<double>(0.0, double(size[a] - 1))(random);
    PointType p;
    fixed->TransformContinuousIndexToPhysicalPoint(index, p);
    samples.push_back(p);
  }
  const auto inverse = fields.fixedToMovingTransform->GetInverseTransform();
  ASSERT_NE(inverse, nullptr);
  double worstForward = 0.0, worstBackward = 0.0, worstInverse = 0.0;
  for (const auto & p : samples)
  {
    worstForward =
      std::max(worstForward, Distance(fields.fixedToMovingTransform->TransformPoint(p), expectedMoving(p)));
    // Fixed-grid points lie inside the moving grid too.
    worstBackward =
      std::max(worstBackward, Distance(fields.movingToFixedTransform->TransformPoint(p), expectedFixed(p)));
    worstInverse = std::max(worstInverse, Distance(inverse->TransformPoint(p), expectedFixed(p)));
  }
  EXPECT_LT(worstForward, 1e-3);
  EXPECT_LT(worstBackward, 1e-3);
  EXPECT_LT(worstInverse, 1e-3);

  // The field holds physical vectors: a step along grid axis 0 is along +y.
  itk::morea::DisplacementFieldType::IndexType index{ { 4, 6, 8 } };
  PointType                                    p;
  fixed->TransformIndexToPhysicalPoint(index, p);
  const auto u = fields.fixedToMoving->GetPixel(index);
  const auto expected = expectedMoving(p) - p;
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(u[a], expected[a], 1e-6);
}

TEST_F(MeshTransforms, ComposedDirectionsAreTheIdentity)
{
  // Gentle relative to the ~17-voxel cells: linear interpolation of the second
  // field misses the kinks between tetrahedra by about (gradient jump) x voxel,
  // while a wrong frame, vector or grid would cost about the displacement itself.
  const auto                coarse = morea_test::MakeBoxMesh(box.domain, { 2, 2, 2 });
  const morea_core::MeshTopology coarseTopology(coarse.tetrahedra, coarse.points.size());
  morea_core::DualMesh           solution;
  solution.source = morea_test::Perturb(coarse, 0.05, 13);
  solution.target = coarse.points;
  ASSERT_GT(morea_test::MinimumSignedVolume(coarse.tetrahedra, solution.source), 0.0);
  const auto fields = itk::morea::RasterizeSolution(coarseTopology, solution, fixed, moving);
  EXPECT_EQ(fields.fixedReport.outsideMesh, 0u);

  const auto   inverse = fields.fixedToMovingTransform->GetInverseTransform();
  const double voxel = std::min({ fixed->GetSpacing()[0], fixed->GetSpacing()[1], fixed->GetSpacing()[2] });
  double       worst = 0.0, worstInverse = 0.0, largest = 0.0;
  for (const auto & p : FixedVoxelCentres())
  {
    const PointType y = fields.fixedToMovingTransform->TransformPoint(p);
    largest = std::max(largest, Distance(y, p));
    worst = std::max(worst, Distance(fields.movingToFixedTransform->TransformPoint(y), p));
    worstInverse = std::max(worstInverse, Distance(inverse->TransformPoint(y), p));
  }
  EXPECT_GT(largest, 0.5 * voxel);
  EXPECT_LT(worst, 0.1 * voxel);
  EXPECT_LT(worstInverse, 0.1 * voxel);
}

TEST_F(MeshTransforms, GridsMustShareTheirDirection)
{
  auto turned = itk::morea::ImageType::New();
  turned->CopyInformation(moving);
  turned->SetRegions(moving->GetLargestPossibleRegion());
  DomainFrame::DirectionType identity;
  identity.SetIdentity();
  turned->SetDirection(identity);
  EXPECT_THROW(itk::morea::RasterizeSolution(topology, morea_core::DualMesh{ box.points, box.points }, fixed, turned),
               itk::ExceptionObject);
}

TEST_F(MeshTransforms, VtuPointsAreInPhysicalSpace)
{
  const fs::path folder = fs::path(MOREA_TEST_OUTPUT_DIR) / "mesh_transforms";
  fs::remove_all(folder);
  const fs::path  path = folder / "target.vtu";
  morea_core::VtuArray volume{ "volume", {} };
  for (const auto & t : box.tetrahedra)
    volume.values.push_back(morea_core::SignedVolume(t, box.points));

  // A reflection too: the cells must stay positively oriented in physical space.
  DomainFrame::DirectionType mirrored = RotationAboutZ();
  mirrored[2][2] = -1.0;
  for (const DomainFrame & f : { frame, DomainFrame(mirrored) })
  {
    itk::morea::WriteMeshVtu(path.string(), topology, box.points, f, { volume });
    auto reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
    reader->SetFileName(path.string().c_str());
    reader->Update();
    vtkUnstructuredGrid * grid = reader->GetOutput();
    ASSERT_EQ(grid->GetNumberOfPoints(), static_cast<vtkIdType>(box.points.size()));
    ASSERT_EQ(grid->GetNumberOfCells(), static_cast<vtkIdType>(box.tetrahedra.size()));
    std::vector<Vec3> physical(box.points.size());
    for (std::size_t i = 0; i < box.points.size(); ++i)
    {
      grid->GetPoint(static_cast<vtkIdType>(i), physical[i].data());
      const PointType expected = f.ToPhysical(box.points[i]);
      for (int a = 0; a < 3; ++a)
        EXPECT_NEAR(physical[i][a], expected[a], 1e-9);
    }
    auto ids = vtkSmartPointer<vtkIdList>::New();
    for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c)
    {
      grid->GetCellPoints(c, ids);
      const morea_core::Tetrahedron t{ { static_cast<std::uint32_t>(ids->GetId(0)),
                                    static_cast<std::uint32_t>(ids->GetId(1)),
                                    static_cast<std::uint32_t>(ids->GetId(2)),
                                    static_cast<std::uint32_t>(ids->GetId(3)) } };
      EXPECT_NEAR(morea_core::SignedVolume(t, physical), volume.values[c], 1e-9);
    }
    vtkDataArray * read = grid->GetCellData()->GetArray("volume");
    ASSERT_NE(read, nullptr);
    EXPECT_EQ(read->GetTuple1(0), volume.values[0]);
  }
}
