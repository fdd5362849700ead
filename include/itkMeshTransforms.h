// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: the core's mesh solutions as ITK displacement
 *  fields and transforms, and mesh export in physical space.
 *
 *  The core works in the domain frame: millimetres along the image grid's
 *  axes. For an image direction D (orthonormal columns), a physical point p
 *  has frame coordinates q = D^T p, so the grid (origin o, spacing s) is the
 *  axis-aligned core volume with origin D^T o and spacing s. With an identity
 *  direction the frame is physical space.
 *=========================================================================*/
#ifndef itkMeshTransforms_h
#define itkMeshTransforms_h

#include "itkCompositeTransform.h"
#include "itkDisplacementFieldTransform.h"
#include "itkMOREATypes.h"
#include "itkRigidPreAlignment.h"
#include "morea_core/FieldFoldRepair.h"
#include "morea_core/MeshRasterizer.h"
#include "morea_core/TetrahedralMesh.h"
#include "morea_core/VtuWriter.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace itk
{
namespace morea
{
using DisplacementFieldTransformType = DisplacementFieldTransform<double, Dimension>;

/** The rotation between physical space and the core's domain frame. */
class DomainFrame
{
public:
  using DirectionType = ImageBase<Dimension>::DirectionType;

  /** Identity: frame == physical space. */
  DomainFrame();
  /** Throws unless `direction` is orthonormal (to 1e-6). */
  explicit DomainFrame(const DirectionType & direction);
  /** The frame of an image grid. */
  static DomainFrame
  Of(const ImageBase<Dimension> * grid);

  const DirectionType &
  GetDirection() const
  {
    return m_Direction;
  }
  /** Whether `grid`'s axes are the frame's axes (to `tolerance`). */
  bool
  IsAlignedWith(const ImageBase<Dimension> * grid, double tolerance = 1e-6) const;

  morea_core::Vec3
  ToFrame(const PointType & physical) const;
  PointType
  ToPhysical(const morea_core::Vec3 & frame) const;
  /** Displacements: the same rotation (the frame shares physical space's origin). */
  morea_core::Vec3
  VectorToFrame(const DisplacementVectorType & physical) const;
  DisplacementVectorType
  VectorToPhysical(const morea_core::Vec3 & frame) const;

  /** The grid of `grid` (its largest possible region) in this frame: voxels
   *  per axis, spacing, and the first voxel's centre. Throws unless the grid
   *  is aligned with the frame. */
  struct GridGeometry
  {
    std::array<std::size_t, 3> size{ { 0, 0, 0 } };
    morea_core::Vec3              spacing{ { 1.0, 1.0, 1.0 } };
    morea_core::Vec3              origin{ { 0.0, 0.0, 0.0 } };
  };
  GridGeometry
  GeometryOf(const ImageBase<Dimension> * grid) const;

  /** The same grid as an axis-aligned core displacement volume, filled with
   *  zeros. */
  morea_core::Volume<morea_core::Vec3>
  FieldGridOf(const ImageBase<Dimension> * grid) const;

private:
  DirectionType m_Direction;
};

/** Core volumes in `frame` to ITK images with full geometry (origin, spacing,
 *  direction), and back. The ITK images must be fully buffered and aligned with
 *  the frame. */
ImageType::Pointer
ToImage(const morea_core::Volume<float> & volume, const DomainFrame & frame);
MaskType::Pointer
ToMask(const morea_core::Volume<std::uint8_t> & volume, const DomainFrame & frame);
morea_core::Volume<float>
ToVolume(const ImageType * image, const DomainFrame & frame);
morea_core::Volume<std::uint8_t>
ToVolume(const MaskType * mask, const DomainFrame & frame);

/** A solution's registration as ITK fields and transforms (physical space). */
struct MeshFields
{
  /** u(x) on the fixed grid with x + u(x) the moving point matching fixed x. */
  DisplacementFieldType::Pointer fixedToMoving;
  /** u(y) on the moving grid with y + u(y) the fixed point matching moving y. */
  DisplacementFieldType::Pointer movingToFixed;
  /** Maps fixed points to moving points: the transform ITK resamples the moving
   *  image onto the fixed grid with. Its inverse field is set (on the fixed
   *  grid, as ITK requires), so GetInverseTransform() works. */
  DisplacementFieldTransformType::Pointer fixedToMovingTransform;
  /** Maps moving points to fixed points (fields on the moving grid). */
  DisplacementFieldTransformType::Pointer movingToFixedTransform;
  /** Rasterisation of fixedToMoving and movingToFixed (voxels outside the mesh). */
  morea_core::RasterizationReport fixedReport;
  morea_core::RasterizationReport movingReport;
  /** Voxel-level fold repair of fixedToMoving and movingToFixed (see
   *  morea_core/FieldFoldRepair.h): how many voxels were folded and changed. */
  morea_core::FieldFoldRepairReport fixedFoldRepair;
  morea_core::FieldFoldRepairReport movingFoldRepair;
};

/** Rasterises a solution: `solution.target` is the mesh on the fixed image and
 *  `solution.source` the mesh on the moving image, both in the domain frame of
 *  the grids, which must share their direction. When the grids differ, each
 *  transform's inverse field is rasterised once more on its forward field's
 *  grid (the piecewise-affine map is extrapolated outside the mesh). Every
 *  field is then made fold-free at voxel level (morea_core::RemoveVoxelFolds):
 *  the exact map is kept except around voxels whose finite-difference
 *  Jacobian determinant is <= 0. */
MeshFields
RasterizeSolution(const morea_core::MeshTopology & topology, const morea_core::DualMesh & solution,
                  const ImageBase<Dimension> * fixedGrid, const ImageBase<Dimension> * movingGrid);

/** The transforms of a chosen solution between the original images: the
 *  rigid pre-alignment composed with the solution's fields. */
using CompositeTransformType = CompositeTransform<double, Dimension>;
struct OriginalFrameTransforms
{
  /** Original fixed points -> original moving points, rigid(x + u(x)): the
   *  transform to resample the original moving image onto the original fixed
   *  grid with. Outside the preprocessed grid u is 0. */
  CompositeTransformType::Pointer fixedToMoving;
  /** Original moving points -> original fixed points, y' + v(y') with y' = rigid^-1(y). */
  CompositeTransformType::Pointer movingToFixed;
};

/** Composes `fields` with the pre-alignment `rigid` (null: none). The
 *  composites hold fresh field transforms (without inverse fields). */
OriginalFrameTransforms
MakeOriginalFrameTransforms(const MeshFields & fields, const PreAlignmentTransformType * rigid);

/** Writes the two transforms between the original images as ITK transform
 *  files (.h5 or .tfm; antsApplyTransforms, 3D Slicer and SimpleITK read
 *  them). Atomic; throws on failure. */
void
WriteSolutionTransforms(const OriginalFrameTransforms & transforms, const std::string & fixedToMovingPath,
                        const std::string & movingToFixedPath);

/** Writes a mesh given in `frame` coordinates as a .vtu in physical space
 *  (ParaView, 3D Slicer); atomic. Tetrahedra are reordered to stay positively
 *  oriented when the direction is a reflection. */
void
WriteMeshVtu(const std::string & path, const morea_core::MeshTopology & topology,
             const std::vector<morea_core::Vec3> & framePoints, const DomainFrame & frame,
             const std::vector<morea_core::VtuArray> & cellData, const std::vector<morea_core::VtuArray> & pointData = {});

} // namespace morea
} // namespace itk

#endif
