// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// A 5x7 bitmap font for printable ASCII (32-126), drawn for this module's
// plots: each glyph is seven rows of five columns, '#' set.
#ifndef itkPlotFont_h
#define itkPlotFont_h

namespace itk
{
namespace morea
{
namespace font
{
constexpr int GlyphWidth = 5;
constexpr int GlyphHeight = 7;

/** Glyph of character c (32..126): 7 rows of 5 characters. */
extern const char * const Glyphs[95][7];

/** Glyphs drawn two rows lower, their tails below the baseline. */
inline bool
HasDescender(char c)
{
  return c == 'g' || c == 'p' || c == 'q' || c == 'y';
}
} // namespace font
} // namespace morea
} // namespace itk

#endif
