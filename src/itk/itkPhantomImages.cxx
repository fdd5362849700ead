// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkPhantomImages.h"

#include "itkLandmarkIO.h"
#include "itkMOREAImageIO.h"

#include <algorithm>
#include <filesystem>

namespace fs = std::filesystem;

namespace itk
{
namespace morea
{
namespace
{
template <typename TImage, typename TValue, typename TConvert>
typename TImage::Pointer
Convert(const morea_core::Volume<TValue> & volume, TConvert convert)
{
  auto                          image = TImage::New();
  typename TImage::SizeType     size;
  typename TImage::SpacingType  spacing;
  typename TImage::PointType    origin;
  for (unsigned d = 0; d < Dimension; ++d)
  {
    size[d] = volume.size[d];
    spacing[d] = volume.spacing[d];
    origin[d] = volume.origin[d];
  }
  image->SetRegions(typename TImage::RegionType(size));
  image->SetSpacing(spacing);
  image->SetOrigin(origin);
  image->Allocate();
  auto * buffer = image->GetBufferPointer();
  // ITK's buffer order is the core's: x fastest, then y, then z.
  for (std::size_t i = 0; i < volume.data.size(); ++i)
    buffer[i] = convert(volume.data[i]);
  return image;
}

LandmarkListType
ToPoints(const std::vector<morea_core::Vec3> & points)
{
  LandmarkListType out;
  for (const auto & p : points)
  {
    PointType q;
    for (unsigned d = 0; d < Dimension; ++d)
      q[d] = p[d];
    out.push_back(q);
  }
  return out;
}
} // namespace

ImageType::Pointer
ToImage(const morea_core::Volume<float> & volume)
{
  return Convert<ImageType>(volume, [](float v) { return v; });
}

MaskType::Pointer
ToMask(const morea_core::Volume<std::uint8_t> & volume)
{
  return Convert<MaskType>(volume, [](std::uint8_t v) -> unsigned char { return v != 0 ? 1 : 0; });
}

DisplacementFieldType::Pointer
ToDisplacementField(const morea_core::Volume<morea_core::Vec3> & volume)
{
  return Convert<DisplacementFieldType>(volume, [](const morea_core::Vec3 & v) {
    DisplacementVectorType u;
    for (unsigned d = 0; d < Dimension; ++d)
      u[d] = v[d];
    return u;
  });
}

RegistrationProblem
MakePhantomProblem(const morea_core::PelvisPhantom::Case & c)
{
  RegistrationProblem problem;
  problem.fixedImage = ToImage(c.fixedImage);
  problem.movingImage = ToImage(c.movingImage);
  const auto & names = morea_core::PelvisPhantom::StructureNames();
  for (std::size_t s = 0; s < names.size(); ++s)
  {
    Structure structure;
    structure.name = names[s];
    structure.fixedMask = ToMask(c.fixedMasks[s]);
    structure.movingMask = ToMask(c.movingMasks[s]);
    problem.structures.push_back(structure);
  }
  problem.fixedLandmarks = ToPoints(c.fixedLandmarks);
  problem.movingLandmarks = ToPoints(c.movingLandmarks);
  return problem;
}

PhantomFiles
WritePhantomCase(const morea_core::PelvisPhantom::Case & c, const std::string & folder)
{
  const fs::path root(folder);
  PhantomFiles   files;
  files.fixedImage = (root / "fixed.nii.gz").string();
  files.movingImage = (root / "moving.nii.gz").string();
  WriteImage(ToImage(c.fixedImage), files.fixedImage);
  WriteImage(ToImage(c.movingImage), files.movingImage);
  const auto & names = morea_core::PelvisPhantom::StructureNames();
  for (std::size_t s = 0; s < names.size(); ++s)
  {
    files.fixedMasks[names[s]] = (root / "fixed_masks" / (names[s] + ".nii.gz")).string();
    files.movingMasks[names[s]] = (root / "moving_masks" / (names[s] + ".nii.gz")).string();
    WriteMask(ToMask(c.fixedMasks[s]), files.fixedMasks[names[s]]);
    WriteMask(ToMask(c.movingMasks[s]), files.movingMasks[names[s]]);
  }
  files.fixedLandmarks = (root / "fixed_landmarks.txt").string();
  files.movingLandmarks = (root / "moving_landmarks.txt").string();
  WriteElastixPointFile(ToPoints(c.fixedLandmarks), files.fixedLandmarks);
  WriteElastixPointFile(ToPoints(c.movingLandmarks), files.movingLandmarks);
  files.trueFixedToMoving = (root / "true_fixed_to_moving.nii.gz").string();
  files.trueMovingToFixed = (root / "true_moving_to_fixed.nii.gz").string();
  WriteDisplacementField(ToDisplacementField(c.fixedToMoving), files.trueFixedToMoving);
  WriteDisplacementField(ToDisplacementField(c.movingToFixed), files.trueMovingToFixed);
  return files;
}

} // namespace morea
} // namespace itk
