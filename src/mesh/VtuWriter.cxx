// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/VtuWriter.h"

#include "morea_core/Error.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <unistd.h>

namespace fs = std::filesystem;

namespace morea_core
{
namespace
{
void
CheckArrays(const std::vector<VtuArray> & arrays, std::size_t expected, const std::string & what,
            const std::string & path)
{
  for (const VtuArray & a : arrays)
  {
    if (a.name.empty())
    {
      throw Error("cannot write '" + path + "': a " + what + " data array has no name");
    }
    if (a.values.size() != expected)
    {
      throw Error("cannot write '" + path + "': " + what + " data '" + a.name + "' has " +
                  std::to_string(a.values.size()) + " values for " + std::to_string(expected) + " " + what + "s");
    }
  }
}

void
AddArrays(const std::vector<VtuArray> & arrays, vtkDataSetAttributes * attributes)
{
  for (const VtuArray & a : arrays)
  {
    vtkNew<vtkDoubleArray> array;
    array->SetName(a.name.c_str());
    array->SetNumberOfValues(static_cast<vtkIdType>(a.values.size()));
    for (std::size_t i = 0; i < a.values.size(); ++i)
    {
      array->SetValue(static_cast<vtkIdType>(i), a.values[i]);
    }
    attributes->AddArray(array);
  }
}

vtkSmartPointer<vtkUnstructuredGrid>
MakeGrid(const std::vector<Vec3> & points, const std::vector<Tetrahedron> & tetrahedra)
{
  vtkNew<vtkPoints> vtkPointSet;
  vtkPointSet->SetDataTypeToDouble();
  vtkPointSet->SetNumberOfPoints(static_cast<vtkIdType>(points.size()));
  for (std::size_t p = 0; p < points.size(); ++p)
  {
    vtkPointSet->SetPoint(static_cast<vtkIdType>(p), points[p].data());
  }
  vtkNew<vtkCellArray> cells;
  cells->AllocateExact(static_cast<vtkIdType>(tetrahedra.size()), static_cast<vtkIdType>(4 * tetrahedra.size()));
  for (const Tetrahedron & t : tetrahedra)
  {
    const vtkIdType ids[4] = { t[0], t[1], t[2], t[3] };
    cells->InsertNextCell(4, ids);
  }
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  grid->SetPoints(vtkPointSet);
  grid->SetCells(VTK_TETRA, cells);
  return grid;
}

/** Why the VTK writer failed. Below FirstVTKErrorCode the code is the errno of
 *  the failing system call. (vtkErrorCode's string table lives in a VTK module
 *  this library does not link.) */
std::string
WriterFailure(unsigned long code)
{
  if (code > 0 && code < vtkErrorCode::FirstVTKErrorCode)
  {
    return std::strerror(static_cast<int>(code));
  }
  if (code == vtkErrorCode::OutOfDiskSpaceError)
  {
    return "out of disk space";
  }
  return "the VTK writer failed (VTK error code " + std::to_string(code) + ")";
}

/** A fresh name beside `path` (same folder, so the final rename is atomic). */
fs::path
TemporaryPathFor(const fs::path & path)
{
  static std::atomic<unsigned> counter{ 0 };
  const std::string            name = "." + path.stem().string() + ".tmp" + std::to_string(::getpid()) + "_" +
                           std::to_string(counter++) + path.extension().string();
  return path.parent_path() / name;
}
} // namespace

void
WriteVtu(const std::string & path, const std::vector<Vec3> & points, const std::vector<Tetrahedron> & tetrahedra,
         const std::vector<VtuArray> & cellData, const std::vector<VtuArray> & pointData)
{
  for (const Tetrahedron & t : tetrahedra)
  {
    for (std::uint32_t v : t)
    {
      if (v >= points.size())
      {
        throw Error("cannot write '" + path + "': a tetrahedron refers to point " + std::to_string(v) + " of " +
                    std::to_string(points.size()));
      }
    }
  }
  CheckArrays(cellData, tetrahedra.size(), "cell", path);
  CheckArrays(pointData, points.size(), "point", path);

  const fs::path  target(path);
  std::error_code ec;
  if (!target.parent_path().empty())
  {
    fs::create_directories(target.parent_path(), ec);
    if (ec)
    {
      throw Error("cannot write '" + path + "': cannot create folder '" + target.parent_path().string() +
                  "': " + ec.message());
    }
  }

  vtkSmartPointer<vtkUnstructuredGrid> grid = MakeGrid(points, tetrahedra);
  AddArrays(cellData, grid->GetCellData());
  AddArrays(pointData, grid->GetPointData());

  const fs::path                       temporary = TemporaryPathFor(target);
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetInputData(grid);
  writer->SetFileName(temporary.string().c_str());
  writer->SetDataModeToBinary();
  writer->SetCompressorTypeToZLib();
  if (writer->Write() != 1 || writer->GetErrorCode() != vtkErrorCode::NoError)
  {
    const std::string reason = WriterFailure(writer->GetErrorCode());
    fs::remove(temporary, ec);
    throw Error("cannot write '" + path + "': " + reason);
  }
  fs::rename(temporary, target, ec);
  if (ec)
  {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw Error("cannot write '" + path + "': cannot move the temporary file into place: " + ec.message());
  }
}
} // namespace morea_core
