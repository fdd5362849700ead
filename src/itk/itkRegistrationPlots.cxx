// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkRegistrationPlots.h"

#include "itkLinearInterpolateImageFunction.h"
#include "itkImageRegionConstIterator.h"
#include "itkImageRegionConstIteratorWithIndex.h"
#include "itkRegistrationMetrics.h"
#include "morea_core/Error.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace itk
{
namespace morea
{
namespace
{
using morea_core::Error;

/** The screen axes of a slice: index axis of the columns and of the rows, and
 *  whether rows run against their index axis (superior at the top). */
struct SliceFrame
{
  unsigned int column{ 0 };
  unsigned int row{ 1 };
  bool         rowReversed{ false };
};

SliceFrame
FrameOf(SliceAxis axis)
{
  switch (axis)
  {
    case SliceAxis::Sagittal:
      return { 1, 2, true };
    case SliceAxis::Coronal:
      return { 0, 2, true };
    case SliceAxis::Axial:
    default:
      return { 0, 1, false };
  }
}

template <typename TImage>
std::array<long, 3>
SizeOf(const TImage * image)
{
  const auto size = image->GetBufferedRegion().GetSize();
  return { { static_cast<long>(size[0]), static_cast<long>(size[1]), static_cast<long>(size[2]) } };
}

template <typename TImage>
std::size_t
Offset(const TImage * image, long i, long j, long k)
{
  const auto size = image->GetBufferedRegion().GetSize();
  return static_cast<std::size_t>(i) + size[0] * (static_cast<std::size_t>(j) + size[1] * static_cast<std::size_t>(k));
}

/** Output pixels of one slice and, per pixel, its continuous index in the plane. */
struct SliceSampling
{
  SliceFrame          frame;
  long                slice{ 0 };
  unsigned int        axis{ 2 };
  int                 width{ 1 };
  int                 height{ 1 };
  std::array<long, 3> size{ { 1, 1, 1 } };
  double              pixelsPerMm{ 1.0 };

  double
  ColumnIndex(int x) const
  {
    return (x + 0.5) * static_cast<double>(size[frame.column]) / width - 0.5;
  }
  double
  RowIndex(int y) const
  {
    const double r = (y + 0.5) * static_cast<double>(size[frame.row]) / height - 0.5;
    return frame.rowReversed ? static_cast<double>(size[frame.row]) - 1.0 - r : r;
  }
  /** The pixel position of continuous in-plane indices (column, row). */
  std::pair<double, double>
  PixelOf(double column, double row) const
  {
    const double x = (column + 0.5) * width / static_cast<double>(size[frame.column]) - 0.5;
    const double r = frame.rowReversed ? static_cast<double>(size[frame.row]) - 1.0 - row : row;
    return { x, (r + 0.5) * height / static_cast<double>(size[frame.row]) - 0.5 };
  }
  /** The voxel index of in-plane continuous indices, rounded and clamped. */
  std::array<long, 3>
  Nearest(double column, double row) const
  {
    std::array<long, 3> index;
    index[axis] = slice;
    index[frame.column] = std::clamp(static_cast<long>(std::lround(column)), 0L, size[frame.column] - 1);
    index[frame.row] = std::clamp(static_cast<long>(std::lround(row)), 0L, size[frame.row] - 1);
    return index;
  }
};

/** Bilinear in-plane sample of a float image's slice. */
double
SampleSlice(const ImageType * image, const SliceSampling & s, double column, double row)
{
  const float * data = image->GetBufferPointer();
  column = std::clamp(column, 0.0, static_cast<double>(s.size[s.frame.column] - 1));
  row = std::clamp(row, 0.0, static_cast<double>(s.size[s.frame.row] - 1));
  const long   c0 = static_cast<long>(std::floor(column)), r0 = static_cast<long>(std::floor(row));
  const long   c1 = std::min(c0 + 1, s.size[s.frame.column] - 1), r1 = std::min(r0 + 1, s.size[s.frame.row] - 1);
  const double fc = column - c0, fr = row - r0;
  auto         at = [&](long c, long r) {
    std::array<long, 3> index;
    index[s.axis] = s.slice;
    index[s.frame.column] = c;
    index[s.frame.row] = r;
    return static_cast<double>(data[Offset(image, index[0], index[1], index[2])]);
  };
  return (at(c0, r0) * (1 - fc) + at(c1, r0) * fc) * (1 - fr) + (at(c0, r1) * (1 - fc) + at(c1, r1) * fc) * fr;
}

std::uint8_t
Grey(double value, float lo, float hi)
{
  const double t = (value - lo) / std::max(1e-12, static_cast<double>(hi - lo));
  return static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(t, 0.0, 1.0)));
}

/** Draws the outline of `mask` on the slice: solid, or dashed. */
void
DrawContour(PlotCanvas & canvas, const MaskType * mask, const SliceSampling & s, RGB color, bool dashed)
{
  const std::uint8_t * data = mask->GetBufferPointer();
  std::vector<char>    inside(static_cast<std::size_t>(s.width) * s.height);
  for (int y = 0; y < s.height; ++y)
  {
    const double row = s.RowIndex(y);
    for (int x = 0; x < s.width; ++x)
    {
      const auto index = s.Nearest(s.ColumnIndex(x), row);
      inside[static_cast<std::size_t>(y) * s.width + x] = data[Offset(mask, index[0], index[1], index[2])] != 0;
    }
  }
  auto in = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < s.width && y < s.height && inside[static_cast<std::size_t>(y) * s.width + x];
  };
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x)
    {
      if (!in(x, y) || (in(x - 1, y) && in(x + 1, y) && in(x, y - 1) && in(x, y + 1)))
        continue;
      if (dashed && ((x + y) / 5) % 2 == 1)
        continue;
      canvas.Set(x, y, color);
      // Two pixels wide, inwards, so that the outline reads at any scale.
      for (const auto [dx, dy] : { std::pair{ 1, 0 }, { -1, 0 }, { 0, 1 }, { 0, -1 } })
        if (in(x + dx, y + dy))
          canvas.Set(x + dx, y + dy, color);
    }
}

