// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkPlotCanvas.h"

#include "itkMOREAImageIO.h"
#include "itkPlotFont.h"
#include "morea_core/Error.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace itk
{
namespace morea
{
RGB
StructureColor(std::size_t i)
{
  static constexpr RGB palette[] = { { { 0, 200, 255 } },   { { 255, 200, 0 } },  { { 60, 220, 60 } },
                                     { { 255, 90, 200 } },  { { 255, 120, 40 } }, { { 160, 120, 255 } },
                                     { { 240, 240, 240 } }, { { 0, 160, 140 } } };
  return palette[i % (sizeof(palette) / sizeof(palette[0]))];
}

RGB
JacobianColor(double determinant)
{
  if (!(determinant > 0.0))
    return colors::Black;
  const double t = std::clamp(std::log2(determinant) / 2.0, -1.0, 1.0); // 1/4 .. 4
  const auto   mix = [](double a, double b, double s) { return static_cast<std::uint8_t>(std::lround(a + (b - a) * s)); };
  if (t < 0.0) // white -> blue
    return { { mix(255, 30, -t), mix(255, 70, -t), mix(255, 200, -t) } };
  return { { mix(255, 200, t), mix(255, 30, t), mix(255, 30, t) } };
}

RGB
SequentialColor(double t)
{
  // A short viridis-like ramp.
  static constexpr double stops[][3] = {
    { 68, 1, 84 }, { 59, 82, 139 }, { 33, 145, 140 }, { 94, 201, 98 }, { 253, 231, 37 }
  };
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 4.0;
  const int    i = std::min(3, static_cast<int>(t));
  const double f = t - i;
  RGB          c;
  for (int k = 0; k < 3; ++k)
    c[k] = static_cast<std::uint8_t>(std::lround(stops[i][k] + (stops[i + 1][k] - stops[i][k]) * f));
  return c;
}

PlotCanvas::PlotCanvas(int width, int height, RGB background)
  : m_Width(std::max(1, width))
  , m_Height(std::max(1, height))
  , m_Pixels(static_cast<std::size_t>(m_Width) * static_cast<std::size_t>(m_Height) * 3)
{
  for (std::size_t i = 0; i < m_Pixels.size(); i += 3)
    std::copy(background.begin(), background.end(), m_Pixels.begin() + static_cast<std::ptrdiff_t>(i));
}

RGB
PlotCanvas::Get(int x, int y) const
{
  if (x < 0 || y < 0 || x >= m_Width || y >= m_Height)
    return colors::Black;
  const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(m_Width) + static_cast<std::size_t>(x)) * 3;
  return { { m_Pixels[i], m_Pixels[i + 1], m_Pixels[i + 2] } };
}

void
PlotCanvas::Set(int x, int y, RGB color, double alpha)
{
  if (x < 0 || y < 0 || x >= m_Width || y >= m_Height)
    return;
  const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(m_Width) + static_cast<std::size_t>(x)) * 3;
  if (alpha >= 1.0)
  {
    std::copy(color.begin(), color.end(), m_Pixels.begin() + static_cast<std::ptrdiff_t>(i));
    return;
  }
  for (int k = 0; k < 3; ++k)
    m_Pixels[i + k] = static_cast<std::uint8_t>(std::lround(m_Pixels[i + k] * (1.0 - alpha) + color[k] * alpha));
}

void
PlotCanvas::FillRect(int x, int y, int w, int h, RGB color)
{
  for (int j = std::max(0, y); j < std::min(m_Height, y + h); ++j)
    for (int i = std::max(0, x); i < std::min(m_Width, x + w); ++i)
      Set(i, j, color);
}

void
PlotCanvas::Rect(int x, int y, int w, int h, RGB color, int thickness)
{
  FillRect(x, y, w, thickness, color);
  FillRect(x, y + h - thickness, w, thickness, color);
  FillRect(x, y, thickness, h, color);
  FillRect(x + w - thickness, y, thickness, h, color);
}

void
PlotCanvas::Line(double x0, double y0, double x1, double y1, RGB color, int thickness, int dash)
{
  if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1))
    return;
  const double length = std::hypot(x1 - x0, y1 - y0);
  const int    steps = std::max(1, static_cast<int>(std::ceil(length * 2.0)));
  if (steps > 1 << 20)
    return; // far off the canvas
  const int lo = -(thickness - 1) / 2, hi = thickness / 2;
  for (int s = 0; s <= steps; ++s)
  {
    const double t = static_cast<double>(s) / steps;
    if (dash > 0 && static_cast<int>(t * length / dash) % 2 == 1)
      continue;
    const int x = static_cast<int>(std::lround(x0 + (x1 - x0) * t));
    const int y = static_cast<int>(std::lround(y0 + (y1 - y0) * t));
    for (int dy = lo; dy <= hi; ++dy)
      for (int dx = lo; dx <= hi; ++dx)
        Set(x + dx, y + dy, color);
  }
}

