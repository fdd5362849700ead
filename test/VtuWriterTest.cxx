// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/VtuWriter.h"

#include "morea_core/Error.h"

#include "BoxMesh.h"

#include <gtest/gtest.h>

#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace
{
fs::path
OutputFolder(const std::string & name)
{
  const fs::path folder = fs::path(MOREA_TEST_OUTPUT_DIR) / "vtu" / name;
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

std::size_t
FilesIn(const fs::path & folder)
{
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(folder), fs::directory_iterator{}));
}

vtkSmartPointer<vtkUnstructuredGrid>
ReadVtu(const fs::path & path)
{
  auto reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
  reader->SetFileName(path.string().c_str());
  reader->Update();
  return reader->GetOutput();
}

morea_test::BoxMesh
SmallMesh()
{
  morea_core::MeshDomain domain;
  domain.lower = { { -1.5, 2.0, 10.0 } };
  domain.upper = { { 4.5, 6.0, 13.0 } };
  return morea_test::MakeBoxMesh(domain, { 2, 1, 1 });
}
} // namespace

TEST(VtuWriter, RoundTripKeepsPointsCellsAndData)
{
  const auto     mesh = SmallMesh();
  const fs::path folder = OutputFolder("round_trip");
  const fs::path path = folder / "mesh.vtu";

  morea_core::VtuArray volume{ "volume", {} };
  morea_core::VtuArray label{ "label", {} };
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
  {
    volume.values.push_back(morea_core::SignedVolume(mesh.tetrahedra[t], mesh.points));
    label.values.push_back(0.5 * static_cast<double>(t) - 1.0);
  }
  morea_core::VtuArray height{ "height", {} };
  for (const auto & p : mesh.points)
    height.values.push_back(p[2] * 1.25);
  morea_core::WriteVtu(path.string(), mesh.points, mesh.tetrahedra, { volume, label }, { height });
  EXPECT_EQ(FilesIn(folder), 1u) << "the temporary file must be gone";

  const auto grid = ReadVtu(path);
  ASSERT_NE(grid, nullptr);
  ASSERT_EQ(grid->GetNumberOfPoints(), static_cast<vtkIdType>(mesh.points.size()));
  ASSERT_EQ(grid->GetNumberOfCells(), static_cast<vtkIdType>(mesh.tetrahedra.size()));
  for (std::size_t p = 0; p < mesh.points.size(); ++p)
  {
    double x[3];
    grid->GetPoint(static_cast<vtkIdType>(p), x);
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(x[a], mesh.points[p][a]);
  }
  auto ids = vtkSmartPointer<vtkIdList>::New();
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
  {
    EXPECT_EQ(grid->GetCellType(static_cast<vtkIdType>(t)), VTK_TETRA);
    grid->GetCellPoints(static_cast<vtkIdType>(t), ids);
    ASSERT_EQ(ids->GetNumberOfIds(), 4);
    for (int v = 0; v < 4; ++v)
      EXPECT_EQ(ids->GetId(v), static_cast<vtkIdType>(mesh.tetrahedra[t][v]));
  }
  for (const auto * expected : { &volume, &label })
  {
    vtkDataArray * array = grid->GetCellData()->GetArray(expected->name.c_str());
    ASSERT_NE(array, nullptr) << expected->name;
    ASSERT_EQ(array->GetNumberOfTuples(), static_cast<vtkIdType>(expected->values.size()));
    for (std::size_t t = 0; t < expected->values.size(); ++t)
      EXPECT_EQ(array->GetTuple1(static_cast<vtkIdType>(t)), expected->values[t]);
  }
  vtkDataArray * pointArray = grid->GetPointData()->GetArray("height");
  ASSERT_NE(pointArray, nullptr);
  for (std::size_t p = 0; p < mesh.points.size(); ++p)
    EXPECT_EQ(pointArray->GetTuple1(static_cast<vtkIdType>(p)), height.values[p]);

  // The file is binary and compressed, as announced.
  std::ifstream     in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("vtkZLibDataCompressor"), std::string::npos);
}

TEST(VtuWriter, UnwritablePathThrowsAndLeavesNoFile)
{
  const auto     mesh = SmallMesh();
  const fs::path folder = OutputFolder("unwritable");
  // A regular file where the parent folder should be.
  const fs::path blocker = folder / "not_a_folder";
  std::ofstream(blocker) << "x";
  const fs::path underFile = blocker / "mesh.vtu";
  EXPECT_THROW(morea_core::WriteVtu(underFile.string(), mesh.points, mesh.tetrahedra, {}), morea_core::Error);
  EXPECT_FALSE(fs::exists(underFile));
  // A folder where the file should be: the rename fails, the temporary goes.
  const fs::path occupied = folder / "occupied.vtu";
  fs::create_directory(occupied);
  fs::create_directory(occupied / "keep");
  EXPECT_THROW(morea_core::WriteVtu(occupied.string(), mesh.points, mesh.tetrahedra, {}), morea_core::Error);
  EXPECT_TRUE(fs::is_directory(occupied));
  EXPECT_EQ(FilesIn(folder), 2u) << "only the blocker file and the occupied folder may remain";
}

TEST(VtuWriter, BadSizesThrow)
{
  const auto     mesh = SmallMesh();
  const fs::path folder = OutputFolder("bad_sizes");
  const fs::path path = folder / "mesh.vtu";
  EXPECT_THROW(morea_core::WriteVtu(path.string(), mesh.points, mesh.tetrahedra, { { "short", { 1.0 } } }), morea_core::Error);
  EXPECT_THROW(morea_core::WriteVtu(
                 path.string(), mesh.points, mesh.tetrahedra, {}, { { "", std::vector<double>(mesh.points.size()) } }),
               morea_core::Error);
  auto badTetrahedra = mesh.tetrahedra;
  badTetrahedra[0][3] = static_cast<std::uint32_t>(mesh.points.size());
  EXPECT_THROW(morea_core::WriteVtu(path.string(), mesh.points, badTetrahedra, {}), morea_core::Error);
  EXPECT_EQ(FilesIn(folder), 0u);
}