ImageType::Pointer
NewLike(const ImageType * like)
{
  auto image = ImageType::New();
  image->CopyInformation(like);
  image->SetRegions(like->GetBufferedRegion());
  image->Allocate();
  return image;
}
} // namespace

SliceView
SliceViewFromName(const std::string & name)
{
  static const std::pair<const char *, SliceView> names[] = {
    { "overlay", SliceView::Overlay },
    { "checkerboard-before", SliceView::CheckerboardBefore },
    { "checkerboard", SliceView::CheckerboardAfter },
    { "difference-before", SliceView::DifferenceBefore },
    { "difference", SliceView::DifferenceAfter },
    { "jacobian", SliceView::Jacobian },
    { "grid", SliceView::Grid },
  };
  for (const auto & [n, v] : names)
    if (name == n)
      return v;
  throw Error("unknown slice view '" + name +
              "' (overlay, checkerboard-before, checkerboard, difference-before, difference, jacobian, grid)");
}

SliceAxis
SliceAxisFromName(const std::string & name)
{
  if (name == "axial")
    return SliceAxis::Axial;
  if (name == "coronal")
    return SliceAxis::Coronal;
  if (name == "sagittal")
    return SliceAxis::Sagittal;
  throw Error("unknown slice axis '" + name + "' (axial, coronal, sagittal)");
}

const char *
SliceAxisName(SliceAxis axis)
{
  return axis == SliceAxis::Axial ? "axial" : axis == SliceAxis::Coronal ? "coronal" : "sagittal";
}