void
PlotCanvas::Circle(double cx, double cy, double radius, RGB color, bool filled, int thickness)
{
  const int r = static_cast<int>(std::ceil(radius)) + 1;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
    {
      const int    x = static_cast<int>(std::lround(cx)) + dx, y = static_cast<int>(std::lround(cy)) + dy;
      const double d = std::hypot(x - cx, y - cy);
      if (d <= radius && (filled || d > radius - thickness))
        Set(x, y, color);
    }
}

namespace
{
/** The font's glyph for `ch` ('?' for characters it lacks), and in `drop`
 *  the rows a descender lowers it by. */
const auto &
GlyphOf(char ch, int & drop)
{
  const int c = static_cast<unsigned char>(ch);
  drop = font::HasDescender(static_cast<char>(c)) ? 2 : 0;
  return font::Glyphs[(c >= 32 && c <= 126) ? c - 32 : '?' - 32];
}
} // namespace

int
PlotCanvas::Text(int x, int y, const std::string & text, RGB color, int scale)
{
  int pen = x;
  for (const char ch : text)
  {
    int          drop = 0;
    const auto & glyph = GlyphOf(ch, drop);
    for (int row = 0; row < font::GlyphHeight; ++row)
      for (int col = 0; col < font::GlyphWidth; ++col)
        if (glyph[row][col] == '#')
          FillRect(pen + col * scale, y + (row + drop) * scale, scale, scale, color);
    pen += 6 * scale;
  }
  return pen - x;
}

void
PlotCanvas::TextVertical(int x, int y, const std::string & text, RGB color, int scale)
{
  int pen = y;
  for (const char ch : text)
  {
    int          drop = 0;
    const auto & glyph = GlyphOf(ch, drop);
    // Column `col` of the glyph runs upwards from the pen; row `row` goes right.
    for (int row = 0; row < font::GlyphHeight; ++row)
      for (int col = 0; col < font::GlyphWidth; ++col)
        if (glyph[row][col] == '#')
          FillRect(x + (row + drop) * scale, pen - (col + 1) * scale, scale, scale, color);
    pen -= 6 * scale;
  }
}

void
PlotCanvas::Blit(const PlotCanvas & other, int x, int y)
{
  for (int j = 0; j < other.Height(); ++j)
    for (int i = 0; i < other.Width(); ++i)
      Set(x + i, y + j, other.Get(i, j));
}

namespace
{
void
AppendUint32(std::string & out, std::uint32_t v)
{
  for (int shift = 24; shift >= 0; shift -= 8)
    out.push_back(static_cast<char>((v >> shift) & 0xff));
}

void
AppendChunk(std::string & out, const char * type, const std::string & data)
{
  AppendUint32(out, static_cast<std::uint32_t>(data.size()));
  const std::string typed = std::string(type, 4) + data;
  out += typed;
  AppendUint32(out, static_cast<std::uint32_t>(
                      crc32(0L, reinterpret_cast<const Bytef *>(typed.data()), static_cast<uInt>(typed.size()))));
}
} // namespace

std::string
PlotCanvas::EncodePng() const
{
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string header;
  AppendUint32(header, static_cast<std::uint32_t>(m_Width));
  AppendUint32(header, static_cast<std::uint32_t>(m_Height));
  header += std::string("\x08\x02\x00\x00\x00", 5); // 8 bits, RGB, deflate, no filter set, no interlace
  AppendChunk(png, "IHDR", header);
  // Each row: filter type 1 (difference to the pixel on the left), which
  // suits plots' flat areas.
  const std::size_t row = static_cast<std::size_t>(m_Width) * 3;
  std::string       raw;
  raw.reserve((row + 1) * static_cast<std::size_t>(m_Height));
  for (int y = 0; y < m_Height; ++y)
  {
    raw.push_back('\x01');
    const std::uint8_t * p = m_Pixels.data() + static_cast<std::size_t>(y) * row;
    for (std::size_t i = 0; i < row; ++i)
      raw.push_back(static_cast<char>(i < 3 ? p[i] : static_cast<std::uint8_t>(p[i] - p[i - 3])));
  }
  uLongf      size = compressBound(static_cast<uLong>(raw.size()));
  std::string deflated(size, '\0');
  if (compress2(reinterpret_cast<Bytef *>(&deflated[0]), &size, reinterpret_cast<const Bytef *>(raw.data()),
                static_cast<uLong>(raw.size()), 6) != Z_OK)
    throw morea_core::Error("cannot compress a PNG image");
  deflated.resize(size);
  AppendChunk(png, "IDAT", deflated);
  AppendChunk(png, "IEND", "");
  return png;
}

void
PlotCanvas::WritePng(const std::string & path) const
{
  WriteTextFile(EncodePng(), path);
}

std::string
FormatNumber(double value, int significant)
{
  if (!std::isfinite(value))
    return "n/a";
  char         text[64];
  const double magnitude = std::abs(value);
  if (magnitude != 0.0 && (magnitude < 1e-3 || magnitude >= 1e5))
    std::snprintf(text, sizeof text, "%.*e", std::max(0, significant - 1), value);
  else
    std::snprintf(text, sizeof text, "%.*g", significant, value);
  return text;
}
} // namespace morea
} // namespace itk
