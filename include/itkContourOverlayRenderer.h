// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: PNG renders of a slice with structure contours.
 *=========================================================================*/
#ifndef itkContourOverlayRenderer_h
#define itkContourOverlayRenderer_h

#include "itkMOREATypes.h"

#include <array>
#include <string>
#include <vector>

namespace itk
{
namespace morea
{
enum class SliceAxis
{
  Sagittal = 0, ///< constant x (first index axis)
  Coronal = 1,  ///< constant y
  Axial = 2     ///< constant z
};

/** One set of contours drawn over the slice: the outline of `mask` in `color`. */
struct ContourLayer
{
  const MaskType *            mask{ nullptr };
  std::array<unsigned char, 3> color{ { 255, 0, 0 } };
  std::string                 label;
};

struct SliceRenderOptions
{
  SliceAxis axis{ SliceAxis::Axial };
  /** Slice index along `axis`; negative: the slice through the centroid of the first layer's mask. */
  long  sliceIndex{ -1 };
  float windowMin{ -1000.0f }; ///< intensity shown black
  float windowMax{ 1000.0f };  ///< intensity shown white
  /** Output pixels per mm (the slice is resampled so pixels are square). */
  double pixelsPerMm{ 1.0 };
};

/** Renders the slice of `image` with every layer's contour drawn on top and writes
 *  it as an 8-bit RGB PNG (atomically). Masks must share the image's grid.
 *  Returns the slice index that was drawn. */
long
RenderContourOverlay(const ImageType *                 image,
                     const std::vector<ContourLayer> & layers,
                     const SliceRenderOptions &        options,
                     const std::string &               pngPath);

} // namespace morea
} // namespace itk

#endif