SolutionSliceViews::SolutionSliceViews(const RegistrationProblem & problem, const DisplacementFieldType * fixedToMoving)
  : m_Fixed(problem.fixedImage)
  , m_Moving(problem.movingImage)
{
  if (!m_Fixed || !m_Moving)
    throw Error("slice views need both images");
  if (m_Fixed->GetBufferedRegion() != m_Moving->GetBufferedRegion())
    throw Error("slice views need both images on one grid (a preprocessed problem)");
  if (fixedToMoving && fixedToMoving->GetBufferedRegion() != m_Fixed->GetBufferedRegion())
    throw Error("slice views: the displacement field is not on the fixed image's grid");
  m_Field = const_cast<DisplacementFieldType *>(fixedToMoving);
  const auto size = SizeOf(m_Fixed.GetPointer());

  // The intensity window: [0, 1] for preprocessed images, else CT's [-1000, 1000].
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  for (itk::ImageRegionConstIterator<ImageType> it(m_Fixed, m_Fixed->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    lo = std::min(lo, it.Get());
    hi = std::max(hi, it.Get());
  }
  if (!(lo >= 0.0f && hi <= 1.0f))
  {
    m_WindowMin = -1000.0f;
    m_WindowMax = 1000.0f;
  }

  // The warped moving image: moving(x + u(x)), linear; 0 outside.
  m_Warped = NewLike(m_Fixed);
  m_Jacobian = NewLike(m_Fixed);
  auto interpolator = LinearInterpolateImageFunction<ImageType, double>::New();
  interpolator->SetInputImage(m_Moving);
  float *       warped = m_Warped->GetBufferPointer();
  float *       jacobian = m_Jacobian->GetBufferPointer();
  const auto &  spacing = m_Fixed->GetSpacing();
  const auto &  direction = m_Fixed->GetDirection();
  for (long k = 0; k < size[2]; ++k)
    for (long j = 0; j < size[1]; ++j)
      for (long i = 0; i < size[0]; ++i)
      {
        const std::size_t o = Offset(m_Fixed.GetPointer(), i, j, k);
        if (!m_Field)
        {
          warped[o] = m_Moving->GetBufferPointer()[o];
          jacobian[o] = 1.0f;
          continue;
        }
        ImageType::IndexType index{ { i, j, k } };
        PointType            p;
        m_Fixed->TransformIndexToPhysicalPoint(index, p);
        const auto & u = m_Field->GetPixel(index);
        for (unsigned d = 0; d < 3; ++d)
          p[d] += u[d];
        ContinuousIndex<double, 3> c;
        const bool inside = m_Moving->TransformPhysicalPointToContinuousIndex(p, c);
        warped[o] = inside && interpolator->IsInsideBuffer(c) ? static_cast<float>(interpolator->EvaluateAtContinuousIndex(c))
                                                             : 0.0f;
        // det(I + du/dx): central differences along index axes, then to physical axes.
        double        g[3][3]; // g[d][a] = d u_d / d index_a / spacing_a
        const long    at[3] = { i, j, k };
        for (unsigned a = 0; a < 3; ++a)
        {
          ImageType::IndexType lo_i = index, hi_i = index;
          lo_i[a] = std::max(0L, at[a] - 1);
          hi_i[a] = std::min(size[a] - 1, at[a] + 1);
          const double span = static_cast<double>(hi_i[a] - lo_i[a]) * spacing[a];
          const auto & ulo = m_Field->GetPixel(lo_i);
          const auto & uhi = m_Field->GetPixel(hi_i);
          for (unsigned d = 0; d < 3; ++d)
            g[d][a] = span > 0.0 ? (uhi[d] - ulo[d]) / span : 0.0;
        }
        double m[3][3]; // I + g D^T (index-axis derivatives to physical ones)
        for (unsigned d = 0; d < 3; ++d)
          for (unsigned e = 0; e < 3; ++e)
          {
            double v = d == e ? 1.0 : 0.0;
            for (unsigned a = 0; a < 3; ++a)
              v += g[d][a] * direction[e][a];
            m[d][e] = v;
          }
        jacobian[o] = static_cast<float>(m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                                         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                                         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]));
      }

  std::size_t mostChanged = 0;
  for (const auto & s : problem.structures)
  {
    if (!s.fixedMask || !s.movingMask || s.name == "body")
      continue;
    Layer layer{ s.name, s.fixedMask, m_Field ? WarpMask(s.movingMask, m_Field) : s.movingMask };
    m_Layers.push_back(layer);
    if (s.fixedMask->GetBufferedRegion() != s.movingMask->GetBufferedRegion())
      continue;
    std::size_t changed = 0;
    const auto  n = s.fixedMask->GetBufferedRegion().GetNumberOfPixels();
    for (std::size_t v = 0; v < n; ++v)
      changed += (s.fixedMask->GetBufferPointer()[v] != 0) != (s.movingMask->GetBufferPointer()[v] != 0);
    if (m_Focus.empty() || changed > mostChanged)
    {
      m_Focus = s.name;
      mostChanged = changed;
    }
  }
}

std::array<long, 3>
SolutionSliceViews::Size() const
{
  return SizeOf(m_Fixed.GetPointer());
}

