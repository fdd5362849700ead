// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/StructureSurface.h"

#include <vtkCellArray.h>
#include <vtkCleanPolyData.h>
#include <vtkFloatArray.h>
#include <vtkIdList.h>
#include <vtkImageData.h>
#include <vtkMarchingCubes.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkQuadricDecimation.h>
#include <vtkTriangleFilter.h>

#include <algorithm>
#include <cmath>

namespace morea_core
{
namespace
{
/** The mask as 0/1 floats with one empty voxel of padding on every side (so
 *  the surface closes), blurred by a Gaussian of one voxel. */
vtkNew<vtkImageData>
BlurredPaddedMask(const Volume<std::uint8_t> & mask)
{
  const std::array<std::size_t, 3> n{ { mask.size[0] + 2, mask.size[1] + 2, mask.size[2] + 2 } };
  std::vector<float> a(n[0] * n[1] * n[2], 0.0f);
  for (std::size_t k = 0; k < mask.size[2]; ++k)
    for (std::size_t j = 0; j < mask.size[1]; ++j)
      for (std::size_t i = 0; i < mask.size[0]; ++i)
        if (mask(i, j, k) != 0)
          a[(i + 1) + n[0] * ((j + 1) + n[1] * (k + 1))] = 1.0f;

  // Separable blur, kernel truncated at 2 sigma.
  const float kernel[5] = { 0.054f, 0.242f, 0.399f, 0.242f, 0.054f };
  const std::size_t stride[3] = { 1, n[0], n[0] * n[1] };
  std::vector<float> b(a.size());
  for (int axis = 0; axis < 3; ++axis)
  {
    for (std::size_t k = 0; k < n[2]; ++k)
      for (std::size_t j = 0; j < n[1]; ++j)
        for (std::size_t i = 0; i < n[0]; ++i)
        {
          const std::size_t idx[3] = { i, j, k };
          const std::size_t o = i + n[0] * (j + n[1] * k);
          float             sum = 0.0f, weight = 0.0f;
          for (int d = -2; d <= 2; ++d)
          {
            const long long c = static_cast<long long>(idx[axis]) + d;
            if (c < 0 || c >= static_cast<long long>(n[axis]))
              continue;
            sum += kernel[d + 2] *
                   a[static_cast<std::size_t>(static_cast<long long>(o) + static_cast<long long>(stride[axis]) * d)];
            weight += kernel[d + 2];
          }
          b[o] = sum / weight;
        }
    a.swap(b);
  }

  vtkNew<vtkImageData> image;
  image->SetDimensions(static_cast<int>(n[0]), static_cast<int>(n[1]), static_cast<int>(n[2]));
  image->SetSpacing(mask.spacing[0], mask.spacing[1], mask.spacing[2]);
  image->SetOrigin(mask.origin[0] - mask.spacing[0], mask.origin[1] - mask.spacing[1],
                   mask.origin[2] - mask.spacing[2]);
  vtkNew<vtkFloatArray> scalars;
  scalars->SetNumberOfTuples(static_cast<vtkIdType>(a.size()));
  std::copy(a.begin(), a.end(), scalars->GetPointer(0));
  image->GetPointData()->SetScalars(scalars);
  return image;
}
} // namespace

TriangleSurface
ExtractStructureSurface(const Volume<std::uint8_t> & mask, std::size_t targetVertices)
{
  TriangleSurface surface;
  if (std::none_of(mask.data.begin(), mask.data.end(), [](std::uint8_t v) { return v != 0; }))
  {
    return surface;
  }
  vtkNew<vtkImageData> image = BlurredPaddedMask(mask);

  vtkNew<vtkMarchingCubes> cubes;
  cubes->SetInputData(image);
  cubes->SetValue(0, 0.5);
  cubes->ComputeNormalsOff();
  cubes->ComputeGradientsOff();
  cubes->ComputeScalarsOff();
  cubes->Update();

  vtkNew<vtkCleanPolyData> clean;
  clean->SetInputConnection(cubes->GetOutputPort());
  clean->Update();
  vtkPolyData * full = clean->GetOutput();

  vtkSmartPointer<vtkPolyData> result = full;
  const auto fullVertices = static_cast<std::size_t>(full->GetNumberOfPoints());
  if (targetVertices >= 4 && fullVertices > targetVertices)
  {
    vtkNew<vtkQuadricDecimation> decimate;
    decimate->SetInputData(full);
    decimate->SetTargetReduction(1.0 - static_cast<double>(targetVertices) / static_cast<double>(fullVertices));
    decimate->VolumePreservationOn();
    decimate->Update();
    vtkNew<vtkTriangleFilter> triangles;
    triangles->SetInputConnection(decimate->GetOutputPort());
    vtkNew<vtkCleanPolyData> cleanAgain;
    cleanAgain->SetInputConnection(triangles->GetOutputPort());
    cleanAgain->Update();
    result = cleanAgain->GetOutput();
  }

  // Only vertices used by a triangle, renumbered.
  const vtkIdType            nPoints = result->GetNumberOfPoints();
  std::vector<std::int64_t>  newIndex(static_cast<std::size_t>(nPoints), -1);
  vtkCellArray *             polys = result->GetPolys();
  vtkNew<vtkIdList>          ids;
  polys->InitTraversal();
  while (polys->GetNextCell(ids))
  {
    if (ids->GetNumberOfIds() != 3)
      continue;
    std::array<std::uint32_t, 3> tri{};
    for (int v = 0; v < 3; ++v)
    {
      const vtkIdType id = ids->GetId(v);
      if (newIndex[static_cast<std::size_t>(id)] < 0)
      {
        newIndex[static_cast<std::size_t>(id)] = static_cast<std::int64_t>(surface.vertices.size());
        double p[3];
        result->GetPoint(id, p);
        surface.vertices.push_back({ p[0], p[1], p[2] });
      }
      tri[v] = static_cast<std::uint32_t>(newIndex[static_cast<std::size_t>(id)]);
    }
    if (tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2])
      surface.triangles.push_back(tri);
  }
  return surface;
}
} // namespace morea_core
