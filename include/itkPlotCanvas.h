// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: a small RGB raster canvas for the plots a run
 *  writes and the navigator page shows: lines, markers, rectangles, text in
 *  an embedded 5x7 bitmap font (printable ASCII, scaled by whole pixels), and
 *  PNG encoding (zlib). No other library is involved, so the command line
 *  writes its plots without Python or a font installed.
 *=========================================================================*/
#ifndef itkPlotCanvas_h
#define itkPlotCanvas_h

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace itk
{
namespace morea
{
using RGB = std::array<std::uint8_t, 3>;

namespace colors
{
constexpr RGB White{ { 255, 255, 255 } };
constexpr RGB Black{ { 0, 0, 0 } };
constexpr RGB Grey{ { 128, 128, 128 } };
constexpr RGB LightGrey{ { 220, 220, 220 } };
constexpr RGB Red{ { 220, 30, 30 } };
constexpr RGB Blue{ { 40, 90, 220 } };
constexpr RGB Orange{ { 245, 140, 20 } };
} // namespace colors

/** Structure colours of plots and the page: the i-th structure's. */
RGB
StructureColor(std::size_t i);

/** A diverging colour for a Jacobian determinant: blue (compression) through
 *  white (1) to red (expansion), log2 scale saturating at 1/4 and 4; black
 *  for a determinant <= 0 (a fold). */
RGB
JacobianColor(double determinant);

/** A sequential colour (dark blue to yellow) for t in [0, 1]. */
RGB
SequentialColor(double t);

class PlotCanvas
{
public:
  PlotCanvas(int width, int height, RGB background = colors::White);

  int
  Width() const
  {
    return m_Width;
  }
  int
  Height() const
  {
    return m_Height;
  }
  const std::vector<std::uint8_t> &
  Pixels() const
  {
    return m_Pixels;
  }
  RGB
  Get(int x, int y) const;
  /** Sets a pixel; outside the canvas nothing happens. `alpha` in [0, 1] blends. */
  void
  Set(int x, int y, RGB color, double alpha = 1.0);
  void
  FillRect(int x, int y, int w, int h, RGB color);
  void
  Rect(int x, int y, int w, int h, RGB color, int thickness = 1);
  /** A line of `thickness` pixels; `dash` > 0 draws dashes of that many pixels. */
  void
  Line(double x0, double y0, double x1, double y1, RGB color, int thickness = 1, int dash = 0);
  /** A filled disc (or a ring of `thickness` when `filled` is false). */
  void
  Circle(double cx, double cy, double radius, RGB color, bool filled = true, int thickness = 1);
  /** Text with its top left at (x, y); glyphs of 6x8 cells times `scale`.
   *  Characters outside printable ASCII draw as '?'. Returns the width drawn. */
  int
  Text(int x, int y, const std::string & text, RGB color, int scale = 2);
  /** Text rotated by 90 degrees counter-clockwise (reading upwards), its
   *  bottom left at (x, y). */
  void
  TextVertical(int x, int y, const std::string & text, RGB color, int scale = 2);
  static int
  TextWidth(const std::string & text, int scale = 2)
  {
    return static_cast<int>(text.size()) * 6 * scale;
  }
  static int
  TextHeight(int scale = 2)
  {
    return 8 * scale;
  }
  /** Copies `other` with its top left at (x, y). */
  void
  Blit(const PlotCanvas & other, int x, int y);

  /** The canvas as PNG file contents (8-bit RGB). */
  std::string
  EncodePng() const;
  /** Writes the PNG atomically (a temporary name, then renamed). */
  void
  WritePng(const std::string & path) const;

private:
  int                       m_Width;
  int                       m_Height;
  std::vector<std::uint8_t> m_Pixels;
};

/** A number formatted for an axis or a table: 3 significant digits,
 *  scientific notation for very large or small magnitudes. */
std::string
FormatNumber(double value, int significant = 3);
} // namespace morea
} // namespace itk

#endif