long
SolutionSliceViews::FocusSlice(SliceAxis axis) const
{
  const unsigned a = static_cast<unsigned>(axis);
  const auto     size = Size();
  for (const auto & layer : m_Layers)
  {
    if (layer.name != m_Focus)
      continue;
    double      sum = 0.0;
    std::size_t n = 0;
    for (itk::ImageRegionConstIteratorWithIndex<MaskType> it(layer.fixed, layer.fixed->GetBufferedRegion()); !it.IsAtEnd();
         ++it)
      if (it.Get())
      {
        sum += static_cast<double>(it.GetIndex()[a]);
        ++n;
      }
    if (n)
      return std::clamp(static_cast<long>(std::lround(sum / n)), 0L, size[a] - 1);
  }
  return size[a] / 2;
}

std::vector<std::string>
SolutionSliceViews::StructureNames() const
{
  std::vector<std::string> names;
  for (const auto & l : m_Layers)
    names.push_back(l.name);
  return names;
}

std::pair<double, double>
SolutionSliceViews::JacobianRange() const
{
  const float * j = m_Jacobian->GetBufferPointer();
  const auto    n = m_Jacobian->GetBufferedRegion().GetNumberOfPixels();
  const auto [lo, hi] = std::minmax_element(j, j + n);
  return { *lo, *hi };
}

double
SolutionSliceViews::PixelsPerMmForWidth(int width) const
{
  const auto   size = Size();
  const auto & spacing = m_Fixed->GetSpacing();
  // Axial and coronal slices span x; sagittal spans y.
  const double widest = std::max(size[0] * spacing[0], size[1] * spacing[1]);
  return width / std::max(widest, 1e-6);
}

