// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkMeshTransforms.h"
#include "itkCompositeTransform.h"

#include "itkMOREAImageIO.h"
#include "itkPhantomImages.h"
#include "itkRegistrationEvaluation.h"
#include "morea_core/Error.h"
#include "morea_core/ThreadPool.h"
#include "vnl/algo/vnl_determinant.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <future>
#include <utility>

namespace itk
{
namespace morea
{
namespace
{
/** A core volume with the geometry of `image` in `frame` and its voxels. */
template <typename TValue, typename TImage>
morea_core::Volume<TValue>
ToFrameVolume(const TImage * image, const DomainFrame & frame, const char * what)
{
  if (image == nullptr)
  {
    itkGenericExceptionMacro(<< "cannot convert a null " << what);
  }
  if (image->GetBufferedRegion() != image->GetLargestPossibleRegion())
  {
    itkGenericExceptionMacro(<< "cannot convert a partly buffered " << what);
  }
  const auto              geometry = frame.GeometryOf(image);
  morea_core::Volume<TValue> volume(geometry.size, geometry.spacing, geometry.origin);
  const auto *            buffer = image->GetBufferPointer();
  // ITK's buffer order is the core's: x fastest, then y, then z.
  for (std::size_t i = 0; i < volume.data.size(); ++i)
  {
    volume.data[i] = static_cast<TValue>(buffer[i]);
  }
  return volume;
}

template <typename TImage>
void
PlaceInFrame(TImage * image, const morea_core::Vec3 & frameOrigin, const DomainFrame & frame)
{
  image->SetOrigin(frame.ToPhysical(frameOrigin));
  image->SetDirection(frame.GetDirection());
}
} // namespace

DomainFrame::DomainFrame()
{
  m_Direction.SetIdentity();
}

DomainFrame::DomainFrame(const DirectionType & direction)
  : m_Direction(direction)
{
  // The frame map q = D^T p is only the inverse of p = D q for a rotation (or reflection).
  for (unsigned i = 0; i < Dimension; ++i)
  {
    for (unsigned j = 0; j < Dimension; ++j)
    {
      double dot = 0.0;
      for (unsigned r = 0; r < Dimension; ++r)
      {
        dot += direction[r][i] * direction[r][j];
      }
      if (std::abs(dot - (i == j ? 1.0 : 0.0)) > 1e-6)
      {
        itkGenericExceptionMacro(<< "the image direction is not orthonormal (sheared grids are not supported): "
                                 << direction);
      }
    }
  }
}

DomainFrame
DomainFrame::Of(const ImageBase<Dimension> * grid)
{
  if (grid == nullptr)
  {
    itkGenericExceptionMacro(<< "domain frame of a null image");
  }
  return DomainFrame(grid->GetDirection());
}

bool
DomainFrame::IsAlignedWith(const ImageBase<Dimension> * grid, double tolerance) const
{
  for (unsigned i = 0; i < Dimension; ++i)
  {
    for (unsigned j = 0; j < Dimension; ++j)
    {
      if (std::abs(grid->GetDirection()[i][j] - m_Direction[i][j]) > tolerance)
      {
        return false;
      }
    }
  }
  return true;
}

morea_core::Vec3
DomainFrame::ToFrame(const PointType & physical) const
{
  morea_core::Vec3 q{ { 0.0, 0.0, 0.0 } };
  for (unsigned r = 0; r < Dimension; ++r)
  {
    for (unsigned c = 0; c < Dimension; ++c)
    {
      q[r] += m_Direction[c][r] * physical[c];
    }
  }
  return q;
}

PointType
DomainFrame::ToPhysical(const morea_core::Vec3 & frame) const
{
  PointType p;
  for (unsigned r = 0; r < Dimension; ++r)
  {
    p[r] = m_Direction[r][0] * frame[0] + m_Direction[r][1] * frame[1] + m_Direction[r][2] * frame[2];
  }
  return p;
}

morea_core::Vec3
DomainFrame::VectorToFrame(const DisplacementVectorType & physical) const
{
  PointType p;
  for (unsigned d = 0; d < Dimension; ++d)
  {
    p[d] = physical[d];
  }
  return ToFrame(p);
}

DisplacementVectorType
DomainFrame::VectorToPhysical(const morea_core::Vec3 & frame) const
{
  DisplacementVectorType v;
  for (unsigned r = 0; r < Dimension; ++r)
  {
    v[r] = m_Direction[r][0] * frame[0] + m_Direction[r][1] * frame[1] + m_Direction[r][2] * frame[2];
  }
  return v;
}

DomainFrame::GridGeometry
DomainFrame::GeometryOf(const ImageBase<Dimension> * grid) const
{
  if (grid == nullptr)
  {
    itkGenericExceptionMacro(<< "grid of a null image");
  }
  if (!IsAlignedWith(grid))
  {
    itkGenericExceptionMacro(<< "the image grid's direction " << grid->GetDirection() << " is not the domain frame's "
                             << m_Direction);
  }
  const auto   region = grid->GetLargestPossibleRegion();
  GridGeometry geometry;
  for (unsigned d = 0; d < Dimension; ++d)
  {
    geometry.size[d] = region.GetSize()[d];
    geometry.spacing[d] = grid->GetSpacing()[d];
  }
  // The region may start at a non-zero index: the core's first voxel is that one.
  PointType first;
  grid->TransformIndexToPhysicalPoint(region.GetIndex(), first);
  geometry.origin = ToFrame(first);
  return geometry;
}

morea_core::Volume<morea_core::Vec3>
DomainFrame::FieldGridOf(const ImageBase<Dimension> * grid) const
{
  const GridGeometry geometry = GeometryOf(grid);
  return morea_core::Volume<morea_core::Vec3>(geometry.size, geometry.spacing, geometry.origin);
}

ImageType::Pointer
ToImage(const morea_core::Volume<float> & volume, const DomainFrame & frame)
{
  ImageType::Pointer image = ToImage(volume);
  PlaceInFrame(image.GetPointer(), volume.origin, frame);
  return image;
}

MaskType::Pointer
ToMask(const morea_core::Volume<std::uint8_t> & volume, const DomainFrame & frame)
{
  MaskType::Pointer mask = ToMask(volume);
  PlaceInFrame(mask.GetPointer(), volume.origin, frame);
  return mask;
}

morea_core::Volume<float>
ToVolume(const ImageType * image, const DomainFrame & frame)
{
  return ToFrameVolume<float>(image, frame, "image");
}

morea_core::Volume<std::uint8_t>
ToVolume(const MaskType * mask, const DomainFrame & frame)
{
  return ToFrameVolume<std::uint8_t>(mask, frame, "mask");
}

MeshFields
RasterizeSolution(const morea_core::MeshTopology & topology, const morea_core::DualMesh & solution,
                  const ImageBase<Dimension> * fixedGrid, const ImageBase<Dimension> * movingGrid)
{
  if (fixedGrid == nullptr || movingGrid == nullptr)
  {
    itkGenericExceptionMacro(<< "rasterising a solution needs both the fixed and the moving image grid");
  }
  const DomainFrame frame = DomainFrame::Of(fixedGrid);
  if (!frame.IsAlignedWith(movingGrid))
  {
    itkGenericExceptionMacro(<< "the fixed and moving images must share their direction (one domain frame); "
                             << "fixed: " << fixedGrid->GetDirection() << " moving: " << movingGrid->GetDirection());
  }

  // The map `from` -> `to` sampled on a grid's volume (plain C++, no ITK
  // objects made, so that both directions can run at once: the voxel fold
  // repair takes a good part of a second on a folded field, and each
  // direction's repair gets half of the cores).
  struct Rasterized
  {
    morea_core::Volume<morea_core::Vec3>  volume;
    morea_core::RasterizationReport    report;
    morea_core::FieldFoldRepairReport repair;
  };
  auto rasterizeVolume = [&topology](const std::vector<morea_core::Vec3> & from, const std::vector<morea_core::Vec3> & to,
                                     morea_core::Volume<morea_core::Vec3> volume) {
    Rasterized r{ std::move(volume), {}, {} };
    morea_core::RasterizeDisplacement(topology, from, to, r.volume, &r.report);
    morea_core::FieldFoldRepairOptions repairOptions;
    repairOptions.threads = std::max<std::size_t>(1, morea_core::HostThreads() / 2);
    r.repair = morea_core::RemoveVoxelFolds(r.volume, repairOptions,
                                            r.report.outsideMask.empty() ? nullptr : &r.report.outsideMask);
    r.report.outsideMask = {}; // only needed to split the repair's report
    return r;
  };
  // ... and as a physical displacement field on the grid's full geometry.
  auto toField = [&frame](const Rasterized & r, const ImageBase<Dimension> * grid) {
    DisplacementFieldType::Pointer field = MakeIdentityField(grid);
    DisplacementVectorType *       buffer = field->GetBufferPointer();
    for (std::size_t i = 0; i < r.volume.data.size(); ++i)
    {
      buffer[i] = frame.VectorToPhysical(r.volume.data[i]);
    }
    return field;
  };
  auto rasterize = [&](const std::vector<morea_core::Vec3> & from, const std::vector<morea_core::Vec3> & to,
                       const ImageBase<Dimension> * grid) {
    try
    {
      return toField(rasterizeVolume(from, to, frame.FieldGridOf(grid)), grid);
    }
    catch (const morea_core::Error & e)
    {
      itkGenericExceptionMacro(<< e.what());
    }
  };

  MeshFields fields;
  {
    Rasterized forward, backward;
    try
    {
      auto later = std::async(std::launch::async, rasterizeVolume, std::cref(solution.source),
                              std::cref(solution.target), frame.FieldGridOf(movingGrid));
      forward = rasterizeVolume(solution.target, solution.source, frame.FieldGridOf(fixedGrid));
      backward = later.get();
    }
    catch (const morea_core::Error & e)
    {
      itkGenericExceptionMacro(<< e.what());
    }
    fields.fixedToMoving = toField(forward, fixedGrid);
    fields.fixedReport = forward.report;
    fields.fixedFoldRepair = forward.repair;
    fields.movingToFixed = toField(backward, movingGrid);
    fields.movingReport = backward.report;
    fields.movingFoldRepair = backward.repair;
  }

  // ITK wants a transform's inverse field on its forward field's grid.
  const bool                     sameGrid = SameGrid(fixedGrid, movingGrid, 1e-9);
  DisplacementFieldType::Pointer movingToFixedOnFixedGrid =
    sameGrid ? fields.movingToFixed : rasterize(solution.source, solution.target, fixedGrid);
  DisplacementFieldType::Pointer fixedToMovingOnMovingGrid =
    sameGrid ? fields.fixedToMoving : rasterize(solution.target, solution.source, movingGrid);

  fields.fixedToMovingTransform = DisplacementFieldTransformType::New();
  fields.fixedToMovingTransform->SetDisplacementField(fields.fixedToMoving);
  fields.fixedToMovingTransform->SetInverseDisplacementField(movingToFixedOnFixedGrid);
  fields.movingToFixedTransform = DisplacementFieldTransformType::New();
  fields.movingToFixedTransform->SetDisplacementField(fields.movingToFixed);
  fields.movingToFixedTransform->SetInverseDisplacementField(fixedToMovingOnMovingGrid);
  return fields;
}

void
WriteMeshVtu(const std::string & path, const morea_core::MeshTopology & topology,
             const std::vector<morea_core::Vec3> & framePoints, const DomainFrame & frame,
             const std::vector<morea_core::VtuArray> & cellData, const std::vector<morea_core::VtuArray> & pointData)
{
  if (framePoints.size() != topology.NumberOfPoints())
  {
    itkGenericExceptionMacro(<< "cannot write '" << path << "': the topology has " << topology.NumberOfPoints()
                             << " points but " << framePoints.size() << " were given");
  }
  std::vector<morea_core::Vec3> physical;
  physical.reserve(framePoints.size());
  for (const auto & q : framePoints)
  {
    const PointType p = frame.ToPhysical(q);
    physical.push_back({ { p[0], p[1], p[2] } });
  }
  // A reflection flips every tetrahedron's orientation; one swap flips it back.
  std::vector<morea_core::Tetrahedron> tetrahedra = topology.Tetrahedra();
  if (vnl_determinant(frame.GetDirection().GetVnlMatrix()) < 0.0)
  {
    for (auto & t : tetrahedra)
    {
      std::swap(t[2], t[3]);
    }
  }
  try
  {
    morea_core::WriteVtu(path, physical, tetrahedra, cellData, pointData);
  }
  catch (const morea_core::Error & e)
  {
    itkGenericExceptionMacro(<< e.what());
  }
}

OriginalFrameTransforms
MakeOriginalFrameTransforms(const MeshFields & fields, const PreAlignmentTransformType * rigid)
{
  // CompositeTransform applies the transform added last first.
  OriginalFrameTransforms out{ CompositeTransformType::New(), CompositeTransformType::New() };
  // Fresh transforms without inverse fields: files hold one field each.
  auto u = DisplacementFieldTransformType::New();
  u->SetDisplacementField(fields.fixedToMoving);
  auto v = DisplacementFieldTransformType::New();
  v->SetDisplacementField(fields.movingToFixed);
  if (rigid)
  {
    out.fixedToMoving->AddTransform(rigid->Clone());
  }
  out.fixedToMoving->AddTransform(u);
  out.movingToFixed->AddTransform(v);
  if (rigid)
  {
    const auto inverse = rigid->GetInverseTransform();
    if (!inverse)
      itkGenericExceptionMacro("the pre-alignment is not invertible");
    out.movingToFixed->AddTransform(inverse);
  }
  return out;
}

void
WriteSolutionTransforms(const OriginalFrameTransforms & transforms, const std::string & fixedToMovingPath,
                        const std::string & movingToFixedPath)
{
  for (const auto & [transform, path] : { std::make_pair(transforms.fixedToMoving, fixedToMovingPath),
                                          std::make_pair(transforms.movingToFixed, movingToFixedPath) })
  {
    WriteTransformFile(transform, path);
  }
}

} // namespace morea
} // namespace itk
