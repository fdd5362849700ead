// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: the pictures a run writes and the navigator
 *  page shows, drawn with itk::morea::PlotCanvas (no Python needed).
 *
 *  - the front: three 2D projections of the objectives, the chosen solutions
 *    marked;
 *  - convergence: hypervolume and best guidance per generation;
 *  - per solution and slice (axial, coronal, sagittal through the structure
 *    that moves most): the fixed image with fixed and warped moving contours
 *    and a legend, checkerboards of fixed and moving before and after, the
 *    Jacobian determinant map and the deformed grid.
 *
 *  Slices are taken along the index axes of the preprocessed grid (whose
 *  direction is the identity), in the radiological convention of
 *  itkContourOverlayRenderer.h: axial rows run to +y, coronal and sagittal
 *  rows to -z (superior at the top).
 *=========================================================================*/
#ifndef itkRegistrationPlots_h
#define itkRegistrationPlots_h

#include "itkContourOverlayRenderer.h"
#include "itkPlotCanvas.h"
#include "itkRegistrationProblem.h"

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace itk
{
namespace morea
{
/** What a slice picture shows. */
enum class SliceView
{
  Overlay,            ///< the fixed image (contours drawn when asked)
  CheckerboardBefore, ///< fixed and moving image in alternating tiles
  CheckerboardAfter,  ///< fixed and warped moving image in alternating tiles
  DifferenceBefore,   ///< |fixed - moving|
  DifferenceAfter,    ///< |fixed - warped moving|
  Jacobian,           ///< determinant of the fixed-to-moving map's Jacobian (JacobianColor)
  Grid                ///< a regular grid moved by the fixed-to-moving displacement
};

/** SliceView by name: overlay, checkerboard-before, checkerboard, difference-before,
 *  difference, jacobian, grid. Throws morea_core::Error on another name. */
SliceView
SliceViewFromName(const std::string & name);
/** "axial", "coronal", "sagittal". Throws morea_core::Error on another name. */
SliceAxis
SliceAxisFromName(const std::string & name);
const char *
SliceAxisName(SliceAxis axis);

/** One registration of a preprocessed problem, ready to be looked at on slices:
 *  the warped moving image and masks and the Jacobian determinant are
 *  computed once. Both images must share one grid (as preprocessed ones do). */
class SolutionSliceViews
{
public:
  /** `fixedToMoving` on the fixed grid; null: the identity (no registration). */
  SolutionSliceViews(const RegistrationProblem & problem, const DisplacementFieldType * fixedToMoving);

  /** Voxels along index axis 0 (sagittal), 1 (coronal), 2 (axial). */
  std::array<long, 3>
  Size() const;
  /** The structure whose fixed and moving masks differ in the most voxels
   *  ("" without structures): where the slices go by default. */
  const std::string &
  FocusStructure() const
  {
    return m_Focus;
  }
  /** The slice through the focus structure's centroid (the middle one without it). */
  long
  FocusSlice(SliceAxis axis) const;
  /** Structure names, in the colours StructureColor(i) gives them. */
  std::vector<std::string>
  StructureNames() const;
  /** Jacobian determinant range over the fixed grid (min, max). */
  std::pair<double, double>
  JacobianRange() const;

  /** The slice as a picture, `pixelsPerMm` output pixels per millimetre
   *  (square pixels); with `contours` each structure's fixed contour (solid)
   *  and warped moving contour (dashed) on top. Throws morea_core::Error for a
   *  slice outside the image. */
  PlotCanvas
  Render(SliceAxis axis, long slice, SliceView view, bool contours, double pixelsPerMm) const;

  /** pixelsPerMm that makes the widest of the three slices `width` pixels wide. */
  double
  PixelsPerMmForWidth(int width) const;

private:
  struct Layer
  {
    std::string       name;
    MaskType::Pointer fixed;
    MaskType::Pointer warped;
  };
  ImageType::Pointer             m_Fixed;
  ImageType::Pointer             m_Moving;
  ImageType::Pointer             m_Warped;
  ImageType::Pointer             m_Jacobian;
  DisplacementFieldType::Pointer m_Field; ///< null: identity
  std::vector<Layer>             m_Layers;
  std::string                    m_Focus;
  float                          m_WindowMin{ 0.0f };
  float                          m_WindowMax{ 1.0f };
};

/** The front: guidance against intensity, guidance against magnitude and
 *  intensity against magnitude, each point coloured by the third objective,
 *  `marked` (front index, label) ringed and labelled. Written as a PNG of
 *  1500 x 560 pixels. */
void
WriteFrontPlot(const std::vector<std::array<double, 3>> & objectives,
               const std::vector<std::pair<std::size_t, std::string>> & marked, const std::string & path);

/** Hypervolume and best guidance per generation, side by side (1400 x 520). */
void
WriteConvergencePlot(const std::vector<double> & generations, const std::vector<double> & hypervolume,
                     const std::vector<double> & bestGuidance, const std::string & path);

/** Per axis, PREFIX_{axial,coronal,sagittal}.png: five panels through the
 *  focus structure (fixed image with contours and a legend, checkerboard
 *  before and after, the Jacobian determinant with its colour bar, the
 *  deformed grid), `title` above. At least 1200 pixels wide. */
void
WriteSolutionPlots(const SolutionSliceViews & views, const std::string & title, const std::string & prefix);
} // namespace morea
} // namespace itk

#endif