PlotCanvas
SolutionSliceViews::Render(SliceAxis axis, long slice, SliceView view, bool contours, double pixelsPerMm) const
{
  SliceSampling s;
  s.axis = static_cast<unsigned>(axis);
  s.frame = FrameOf(axis);
  s.size = Size();
  s.slice = slice;
  s.pixelsPerMm = pixelsPerMm;
  if (slice < 0 || slice >= s.size[s.axis])
    throw Error(std::string(SliceAxisName(axis)) + " slice " + std::to_string(slice) + " is outside the image (0 to " +
                std::to_string(s.size[s.axis] - 1) + ")");
  if (!(pixelsPerMm > 0.0) || !std::isfinite(pixelsPerMm))
    throw Error("slice views: pixels per mm must be positive");
  const auto & spacing = m_Fixed->GetSpacing();
  s.width = std::clamp(static_cast<int>(std::lround(s.size[s.frame.column] * spacing[s.frame.column] * pixelsPerMm)), 1, 4096);
  s.height = std::clamp(static_cast<int>(std::lround(s.size[s.frame.row] * spacing[s.frame.row] * pixelsPerMm)), 1, 4096);
  PlotCanvas canvas(s.width, s.height, colors::Black);
  const int  tile = std::max(8, std::min(s.width, s.height) / 8);
  for (int y = 0; y < s.height; ++y)
  {
    const double row = s.RowIndex(y);
    for (int x = 0; x < s.width; ++x)
    {
      const double column = s.ColumnIndex(x);
      const double fixed = SampleSlice(m_Fixed, s, column, row);
      RGB          c;
      switch (view)
      {
        case SliceView::Overlay:
        {
          const auto g = Grey(fixed, m_WindowMin, m_WindowMax);
          c = { { g, g, g } };
          break;
        }
        case SliceView::CheckerboardBefore:
        case SliceView::CheckerboardAfter:
        {
          const bool   odd = ((x / tile) + (y / tile)) % 2 == 1;
          const auto * other = view == SliceView::CheckerboardBefore ? m_Moving.GetPointer() : m_Warped.GetPointer();
          const auto   g = Grey(odd ? SampleSlice(other, s, column, row) : fixed, m_WindowMin, m_WindowMax);
          c = { { g, g, g } };
          break;
        }
        case SliceView::DifferenceBefore:
        case SliceView::DifferenceAfter:
        {
          const auto * other = view == SliceView::DifferenceBefore ? m_Moving.GetPointer() : m_Warped.GetPointer();
          const double d = std::abs(fixed - SampleSlice(other, s, column, row)) / (m_WindowMax - m_WindowMin);
          c = SequentialColor(std::sqrt(std::clamp(d, 0.0, 1.0)));
          break;
        }
        case SliceView::Jacobian:
        {
          const auto   index = s.Nearest(column, row);
          const double det = m_Jacobian->GetBufferPointer()[Offset(m_Jacobian.GetPointer(), index[0], index[1], index[2])];
          const RGB    j = JacobianColor(det);
          const double g = Grey(fixed, m_WindowMin, m_WindowMax);
          for (int k = 0; k < 3; ++k)
            c[k] = static_cast<std::uint8_t>(std::lround(0.8 * j[k] + 0.2 * g));
          break;
        }
        case SliceView::Grid:
        {
          const auto g = static_cast<std::uint8_t>(Grey(SampleSlice(m_Moving, s, column, row), m_WindowMin, m_WindowMax) * 0.6);
          c = { { g, g, g } };
          break;
        }
      }
      canvas.Set(x, y, c);
    }
  }
  if (view == SliceView::Grid)
  {
    // Grid lines every 8 mm of the fixed grid, each point moved by u (in plane).
    const double step = 0.5;
    const double every[2] = { 8.0 / spacing[s.frame.column], 8.0 / spacing[s.frame.row] };
    const RGB    yellow{ { 255, 220, 0 } };
    auto         moved = [&](double column, double row) {
      auto p = s.PixelOf(column, row);
      if (m_Field)
      {
        const auto index = s.Nearest(column, row);
        const auto u = m_Field->GetPixel(DisplacementFieldType::IndexType{ { index[0], index[1], index[2] } });
        p.first += u[s.frame.column] * pixelsPerMm;
        p.second += (s.frame.rowReversed ? -1.0 : 1.0) * u[s.frame.row] * pixelsPerMm;
      }
      return p;
    };
    for (int pass = 0; pass < 2; ++pass)
    {
      const unsigned along = pass == 0 ? s.frame.row : s.frame.column;   // the line runs along this axis
      const unsigned across = pass == 0 ? s.frame.column : s.frame.row; // lines are spaced along this one
      for (double a = 0.0; a <= s.size[across] - 1 + 1e-9; a += every[pass])
      {
        std::pair<double, double> last{ 0, 0 };
        for (double b = 0.0; b <= s.size[along] - 1 + 1e-9; b += step)
        {
          const auto p = pass == 0 ? moved(a, b) : moved(b, a);
          if (b > 0.0)
            canvas.Line(last.first, last.second, p.first, p.second, yellow, 1);
          last = p;
        }
      }
    }
  }
  if (contours)
    for (std::size_t i = 0; i < m_Layers.size(); ++i)
    {
      DrawContour(canvas, m_Layers[i].fixed, s, StructureColor(i), false);
      DrawContour(canvas, m_Layers[i].warped, s, StructureColor(i), true);
    }
  return canvas;
}

namespace
{
/** "Nice" tick values covering [lo, hi]. */
std::vector<double>
Ticks(double lo, double hi, int wanted = 5)
{
  std::vector<double> ticks;
  if (!(hi > lo))
    return { lo };
  const double raw = (hi - lo) / wanted;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double       step = magnitude;
  for (const double m : { 1.0, 2.0, 2.5, 5.0, 10.0 })
    if (m * magnitude >= raw)
    {
      step = m * magnitude;
      break;
    }
  for (double t = std::ceil(lo / step) * step; t <= hi + step * 1e-9; t += step)
    ticks.push_back(std::abs(t) < step * 1e-9 ? 0.0 : t);
  return ticks;
}

/** A plotting box on a canvas with data ranges. */
struct Axes
{
  int    left, top, width, height;
  double xmin, xmax, ymin, ymax;

  double
  X(double v) const
  {
    return left + (v - xmin) / (xmax - xmin) * width;
  }
  double
  Y(double v) const
  {
    return top + height - (v - ymin) / (ymax - ymin) * height;
  }
};

std::pair<double, double>
PaddedRange(const std::vector<double> & values)
{
  double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
  for (const double v : values)
    if (std::isfinite(v))
    {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  if (lo > hi)
    return { 0.0, 1.0 };
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi)))
    return { lo - 0.5 * std::max(1e-9, std::abs(lo)), hi + 0.5 * std::max(1e-9, std::abs(hi)) };
  const double pad = 0.05 * (hi - lo);
  return { lo - pad, hi + pad };
}

