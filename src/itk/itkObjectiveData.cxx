// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkObjectiveData.h"

#include "itkImageRegionConstIterator.h"
#include "itkImageRegionIterator.h"
#include "itkMOREAImageIO.h"
#include "itkPreprocessing.h"
#include "itkSignedMaurerDistanceMapImageFilter.h"
#include "morea_core/ParameterSet.h"

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

namespace itk
{
namespace morea
{
namespace
{
[[noreturn]] void
Fail(const std::string & message)
{
  itkGenericExceptionMacro(<< "objective data: " << message);
}

const char *
SideName(bool fixedSide)
{
  return fixedSide ? "fixed" : "moving";
}

template <typename TImage>
typename TImage::Pointer
MakeImageOn(const ImageBase<Dimension> * grid)
{
  auto image = TImage::New();
  image->SetOrigin(grid->GetOrigin());
  image->SetSpacing(grid->GetSpacing());
  image->SetDirection(grid->GetDirection());
  image->SetRegions(grid->GetLargestPossibleRegion());
  image->Allocate(true);
  return image;
}


/** Distance (mm) from every voxel centre outside `set` to the nearest voxel
 *  centre of `set`, 0 on the set. Only the outside of Maurer's signed map is
 *  used: inside, it measures to the set's voxels that touch the outside by a
 *  face, edge or corner, which is not the face-halfway surface wanted here (at
 *  the centre of a voxelised sphere of 8 mm on 1.5 mm voxels: 5.6 mm, not 7.4). */
ImageType::Pointer
DistanceToSet(const MaskType * set)
{
  auto filter = SignedMaurerDistanceMapImageFilter<MaskType, ImageType>::New();
  filter->SetInput(set);
  filter->SetInsideIsPositive(false);
  filter->SetSquaredDistance(false);
  filter->SetUseImageSpacing(true);
  filter->SetBackgroundValue(0);
  filter->Update();
  ImageType::Pointer map = filter->GetOutput();
  map->DisconnectPipeline();
  for (ImageRegionIterator<ImageType> it(map, map->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    if (it.Get() < 0.0f)
    {
      it.Set(0.0f);
    }
  }
  return map;
}

/** The mean of the distances to the inside voxels that face an outside voxel
 *  and to the outside voxels that face an inside one, so that the surface lies
 *  halfway between inside and outside voxel centres along every axis, whatever
 *  its spacing (an outside voxel next to the mask holds half a voxel). Outside
 *  the mask the first term is the distance to the nearest inside voxel (that
 *  one always faces the outside), inside it the second likewise. */
ImageType::Pointer
DistanceFromMask(const MaskType * mask)
{
  const auto region = mask->GetBufferedRegion();
  const auto size = region.GetSize();
  auto       innerLayer = MaskType::New();
  auto       outerLayer = MaskType::New();
  for (const auto & layer : { innerLayer, outerLayer })
  {
    layer->CopyInformation(mask);
    layer->SetRegions(region);
    layer->Allocate(true);
  }
  const unsigned char * in = mask->GetBufferPointer();
  unsigned char *       inner = innerLayer->GetBufferPointer();
  unsigned char *       outer = outerLayer->GetBufferPointer();
  const std::size_t     stride[3] = { 1, size[0], size[0] * size[1] };
  std::size_t           o = 0;
  for (std::size_t z = 0; z < size[2]; ++z)
  {
    for (std::size_t y = 0; y < size[1]; ++y)
    {
      for (std::size_t x = 0; x < size[0]; ++x, ++o)
      {
        const std::size_t at[3] = { x, y, z };
        const bool        inside = in[o] != 0;
        for (unsigned d = 0; d < Dimension; ++d)
        {
          // Face neighbours on the grid only: the grid edge is not a surface.
          if ((at[d] > 0 && (in[o - stride[d]] != 0) != inside) ||
              (at[d] + 1 < size[d] && (in[o + stride[d]] != 0) != inside))
          {
            (inside ? inner : outer)[o] = 1;
            break;
          }
        }
      }
    }
  }
  ImageType::Pointer                  distance = DistanceToSet(innerLayer);
  const ImageType::Pointer            toOuter = DistanceToSet(outerLayer);
  ImageRegionIterator<ImageType>      a(distance, distance->GetBufferedRegion());
  ImageRegionConstIterator<ImageType> b(toOuter, toOuter->GetBufferedRegion());
  for (; !a.IsAtEnd(); ++a, ++b)
  {
    a.Set(0.5f * (a.Get() + b.Get()));
  }
  return distance;
}

/** Distance to the nearest voxel holding a point; points off the grid are skipped. */
ImageType::Pointer
DistanceFromPoints(const PointListType & points, const ImageBase<Dimension> * grid, const std::string & what)
{
  auto                raster = MakeImageOn<MaskType>(grid);
  const auto          region = raster->GetLargestPossibleRegion();
  std::size_t         placed = 0;
  MaskType::IndexType index;
  for (const PointType & p : points)
  {
    // Nearest voxel centre (ITK rounds); a point on the grid's outer half voxel still counts.
    if (raster->TransformPhysicalPointToIndex(p, index) && region.IsInside(index))
    {
      placed += raster->GetPixel(index) == 0;
      raster->SetPixel(index, 1);
    }
  }
  if (placed == 0)
  {
    Fail("none of the " + std::to_string(points.size()) + " points of " + what + " lies on the image grid");
  }
  return DistanceToSet(raster);
}

/** |C| of one side: its contour points, else its mask's surface points (0 when neither). */
std::size_t
ContourPointCount(const Structure & structure, bool fixedSide)
{
  const PointListType &     points = fixedSide ? structure.fixedPoints : structure.movingPoints;
  const MaskType::Pointer & mask = fixedSide ? structure.fixedMask : structure.movingMask;
  if (!points.empty())
  {
    return points.size();
  }
  return mask ? ExtractSurfacePoints(mask).size() : 0;
}

/** Copies `volume` into channel `c` of `target`, whose grid it must share. */
void
SetChannel(morea_core::ChannelVolume & target, std::size_t c, const morea_core::Volume<float> & volume)
{
  for (std::size_t v = 0; v < volume.data.size(); ++v)
  {
    target.data[target.channels * v + c] = volume.data[v];
  }
}

morea_core::ChannelVolume
MakeChannelVolume(const morea_core::Volume<float> & intensity, std::size_t channels)
{
  morea_core::ChannelVolume volume;
  volume.size = intensity.size;
  volume.spacing = intensity.spacing;
  volume.origin = intensity.origin;
  volume.channels = channels;
  volume.data.assign(channels * intensity.NumberOfVoxels(), 0.0f);
  SetChannel(volume, 0, intensity);
  return volume;
}
} // namespace

ImageType::Pointer
StructureDistanceMap(const Structure & structure, bool fixedSide, const ImageBase<Dimension> * grid)
{
  if (grid == nullptr)
  {
    Fail("distance map of " + structure.name + " on a null grid");
  }
  const std::string         what = "structure " + structure.name + " on the " + SideName(fixedSide) + " image";
  const MaskType::Pointer & mask = fixedSide ? structure.fixedMask : structure.movingMask;
  const PointListType &     points = fixedSide ? structure.fixedPoints : structure.movingPoints;
  if (mask)
  {
    if (!SameGrid(mask, grid) || mask->GetBufferedRegion() != grid->GetLargestPossibleRegion())
    {
      Fail("the mask of " + what + " is not on the image grid");
    }
    const std::size_t inside = CountInside(mask);
    const std::size_t all = mask->GetBufferedRegion().GetNumberOfPixels();
    if (inside > 0 && inside < all)
    {
      ImageType::Pointer distance = DistanceFromMask(mask);
      distance->SetOrigin(grid->GetOrigin()); // SameGrid allows a tolerance: take the grid's geometry exactly
      distance->SetSpacing(grid->GetSpacing());
      distance->SetDirection(grid->GetDirection());
      return distance;
    }
    // A mask filling the whole grid has no outside to be halfway to: its surface is the grid edge.
    if (inside == all && points.empty())
    {
      return DistanceFromPoints(ExtractSurfacePoints(mask), grid, what);
    }
  }
  if (points.empty())
  {
    Fail(what + " has neither a non-empty mask nor contour points");
  }
  return DistanceFromPoints(points, grid, what);
}

morea_core::ObjectiveData
BuildObjectiveData(const RegistrationProblem & problem, const MeshModel & model,
                   const morea_core::ParameterSet & parameters)
{
  return BuildObjectiveData(problem, model.frame, parameters);
}

morea_core::ObjectiveData
BuildObjectiveData(const RegistrationProblem & problem, const DomainFrame & frame,
                   const morea_core::ParameterSet & parameters)
{
  if (!problem.fixedImage || !problem.movingImage)
  {
    Fail("the problem has no images");
  }
  if (!SameGrid(problem.fixedImage, problem.movingImage))
  {
    Fail("the problem must be preprocessed (both images on one grid)");
  }
  if (!frame.IsAlignedWith(problem.movingImage))
  {
    Fail("the mesh model's domain frame is not the images' frame");
  }

  morea_core::ObjectiveData data;
  if (parameters.GetBool("problem_guidance_enabled"))
  {
    data.guidanceNames = GuidanceStructureNames(problem, parameters);
  }
  const std::size_t guidance = data.guidanceNames.size();

  // Check every guidance structure before the expensive distance maps.
  std::vector<const Structure *> structures;
  std::vector<double>            counts;
  for (const std::string & name : data.guidanceNames)
  {
    const Structure * s = problem.FindStructure(name);
    if (s == nullptr)
    {
      Fail("guidance structure " + name + " is not in the problem");
    }
    const std::size_t fixedCount = ContourPointCount(*s, true);
    const std::size_t movingCount = ContourPointCount(*s, false);
    if (fixedCount == 0 || movingCount == 0)
    {
      Fail(std::string("guidance structure ") + name + " has neither a non-empty mask nor contour points on the " +
           SideName(fixedCount == 0) + " image");
    }
    structures.push_back(s);
    // |C_g| on the source image, where the mesh and its contour points lie.
    counts.push_back(static_cast<double>(movingCount));
  }

  data.fixed = MakeChannelVolume(ToVolume(problem.fixedImage.GetPointer(), frame), 1 + guidance);
  data.moving = MakeChannelVolume(ToVolume(problem.movingImage.GetPointer(), frame), 1 + guidance);
  // One grid (SameGrid allows rounding differences): both take the moving image's geometry bit for bit.
  data.fixed.origin = data.moving.origin;
  data.fixed.spacing = data.moving.spacing;
  for (std::size_t g = 0; g < guidance; ++g)
  {
    // One map at a time: real grids hold tens of millions of voxels.
    SetChannel(data.fixed, 1 + g,
               ToVolume(StructureDistanceMap(*structures[g], true, problem.fixedImage).GetPointer(), frame));
    SetChannel(data.moving, 1 + g,
               ToVolume(StructureDistanceMap(*structures[g], false, problem.movingImage).GetPointer(), frame));
  }

  double total = 0.0;
  for (double c : counts)
  {
    total += c;
  }
  for (double c : counts)
  {
    data.guidanceWeights.push_back(c / total);
  }

  // The mesh domain spans the voxel centres (MeshDomain::OfGrid), as the channel volumes' grid.
  morea_core::Vec3 extent;
  data.voxelVolume = 1.0;
  for (unsigned d = 0; d < Dimension; ++d)
  {
    extent[d] = data.moving.spacing[d] * static_cast<double>(data.moving.size[d] - 1);
    data.voxelVolume *= problem.fixedImage->GetSpacing()[d];
  }
  data.guidanceRadius = morea_core::DefaultGuidanceRadius(extent);
  data.samplingRate = parameters.GetReal("morea_sampling_rate");
  return data;
}
} // namespace morea
} // namespace itk