/** Tick labels of `ticks`: with very small or large values, a common power
 *  of ten is taken out and returned as a suffix for the axis label. */
std::pair<std::vector<std::string>, std::string>
TickLabels(const std::vector<double> & ticks)
{
  double largest = 0.0;
  for (const double t : ticks)
    largest = std::max(largest, std::abs(t));
  int exponent = 0;
  if (largest > 0.0 && (largest < 1e-2 || largest >= 1e5))
    exponent = static_cast<int>(std::floor(std::log10(largest)));
  std::vector<std::string> labels;
  for (const double t : ticks)
    labels.push_back(FormatNumber(t / std::pow(10.0, exponent)));
  return { labels, exponent ? " (x 1e" + std::to_string(exponent) + ")" : "" };
}

/** Frame, ticks, tick labels, axis labels and title of a panel. */
void
DrawAxes(PlotCanvas & c, const Axes & a, const std::string & xlabel, const std::string & ylabel, const std::string & title)
{
  c.Rect(a.left, a.top, a.width + 1, a.height + 1, colors::Black, 1);
  const auto xticks = Ticks(a.xmin, a.xmax);
  const auto [xlabels, xscale] = TickLabels(xticks);
  for (std::size_t i = 0; i < xticks.size(); ++i)
  {
    const int x = static_cast<int>(std::lround(a.X(xticks[i])));
    c.FillRect(x, a.top + a.height, 1, 6, colors::Black);
    for (int y = a.top + 1; y < a.top + a.height; y += 4)
      c.Set(x, y, colors::LightGrey);
    c.Text(x - PlotCanvas::TextWidth(xlabels[i]) / 2, a.top + a.height + 10, xlabels[i], colors::Black);
  }
  int        widest = 0;
  const auto yticks = Ticks(a.ymin, a.ymax);
  const auto [ylabels, yscale] = TickLabels(yticks);
  for (std::size_t i = 0; i < yticks.size(); ++i)
  {
    const int y = static_cast<int>(std::lround(a.Y(yticks[i])));
    c.FillRect(a.left - 6, y, 6, 1, colors::Black);
    for (int x = a.left + 1; x < a.left + a.width; x += 4)
      c.Set(x, y, colors::LightGrey);
    widest = std::max(widest, PlotCanvas::TextWidth(ylabels[i]));
    c.Text(a.left - 10 - PlotCanvas::TextWidth(ylabels[i]), y - 7, ylabels[i], colors::Black);
  }
  const std::string xtext = xlabel + xscale, ytext = ylabel + yscale;
  c.Text(a.left + a.width / 2 - PlotCanvas::TextWidth(xtext) / 2, a.top + a.height + 34, xtext, colors::Black);
  c.TextVertical(std::max(0, a.left - 20 - widest - PlotCanvas::TextHeight()),
                 a.top + a.height / 2 + PlotCanvas::TextWidth(ytext) / 2, ytext, colors::Black);
  c.Text(a.left + a.width / 2 - PlotCanvas::TextWidth(title, 2) / 2, a.top - 26, title, colors::Black, 2);
}
} // namespace

void
WriteFrontPlot(const std::vector<std::array<double, 3>> & objectives,
               const std::vector<std::pair<std::size_t, std::string>> & marked, const std::string & path)
{
  static const char * names[3] = { "magnitude", "intensity", "guidance" };
  // (x, y, colour) objective indices of the three projections.
  static const int projections[3][3] = { { 2, 1, 0 }, { 2, 0, 1 }, { 1, 0, 2 } };
  const int        panel = 500;
  PlotCanvas       canvas(3 * panel, 610);
  canvas.Text(20, 12, "The front: " + std::to_string(objectives.size()) +
                        " registrations (all objectives minimised; colour: rank of the third objective, dark = low)",
              colors::Black, 2);
  for (int p = 0; p < 3; ++p)
  {
    const int           xo = projections[p][0], yo = projections[p][1], co = projections[p][2];
    std::vector<double> xs, ys, cs;
    for (const auto & o : objectives)
    {
      xs.push_back(o[xo]);
      ys.push_back(o[yo]);
      cs.push_back(o[co]);
    }
    const auto [x0, x1] = PaddedRange(xs);
    const auto [y0, y1] = PaddedRange(ys);
    const Axes a{ p * panel + 125, 110, panel - 150, 370, x0, x1, y0, y1 };
    DrawAxes(canvas, a, names[xo], names[yo], std::string(names[yo]) + " vs " + names[xo]);
    // Colour by rank of the third objective: a few outliers do not flatten the scale.
    std::vector<std::size_t> order(objectives.size());
    for (std::size_t i = 0; i < order.size(); ++i)
      order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t l, std::size_t r) { return cs[l] < cs[r]; });
    std::vector<double> shade(objectives.size(), 0.5);
    for (std::size_t r = 0; r < order.size() && order.size() > 1; ++r)
      shade[order[r]] = static_cast<double>(r) / static_cast<double>(order.size() - 1);
    for (std::size_t i = 0; i < objectives.size(); ++i)
      canvas.Circle(a.X(xs[i]), a.Y(ys[i]), 4.0, SequentialColor(shade[i]));
    for (std::size_t m = 0; m < marked.size(); ++m)
    {
      const auto i = marked[m].first;
      if (i >= objectives.size())
        continue;
      canvas.Circle(a.X(xs[i]), a.Y(ys[i]), 9.0, colors::Red, false, 3);
    }
    // The colour bar of the third objective.
    const int barTop = 540;
    for (int x = 0; x < a.width; ++x)
      canvas.FillRect(a.left + x, barTop, 1, 12, SequentialColor(static_cast<double>(x) / a.width));
    const auto [lowest, highest] = std::minmax_element(cs.begin(), cs.end());
    canvas.Text(a.left, barTop + 18, cs.empty() ? "" : FormatNumber(*lowest), colors::Black);
    const std::string hiLabel = cs.empty() ? "" : FormatNumber(*highest);
    canvas.Text(a.left + a.width - PlotCanvas::TextWidth(hiLabel), barTop + 18, hiLabel, colors::Black);
    const std::string colourLabel = std::string("colour: rank of ") + names[co];
    canvas.Text(a.left + a.width / 2 - PlotCanvas::TextWidth(colourLabel) / 2, barTop + 40, colourLabel, colors::Black);
  }
  // The legend of the marked solutions.
  int x = 20;
  if (!marked.empty())
  {
    canvas.Circle(x + 8, 47, 9.0, colors::Red, false, 3);
    x += 24;
    std::string labels = "the chosen solutions:";
    for (std::size_t m = 0; m < marked.size(); ++m)
      labels += (m ? ", " : " ") + marked[m].second;
    canvas.Text(x, 40, labels, colors::Black, 2);
  }
  canvas.WritePng(path);
}

void
WriteConvergencePlot(const std::vector<double> & generations, const std::vector<double> & hypervolume,
                     const std::vector<double> & bestGuidance, const std::string & path)
{
  PlotCanvas canvas(1400, 540);
  canvas.Text(20, 12,
              generations.empty() ? std::string("Convergence: no generations recorded")
                                  : "Convergence, generations " + FormatNumber(generations.front(), 6) + " to " +
                                      FormatNumber(generations.back(), 6),
              colors::Black, 2);
  const std::vector<double> * series[2] = { &hypervolume, &bestGuidance };
  const char *                labels[2] = { "hypervolume of the archive (higher is better)",
                                            "best guidance in the archive (lower is better)" };
  const RGB                   tints[2] = { colors::Blue, colors::Orange };
  for (int p = 0; p < 2; ++p)
  {
    const auto [x0, x1] = PaddedRange(generations);
    const auto [y0, y1] = PaddedRange(*series[p]);
    const Axes a{ p * 700 + 130, 80, 540, 370, x0, x1, y0, y1 };
    DrawAxes(canvas, a, "generation", p == 0 ? "hypervolume" : "guidance", labels[p]);
    const auto & ys = *series[p];
    for (std::size_t i = 1; i < std::min(generations.size(), ys.size()); ++i)
      canvas.Line(a.X(generations[i - 1]), a.Y(ys[i - 1]), a.X(generations[i]), a.Y(ys[i]), tints[p], 2);
    if (generations.size() == 1 && !ys.empty())
      canvas.Circle(a.X(generations[0]), a.Y(ys[0]), 4.0, tints[p]);
  }
  canvas.WritePng(path);
}

void
WriteSolutionPlots(const SolutionSliceViews & views, const std::string & title, const std::string & prefix)
{
  const int  panelWidth = 300;
  const auto ppm = views.PixelsPerMmForWidth(panelWidth);
  const auto names = views.StructureNames();
  const auto [jmin, jmax] = views.JacobianRange();
  for (const auto axis : { SliceAxis::Axial, SliceAxis::Coronal, SliceAxis::Sagittal })
  {
    const long slice = views.FocusSlice(axis);
    struct Panel
    {
      SliceView   view;
      bool        contours;
      std::string caption;
    };
    const Panel panels[] = { { SliceView::Overlay, true, "fixed + contours" },
                             { SliceView::CheckerboardBefore, false, "checkerboard before" },
                             { SliceView::CheckerboardAfter, false, "checkerboard after" },
                             { SliceView::Jacobian, false, "Jacobian determinant" },
                             { SliceView::Grid, false, "deformed grid" } };
    std::vector<PlotCanvas> pictures;
    int                     tallest = 0;
    for (const auto & p : panels)
    {
      pictures.push_back(views.Render(axis, slice, p.view, p.contours, ppm));
      tallest = std::max(tallest, pictures.back().Height());
    }
    const int  gap = 12, top = 70;
    const int  legendRows = static_cast<int>(names.size()) + 2;
    const int  width = 5 * panelWidth + 6 * gap;
    PlotCanvas canvas(width, top + tallest + 40 + legendRows * 22 + 20);
    canvas.Text(gap, 12,
                title + ", " + SliceAxisName(axis) + " slice " + std::to_string(slice) +
                  (views.FocusStructure().empty() ? "" : " (through " + views.FocusStructure() + ")"),
                colors::Black, 2);
    for (std::size_t i = 0; i < pictures.size(); ++i)
    {
      const int x = gap + static_cast<int>(i) * (panelWidth + gap);
      canvas.Text(x, top - 24, panels[i].caption, colors::Black, 2);
      canvas.Blit(pictures[i], x + (panelWidth - pictures[i].Width()) / 2, top);
    }
    // Legend: contours under the first panel, the Jacobian's colour bar under the fourth,
    // the grid's meaning under the fifth.
    int y = top + tallest + 14;
    for (std::size_t i = 0; i < names.size(); ++i, y += 22)
    {
      const RGB c = StructureColor(i);
      const RGB dark{ { static_cast<std::uint8_t>(c[0] * 0.7), static_cast<std::uint8_t>(c[1] * 0.7),
                        static_cast<std::uint8_t>(c[2] * 0.7) } };
      canvas.Line(gap, y + 7, gap + 30, y + 7, dark, 3);
      canvas.Line(gap + 40, y + 7, gap + 70, y + 7, dark, 3, 5);
      canvas.Text(gap + 80, y, names[i], colors::Black, 2);
    }
    canvas.Text(gap, y + 2, "solid: fixed, dashed: warped moving", colors::Black, 2);
    const int jx = gap + 3 * (panelWidth + gap), jy = top + tallest + 14;
    for (int x = 0; x < panelWidth; ++x)
      canvas.FillRect(jx + x, jy, 1, 14, JacobianColor(std::pow(2.0, 4.0 * x / panelWidth - 2.0)));
    canvas.Text(jx, jy + 20, "1/4", colors::Black, 2);
    canvas.Text(jx + panelWidth / 2 - 6, jy + 20, "1", colors::Black, 2);
    canvas.Text(jx + panelWidth - 12, jy + 20, "4", colors::Black, 2);
    canvas.Text(jx, jy + 44, "range " + FormatNumber(jmin) + " to " + FormatNumber(jmax), colors::Black, 2);
    canvas.Text(jx, jy + 66, "black: folded (<= 0)", colors::Black, 2);
    const int gx = gap + 4 * (panelWidth + gap);
    canvas.Text(gx, jy, "8 mm fixed grid, each", colors::Black, 2);
    canvas.Text(gx, jy + 22, "point moved by its", colors::Black, 2);
    canvas.Text(gx, jy + 44, "displacement, on the", colors::Black, 2);
    canvas.Text(gx, jy + 66, "moving image", colors::Black, 2);
    canvas.WritePng(prefix + "_" + SliceAxisName(axis) + ".png");
  }
}
} // namespace morea
} // namespace itk
