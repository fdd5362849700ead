// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Registration quality metrics against values derived by hand or computed independently.
#include "itkRegistrationMetrics.h"

#include "itkHausdorffDistanceImageFilter.h"
#include "itkImageRegionIteratorWithIndex.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

using namespace itk::morea;

namespace
{
using Index3 = std::array<long, 3>;

MaskType::Pointer
MakeMask(const std::array<unsigned long, 3> & size,
         const std::array<double, 3> &        spacing,
         const std::function<bool(const Index3 &)> & inside)
{
  auto                mask = MaskType::New();
  MaskType::SizeType  s{ { size[0], size[1], size[2] } };
  mask->SetRegions(MaskType::RegionType{ s });
  MaskType::SpacingType sp;
  for (unsigned d = 0; d < 3; ++d)
  {
    sp[d] = spacing[d];
  }
  mask->SetSpacing(sp);
  mask->Allocate(true);
  for (itk::ImageRegionIteratorWithIndex<MaskType> it(mask, mask->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
  {
    const auto i = it.GetIndex();
    it.Set(inside({ { i[0], i[1], i[2] } }) ? 1 : 0);
  }
  return mask;
}

std::function<bool(const Index3 &)>
Box(const Index3 & lo, const Index3 & hiExclusive)
{
  return [=](const Index3 & i) {
    for (unsigned d = 0; d < 3; ++d)
    {
      if (i[d] < lo[d] || i[d] >= hiExclusive[d])
      {
        return false;
      }
    }
    return true;
  };
}

std::function<bool(const Index3 &)>
Ball(const std::array<double, 3> & centre, double radius)
{
  return [=](const Index3 & i) {
    double r2{ 0.0 };
    for (unsigned d = 0; d < 3; ++d)
    {
      r2 += (i[d] - centre[d]) * (i[d] - centre[d]);
    }
    return r2 <= radius * radius;
  };
}

DisplacementFieldType::Pointer
MakeField(const std::array<unsigned long, 3> &                        size,
          const std::array<double, 3> &                               spacing,
          const std::function<DisplacementVectorType(const PointType &)> & u)
{
  auto                              field = DisplacementFieldType::New();
  DisplacementFieldType::SizeType   s{ { size[0], size[1], size[2] } };
  field->SetRegions(DisplacementFieldType::RegionType{ s });
  DisplacementFieldType::SpacingType sp;
  for (unsigned d = 0; d < 3; ++d)
  {
    sp[d] = spacing[d];
  }
  field->SetSpacing(sp);
  field->Allocate();
  for (itk::ImageRegionIteratorWithIndex<DisplacementFieldType> it(field, field->GetLargestPossibleRegion());
       !it.IsAtEnd();
       ++it)
  {
    PointType p;
    field->TransformIndexToPhysicalPoint(it.GetIndex(), p);
    it.Set(u(p));
  }
  return field;
}

DisplacementVectorType
Vec(double x, double y, double z)
{
  DisplacementVectorType v;
  v[0] = x;
  v[1] = y;
  v[2] = z;
  return v;
}

std::size_t
CountInside(const MaskType * mask)
{
  const auto * p = mask->GetBufferPointer();
  return static_cast<std::size_t>(
    std::count_if(p, p + mask->GetBufferedRegion().GetNumberOfPixels(), [](unsigned char v) { return v != 0; }));
}

double
ItkHausdorff(const MaskType * a, const MaskType * b)
{
  auto filter = itk::HausdorffDistanceImageFilter<MaskType, MaskType>::New();
  filter->SetInput1(a);
  filter->SetInput2(b);
  filter->SetUseImageSpacing(true);
  filter->Update();
  return filter->GetHausdorffDistance();
}

/** Brute force: surface elements on the voxel-corner grid, as documented in
 *  itkRegistrationMetrics.h. Corner c = 0..size per axis lies at continuous
 *  index c - 1/2 and its code has bit (dx + 2 dy + 4 dz) set when voxel
 *  c - 1 + (dx, dy, dz) is inside (voxels beyond the image are outside); codes
 *  other than 0 and 255 are surface elements, weighted by the code's area. */
struct BruteSurface
{
  std::vector<std::array<double, 3>> points; // physical (origin 0, identity direction)
  std::vector<double>                areas;
  std::vector<unsigned int>          codes;
};

BruteSurface
BruteSurfaceOf(const MaskType * mask)
{
  BruteSurface s;
  const auto   size = mask->GetLargestPossibleRegion().GetSize();
  const auto   sp = mask->GetSpacing();
  const auto   table = SurfaceElementAreas(sp);
  for (long z = 0; z <= static_cast<long>(size[2]); ++z)
  {
    for (long y = 0; y <= static_cast<long>(size[1]); ++y)
    {
      for (long x = 0; x <= static_cast<long>(size[0]); ++x)
      {
        unsigned int code{ 0 };
        for (unsigned int bit = 0; bit < 8; ++bit)
        {
          const MaskType::IndexType v{ { x - 1 + (bit & 1), y - 1 + ((bit >> 1) & 1), z - 1 + ((bit >> 2) & 1) } };
          if (mask->GetLargestPossibleRegion().IsInside(v) && mask->GetPixel(v) != 0)
          {
            code |= 1u << bit;
          }
        }
        if (code != 0 && code != 255)
        {
          s.points.push_back({ { (x - 0.5) * sp[0], (y - 0.5) * sp[1], (z - 0.5) * sp[2] } });
          s.areas.push_back(table[code]);
          s.codes.push_back(code);
        }
      }
    }
  }
  return s;
}

std::vector<std::pair<double, double>>
BruteDirected(const BruteSurface & from, const BruteSurface & to)
{
  std::vector<std::pair<double, double>> result;
  for (std::size_t i = 0; i < from.points.size(); ++i)
  {
    double best = std::numeric_limits<double>::max();
    for (const auto & q : to.points)
    {
      double d2{ 0.0 };
      for (unsigned d = 0; d < 3; ++d)
      {
        d2 += (from.points[i][d] - q[d]) * (from.points[i][d] - q[d]);
      }
      best = std::min(best, d2);
    }
    result.emplace_back(std::sqrt(best), from.areas[i]);
  }
  std::sort(result.begin(), result.end());
  return result;
}

/** pymia's rule: first sorted distance whose cumulative area share reaches q. */
double
BrutePercentile(const std::vector<std::pair<double, double>> & sorted, double q)
{
  double total{ 0.0 };
  for (const auto & v : sorted)
  {
    total += v.second;
  }
  double cumulative{ 0.0 };
  for (const auto & v : sorted)
  {
    cumulative += v.second;
    if (cumulative / total >= q)
    {
      return v.first;
    }
  }
  return sorted.back().first;
}
} // namespace

// ---------------------------------------------------------------- Dice

TEST(RegistrationMetrics, DiceOfOffsetCubesMatchesAnalyticValue)
{
  const std::array<unsigned long, 3> size{ { 48, 32, 32 } };
  const std::array<double, 3>        spacing{ { 1.0, 0.8, 2.5 } };
  const auto a = MakeMask(size, spacing, Box({ { 10, 6, 6 } }, { { 30, 26, 26 } }));
  const auto b = MakeMask(size, spacing, Box({ { 15, 6, 6 } }, { { 35, 26, 26 } }));
  // 20^3 cubes overlapping in 15 x 20 x 20: 2 * 6000 / 16000.
  EXPECT_NEAR(ComputeDice(a, b), 0.75, 1e-12);
  EXPECT_NEAR(ComputeDice(b, a), 0.75, 1e-12);
  EXPECT_NEAR(ComputeDice(a, a), 1.0, 1e-12);

  const auto c = MakeMask(size, spacing, Box({ { 40, 0, 0 } }, { { 48, 4, 4 } }));
  EXPECT_NEAR(ComputeDice(a, c), 0.0, 1e-12);
}

TEST(RegistrationMetrics, DiceOfEmptyMasks)
{
  const auto empty = MakeMask({ { 8, 8, 8 } }, { { 1, 1, 1 } }, [](const Index3 &) { return false; });
  const auto some = MakeMask({ { 8, 8, 8 } }, { { 1, 1, 1 } }, Box({ { 1, 1, 1 } }, { { 3, 3, 3 } }));
  EXPECT_DOUBLE_EQ(ComputeDice(empty, empty), 1.0);
  EXPECT_DOUBLE_EQ(ComputeDice(empty, some), 0.0);
}

TEST(RegistrationMetrics, DiceRegionRestrictionCountsOnlyRegionVoxels)
{
  const std::array<unsigned long, 3> size{ { 48, 32, 32 } };
  const std::array<double, 3>        spacing{ { 1, 1, 1 } };
  const auto a = MakeMask(size, spacing, Box({ { 10, 6, 6 } }, { { 30, 26, 26 } }));
  const auto b = MakeMask(size, spacing, Box({ { 15, 6, 6 } }, { { 35, 26, 26 } }));
  const auto region = MakeMask(size, spacing, [](const Index3 & i) { return i[0] < 20; });
  // In x < 20: |A| = 10*400, |B| = 5*400, |A n B| = 5*400 -> 2*2000 / 6000.
  EXPECT_NEAR(ComputeDice(a, b, region), 2.0 / 3.0, 1e-12);
  // A region holding only the overlap gives perfect agreement.
  const auto overlap = MakeMask(size, spacing, [](const Index3 & i) { return i[0] >= 15 && i[0] < 30; });
  EXPECT_NEAR(ComputeDice(a, b, overlap), 1.0, 1e-12);
}

// ---------------------------------------------------------------- surface distances

TEST(RegistrationMetrics, HausdorffOfShiftedCubeEqualsShift)
{
  const std::array<unsigned long, 3> size{ { 48, 40, 40 } };
  const std::array<double, 3>        spacing{ { 1.5, 1.0, 2.0 } };
  const auto a = MakeMask(size, spacing, Box({ { 10, 10, 10 } }, { { 30, 30, 30 } }));
  const auto b = MakeMask(size, spacing, Box({ { 13, 10, 10 } }, { { 33, 30, 30 } }));
  const auto scores = ComputeSurfaceDistances(a, b);
  EXPECT_NEAR(scores.hausdorff, 3 * 1.5, 1e-4);
  EXPECT_NEAR(scores.hausdorff, ItkHausdorff(a, b), 1e-4);
  EXPECT_LE(scores.hausdorff95, scores.hausdorff + 1e-9);
  EXPECT_GT(scores.hausdorff95, 0.0);
  EXPECT_GT(scores.meanSurfaceDistance, 0.0);
  EXPECT_LT(scores.meanSurfaceDistance, scores.hausdorff);

  const auto same = ComputeSurfaceDistances(a, a);
  EXPECT_DOUBLE_EQ(same.hausdorff, 0.0);
  EXPECT_DOUBLE_EQ(same.hausdorff95, 0.0);
  EXPECT_DOUBLE_EQ(same.meanSurfaceDistance, 0.0);
}

TEST(RegistrationMetrics, HausdorffMatchesItkForBoxesOfDifferentShape)
{
  const std::array<unsigned long, 3> size{ { 40, 36, 30 } };
  const std::array<double, 3>        spacing{ { 0.9, 1.3, 2.0 } };
  const auto a = MakeMask(size, spacing, Box({ { 5, 8, 4 } }, { { 25, 20, 16 } }));
  const auto b = MakeMask(size, spacing, Box({ { 9, 4, 7 } }, { { 33, 22, 14 } }));
  const auto scores = ComputeSurfaceDistances(a, b);
  EXPECT_NEAR(scores.hausdorff, ItkHausdorff(a, b), 1e-4);
  EXPECT_NEAR(ComputeSurfaceDistances(b, a).hausdorff, scores.hausdorff, 1e-9);
}

TEST(RegistrationMetrics, ConcentricSpheresDifferByRadii)
{
  const std::array<unsigned long, 3> size{ { 36, 36, 36 } };
  const std::array<double, 3>        spacing{ { 1, 1, 1 } };
  const std::array<double, 3>        centre{ { 17.3, 18.1, 17.6 } };
  const double                       r1{ 6.0 }, r2{ 11.0 };
  const auto inner = MakeMask(size, spacing, Ball(centre, r1));
  const auto outer = MakeMask(size, spacing, Ball(centre, r2));
  const auto scores = ComputeSurfaceDistances(inner, outer);
  EXPECT_NEAR(scores.hausdorff, r2 - r1, 1.0);
  EXPECT_NEAR(scores.hausdorff95, r2 - r1, 1.0);
  EXPECT_NEAR(scores.meanSurfaceDistance, r2 - r1, 1.0);
  EXPECT_LE(scores.hausdorff95, scores.hausdorff + 1e-9);
  // ITK measures between the full voxel sets, not the surfaces: same within a voxel here.
  EXPECT_NEAR(scores.hausdorff, ItkHausdorff(inner, outer), 1.0);

  // The distance maps against an all-pairs search over the same surface elements.
  const auto sInner = BruteSurfaceOf(inner);
  const auto sOuter = BruteSurfaceOf(outer);
  const auto innerToOuter = BruteDirected(sInner, sOuter);
  const auto outerToInner = BruteDirected(sOuter, sInner);
  const double bruteHd = std::max(innerToOuter.back().first, outerToInner.back().first);
  const double bruteHd95 =
    std::max(BrutePercentile(innerToOuter, 0.95), BrutePercentile(outerToInner, 0.95));
  double sum{ 0.0 }, area{ 0.0 };
  for (const auto * set : { &innerToOuter, &outerToInner })
  {
    for (const auto & [d, w] : *set)
    {
      sum += d * w;
      area += w;
    }
  }
  EXPECT_NEAR(scores.hausdorff, bruteHd, 1e-4);
  EXPECT_NEAR(scores.hausdorff95, bruteHd95, 1e-4);
  EXPECT_NEAR(scores.meanSurfaceDistance, sum / area, 1e-4);
}

TEST(RegistrationMetrics, Hd95IgnoresAFewOutlierVoxels)
{
  const std::array<unsigned long, 3> size{ { 60, 40, 40 } };
  const std::array<double, 3>        spacing{ { 1, 1, 1 } };
  const auto cube = Box({ { 10, 10, 10 } }, { { 30, 30, 30 } });
  const auto a = MakeMask(size, spacing, cube);
  // B = A plus three stray voxels 20 voxels beyond A's face at x = 29.
  const auto b = MakeMask(size, spacing, [&](const Index3 & i) {
    return cube(i) || (i[0] == 49 && i[1] == 20 && (i[2] == 15 || i[2] == 20 || i[2] == 25));
  });
  const auto scores = ComputeSurfaceDistances(a, b);
  EXPECT_NEAR(scores.hausdorff, 20.0, 1e-4);
  EXPECT_NEAR(scores.hausdorff, ItkHausdorff(a, b), 1e-4);
  // The strays carry 3 * 8 corner triangles of sqrt(3)/8 mm^2 (5.2 mm^2) against
  // the cube's 2329 mm^2: far below 5 %.
  EXPECT_NEAR(scores.hausdorff95, 0.0, 1e-9);
  EXPECT_LT(scores.hausdorff95, 0.1 * scores.hausdorff);

  // A region that leaves the strays out leaves identical surfaces.
  const auto region = MakeMask(size, spacing, [](const Index3 & i) { return i[0] < 40; });
  EXPECT_NEAR(ComputeSurfaceDistances(a, b, region).hausdorff, 0.0, 1e-9);
}

TEST(RegistrationMetrics, SurfaceDistancesOfTinyMasks)
{
  const std::array<unsigned long, 3> size{ { 10, 10, 10 } };
  const std::array<double, 3>        spacing{ { 1, 1, 1.5 } };
  const auto a = MakeMask(size, spacing, [](const Index3 & i) { return i == Index3{ { 3, 3, 3 } }; });
  const auto b = MakeMask(size, spacing, [](const Index3 & i) { return i == Index3{ { 3, 3, 6 } }; });
  const auto scores = ComputeSurfaceDistances(a, b);
  // Each voxel's surface elements are its 8 corners (equal areas): the 4 facing
  // the other voxel are 2 voxels (3 mm) from it, the other 4 are 4.5 mm.
  EXPECT_NEAR(scores.hausdorff, 4.5, 1e-4);
  EXPECT_NEAR(scores.hausdorff95, 4.5, 1e-4);
  EXPECT_NEAR(scores.meanSurfaceDistance, 3.75, 1e-4);
  // Masks made only of surface voxels, filling their whole bounding box.
  const auto c = MakeMask(size, spacing, Box({ { 0, 0, 0 } }, { { 2, 2, 2 } }));
  EXPECT_DOUBLE_EQ(ComputeSurfaceDistances(c, c).hausdorff, 0.0);
  const auto full = MakeMask(size, spacing, [](const Index3 &) { return true; });
  EXPECT_DOUBLE_EQ(ComputeSurfaceDistances(full, full).hausdorff95, 0.0);
}

// ---------------------------------------------------------------- surface elements

TEST(RegistrationMetrics, SurfaceElementAreasOfSingleConfigurations)
{
  // Spacing (1, 2, 3): a plane with index-space area vector n has area
  // |(2*3 n_x, 1*3 n_y, 1*2 n_z)| = |(6 n_x, 3 n_y, 2 n_z)|.
  MaskType::SpacingType spacing;
  spacing[0] = 1.0;
  spacing[1] = 2.0;
  spacing[2] = 3.0;
  const auto area = SurfaceElementAreas(spacing);
  const auto bit = [](int dx, int dy, int dz) { return 1u << (dx + 2 * dy + 4 * dz); };
  EXPECT_DOUBLE_EQ(area[0], 0.0);
  EXPECT_DOUBLE_EQ(area[255], 0.0);
  // One corner: the triangle through three edge midpoints, n = (1, 1, 1) / 8.
  EXPECT_NEAR(area[bit(0, 0, 0)], 7.0 / 8.0, 1e-12);
  EXPECT_NEAR(area[bit(1, 1, 1)], 7.0 / 8.0, 1e-12);
  // Two corners along x: a rectangle, 1 mm by half the (y, z) cell diagonal.
  EXPECT_NEAR(area[bit(0, 0, 0) | bit(1, 0, 0)], std::sqrt(2.0 * 2.0 + 3.0 * 3.0) / 2.0, 1e-12);
  // Four corners of the z = 0 face: the plane z = 1/2, 1 x 2 mm.
  EXPECT_NEAR(area[bit(0, 0, 0) | bit(1, 0, 0) | bit(0, 1, 0) | bit(1, 1, 0)], 2.0, 1e-12);
  // A corner and its three neighbours: the planar hexagon x + y + z = 3/2, n = (3, 3, 3) / 4.
  EXPECT_NEAR(area[bit(0, 0, 0) | bit(1, 0, 0) | bit(0, 1, 0) | bit(0, 0, 1)], 0.75 * 7.0, 1e-12);
  // Three corners of a face (an L): the triangle z = 1/2 (n = (0, 0, 1/2)) and the
  // planar quadrilateral x + y + z = 3/2 (n = (3, 3, 3) / 8); a fan from the
  // L's middle corner would give 3.6075 instead.
  EXPECT_NEAR(area[bit(0, 0, 0) | bit(1, 0, 0) | bit(0, 1, 0)], 1.0 + 0.375 * 7.0, 1e-12);
  // A chain along x, y, z: the planar quadrilateral with |n| = (1, 1, 1) / 2
  // and two triangles with |n| = (1, 1, 0) / 4 and (0, 1, 1) / 4.
  EXPECT_NEAR(area[bit(0, 0, 0) | bit(1, 0, 0) | bit(1, 1, 0) | bit(1, 1, 1)],
              3.5 + (std::sqrt(45.0) + std::sqrt(13.0)) / 4.0,
              1e-12);
  // Ambiguous configurations keep the corners of the smaller set apart.
  EXPECT_NEAR(area[bit(0, 0, 0) | bit(1, 1, 0)], 2 * 7.0 / 8.0, 1e-12);
  EXPECT_NEAR(area[bit(0, 0, 0) | bit(1, 1, 1)], 2 * 7.0 / 8.0, 1e-12);
  // A code and its complement have one surface.
  for (unsigned int code = 0; code < 256; ++code)
  {
    EXPECT_NEAR(area[code], area[255 - code], 1e-12) << code;
  }

  // Unit spacing: the one-corner triangle has area sqrt(3)/8.
  MaskType::SpacingType unit;
  unit.Fill(1.0);
  EXPECT_NEAR(SurfaceElementAreas(unit)[bit(0, 1, 0)], std::sqrt(3.0) / 8.0, 1e-12);
  MaskType::SpacingType bad = spacing;
  bad[1] = 0.0;
  EXPECT_THROW(SurfaceElementAreas(bad), itk::ExceptionObject);
}

TEST(RegistrationMetrics, SurfaceElementAreasOfABoxAddUpToItsChamferedSurface)
{
  // A 3 x 4 x 5 voxel box, spacing (1, 2, 3). The marching-cubes surface runs on
  // the voxel faces (at the half-voxel planes) but chamfers every box edge and
  // corner within the half voxel: flat parts (n - 1) x (m - 1) cells per face,
  // edge chamfers of (n - 1) cells of half a cell diagonal, 8 corner triangles.
  const auto   box = MakeMask({ { 9, 10, 11 } }, { { 1, 2, 3 } }, Box({ { 2, 3, 4 } }, { { 5, 7, 9 } }));
  const auto   surface = BruteSurfaceOf(box);
  const double faces = 2.0 * (2 * 3 * 1 * 2 + 2 * 4 * 1 * 3 + 3 * 4 * 2 * 3);
  const double edges = 4.0 * (2 * 1 * std::sqrt(2.0 * 2 + 3 * 3) / 2 + 3 * 2 * std::sqrt(1.0 + 3 * 3) / 2 +
                              4 * 3 * std::sqrt(1.0 + 2 * 2) / 2);
  const double corners = 8.0 * 7.0 / 8.0;
  double       total{ 0.0 };
  for (const double a : surface.areas)
  {
    total += a;
  }
  EXPECT_NEAR(total, faces + edges + corners, 1e-9); // 329.035 mm^2 (pymia: the same)
  // Less than the 378 mm^2 of the voxels' outer faces, by the chamfers.
  EXPECT_LT(total, 2.0 * (3 * 1 * 4 * 2 + 3 * 1 * 5 * 3 + 4 * 2 * 5 * 3));
  EXPECT_EQ(surface.points.size(), 4u * 5u * 6u - 2u * 3u * 4u);
}

TEST(RegistrationMetrics, Hd95TakesTheAreaWeightedPercentile)
{
  // A: 2 x 2 x 2 voxels, B: 3 x 3 x 3 voxels sharing A's low corner; spacing (1, 2, 3).
  // From B's far corners (index 5.5 against A's 4.5) to A's surface: the corner
  // (5.5, 5.5, 5.5): sqrt(1 + 4 + 9), area 7/8; the other 3 elements of the edge
  // y = z = 5.5: sqrt(4 + 9), area 7/8 + 2 sqrt(13)/2 = 4.48; the 3 elements of
  // the edge x = z = 5.5 below the corner: sqrt(1 + 9), area 7/8 + 2 sqrt(10) =
  // 7.20; everything else <= 3 mm. B's area: 88 + 4 (sqrt(13) + 2 sqrt(10) +
  // 3 sqrt(5)) + 7 = 161.55, and 5 % of it = 8.08 lies between 0.875 + 4.48 and
  // 0.875 + 4.48 + 7.20: the 95th percentile is sqrt(10). (Counting elements
  // instead, 3 of 56 from the top, would give sqrt(13).) A to B stays below 3 mm.
  const std::array<unsigned long, 3> size{ { 9, 9, 9 } };
  const std::array<double, 3>        spacing{ { 1, 2, 3 } };
  const auto a = MakeMask(size, spacing, Box({ { 3, 3, 3 } }, { { 5, 5, 5 } }));
  const auto b = MakeMask(size, spacing, Box({ { 3, 3, 3 } }, { { 6, 6, 6 } }));
  const auto scores = ComputeSurfaceDistances(a, b);
  EXPECT_NEAR(scores.hausdorff, std::sqrt(14.0), 1e-5);
  EXPECT_NEAR(scores.hausdorff95, std::sqrt(10.0), 1e-5);
  EXPECT_NEAR(ComputeSurfaceDistances(b, a).hausdorff95, std::sqrt(10.0), 1e-5);

  // A 2 x 2 x 2 cube and the same moved up one voxel (3 mm): A's bottom layer
  // of 9 elements (area 4 * 7/8 + 2 sqrt(13)/2 + 2 sqrt(10) + 2 = 15.43
  // of 62.28) is 3 mm from B, A's top face centre 1 mm (its neighbours in x are
  // on B's surface), the rest lies on B's surface.
  const auto c = MakeMask(size, spacing, Box({ { 3, 3, 4 } }, { { 5, 5, 6 } }));
  const auto shifted = ComputeSurfaceDistances(a, c);
  EXPECT_NEAR(shifted.hausdorff, 3.0, 1e-5);
  EXPECT_NEAR(shifted.hausdorff95, 3.0, 1e-5);
  const double areaA = 8 * 7.0 / 8 + 4 * (std::sqrt(13.0) / 2 + std::sqrt(10.0) + 3 * std::sqrt(5.0) / 2) +
                       2 * (6.0 + 3.0 + 2.0);
  const double bottom = 4 * 7.0 / 8 + std::sqrt(13.0) + 2 * std::sqrt(10.0) + 2.0;
  // Both directions alike: mean = (3 * bottom + 1 * 2) / areaA.
  EXPECT_NEAR(shifted.meanSurfaceDistance, (3.0 * bottom + 2.0) / areaA, 1e-5);
}

TEST(RegistrationMetrics, SurfaceDistanceRegionDropsElementsThatReadVoxelsOutsideIt)
{
  // Single voxels at x = 3 (A) and x = 4 (B), spacing (1, 2, 3); the region is x >= 4.
  // A's corners (x = 2.5 and 3.5) read voxel 3, outside the region: none is
  // scored. B's corners at x = 3.5 read voxel 3 too; those at x = 4.5 are scored
  // and lie 1 mm from A's corners at x = 3.5.
  const std::array<unsigned long, 3> size{ { 8, 8, 8 } };
  const std::array<double, 3>        spacing{ { 1, 2, 3 } };
  const auto a = MakeMask(size, spacing, [](const Index3 & i) { return i == Index3{ { 3, 4, 4 } }; });
  const auto b = MakeMask(size, spacing, [](const Index3 & i) { return i == Index3{ { 4, 4, 4 } }; });
  const auto region = MakeMask(size, spacing, [](const Index3 & i) { return i[0] >= 4; });
  const auto scores = ComputeSurfaceDistances(a, b, region);
  EXPECT_NEAR(scores.hausdorff, 1.0, 1e-6);
  EXPECT_NEAR(scores.hausdorff95, 1.0, 1e-6);
  EXPECT_NEAR(scores.meanSurfaceDistance, 1.0, 1e-6); // no element at distance 0 is scored
  // Without the region, half of the corners coincide.
  EXPECT_NEAR(ComputeSurfaceDistances(a, b).meanSurfaceDistance, 0.5, 1e-6);
}

TEST(RegistrationMetrics, SurfaceDistancesRejectEmptyAndMismatchedMasks)
{
  const auto a = MakeMask({ { 16, 16, 16 } }, { { 1, 1, 1 } }, Box({ { 4, 4, 4 } }, { { 8, 8, 8 } }));
  const auto empty = MakeMask({ { 16, 16, 16 } }, { { 1, 1, 1 } }, [](const Index3 &) { return false; });
  const auto otherSpacing = MakeMask({ { 16, 16, 16 } }, { { 1, 1, 2 } }, Box({ { 4, 4, 4 } }, { { 8, 8, 8 } }));
  const auto otherSize = MakeMask({ { 16, 16, 17 } }, { { 1, 1, 1 } }, Box({ { 4, 4, 4 } }, { { 8, 8, 8 } }));
  EXPECT_THROW(ComputeSurfaceDistances(a, empty), itk::ExceptionObject);
  EXPECT_THROW(ComputeSurfaceDistances(empty, a), itk::ExceptionObject);
  EXPECT_THROW(ComputeSurfaceDistances(empty, empty), itk::ExceptionObject);
  EXPECT_THROW(ComputeSurfaceDistances(a, otherSpacing), itk::ExceptionObject);
  EXPECT_THROW(ComputeSurfaceDistances(a, a, otherSize), itk::ExceptionObject);
  EXPECT_THROW(ComputeSurfaceDistances(nullptr, a), itk::ExceptionObject);
  EXPECT_THROW(ComputeDice(a, otherSize), itk::ExceptionObject);
  EXPECT_THROW(ComputeDice(a, a, otherSpacing), itk::ExceptionObject);
  EXPECT_THROW(ComputeDice(a, nullptr), itk::ExceptionObject);

  auto shifted = MakeMask({ { 16, 16, 16 } }, { { 1, 1, 1 } }, Box({ { 4, 4, 4 } }, { { 8, 8, 8 } }));
  MaskType::PointType origin;
  origin.Fill(0.0);
  origin[1] = 3.0;
  shifted->SetOrigin(origin);
  EXPECT_THROW(ComputeDice(a, shifted), itk::ExceptionObject);
  try
  {
    ComputeDice(a, shifted);
  }
  catch (const itk::ExceptionObject & e)
  {
    EXPECT_NE(std::string(e.GetDescription()).find("grid"), std::string::npos) << e.GetDescription();
  }
}

// ---------------------------------------------------------------- landmarks

TEST(RegistrationMetrics, LandmarkErrorsWithTranslationAndIdentity)
{
  const auto   t = Vec(2.0, -1.0, 3.5);
  const auto   field = MakeField({ { 20, 20, 20 } }, { { 2, 2, 2 } }, [&](const PointType &) { return t; });
  const std::vector<std::array<double, 3>> residual{ { { 0, 0, 0 } }, { { 3, 4, 0 } }, { { 0, 0, 1 } } };
  LandmarkListType fixed, moving;
  const double     where[3][3]{ { 5, 7, 9 }, { 20.5, 11.25, 30 }, { 33, 2, 18 } };
  for (unsigned i = 0; i < 3; ++i)
  {
    PointType p, q;
    for (unsigned d = 0; d < 3; ++d)
    {
      p[d] = where[i][d];
      q[d] = where[i][d] + t[d] + residual[i][d];
    }
    fixed.push_back(p);
    moving.push_back(q);
  }
  const auto scores = ComputeLandmarkErrors(fixed, moving, field);
  ASSERT_EQ(scores.errors.size(), 3u);
  EXPECT_NEAR(scores.errors[0], 0.0, 1e-9);
  EXPECT_NEAR(scores.errors[1], 5.0, 1e-9);
  EXPECT_NEAR(scores.errors[2], 1.0, 1e-9);
  EXPECT_NEAR(scores.mean, 2.0, 1e-9);
  EXPECT_NEAR(scores.maximum, 5.0, 1e-9);
  EXPECT_NEAR(scores.standardDeviation, std::sqrt((4.0 + 9.0 + 1.0) / 3.0), 1e-9);

  // Without a field the errors are the raw landmark distances.
  const auto raw = ComputeLandmarkErrors(fixed, moving);
  for (unsigned i = 0; i < 3; ++i)
  {
    EXPECT_NEAR(raw.errors[i], fixed[i].EuclideanDistanceTo(moving[i]), 1e-12);
  }
  EXPECT_NEAR(raw.maximum, *std::max_element(raw.errors.begin(), raw.errors.end()), 1e-12);
}

TEST(RegistrationMetrics, LandmarkErrorsRejectBadLists)
{
  PointType p;
  p.Fill(1.0);
  EXPECT_THROW(ComputeLandmarkErrors({}, {}), itk::ExceptionObject);
  EXPECT_THROW(ComputeLandmarkErrors({ p, p }, { p }), itk::ExceptionObject);
  const auto field = MakeField({ { 4, 4, 4 } }, { { 1, 1, 1 } }, [](const PointType &) { return Vec(0, 0, 0); });
  PointType  far;
  far.Fill(100.0);
  EXPECT_THROW(ComputeLandmarkErrors({ far }, { far }, field), itk::ExceptionObject);
}

// ---------------------------------------------------------------- Jacobian

TEST(RegistrationMetrics, JacobianFractionIsZeroForSmoothSmallField)
{
  const double pi = 3.14159265358979323846;
  const auto   field = MakeField({ { 24, 24, 24 } }, { { 1.5, 1.5, 1.5 } }, [&](const PointType & p) {
    return Vec(0.8 * std::sin(2 * pi * p[1] / 36.0), 0.5 * std::cos(2 * pi * p[2] / 36.0),
               0.7 * std::sin(2 * pi * (p[0] + p[1]) / 36.0));
  });
  EXPECT_DOUBLE_EQ(ComputeNonPositiveJacobianFraction(field), 0.0);
}

TEST(RegistrationMetrics, JacobianFractionCountsFoldedSlab)
{
  // u_x = -3 * clamp(x - 32, -6, 6) mm on 2 mm voxels: slope -3 (det -2) for
  // x in (26, 38), i.e. indices 14..18; at the kinks x = 26, 38 (indices 13, 19)
  // the central difference is -1.5 (det -0.5). Indices 13..19: 7 of 32 slices fold.
  const std::array<unsigned long, 3> size{ { 32, 10, 12 } };
  const std::array<double, 3>        spacing{ { 2, 1, 1 } };
  const auto field = MakeField(size, spacing, [](const PointType & p) {
    return Vec(-3.0 * std::clamp(p[0] - 32.0, -6.0, 6.0), 0, 0);
  });
  EXPECT_NEAR(ComputeNonPositiveJacobianFraction(field), 7.0 / 32.0, 1e-12);

  // Restricted to indices 0..15 the folded ones are 13..15.
  const auto region = MakeMask(size, spacing, [](const Index3 & i) { return i[0] < 16; });
  EXPECT_NEAR(ComputeNonPositiveJacobianFraction(field, region), 3.0 / 16.0, 1e-12);

  const auto wrongGrid = MakeMask({ { 32, 10, 11 } }, spacing, [](const Index3 &) { return true; });
  EXPECT_THROW(ComputeNonPositiveJacobianFraction(field, wrongGrid), itk::ExceptionObject);
  EXPECT_THROW(ComputeNonPositiveJacobianFraction(nullptr), itk::ExceptionObject);
}

// ---------------------------------------------------------------- inverse consistency

TEST(RegistrationMetrics, InverseConsistencyOfTranslationAndItsInverse)
{
  const std::array<unsigned long, 3> size{ { 20, 20, 20 } };
  const std::array<double, 3>        spacing{ { 1, 1, 1 } };
  const auto forward = MakeField(size, spacing, [](const PointType &) { return Vec(2, 0, 0); });
  const auto backward = MakeField(size, spacing, [](const PointType &) { return Vec(-2, 0, 0); });
  const auto scores = ComputeInverseConsistency(forward, backward);
  EXPECT_NEAR(scores.mean, 0.0, 1e-9);
  EXPECT_NEAR(scores.maximum, 0.0, 1e-9);
  // x + 2 stays inside the moving grid (index <= 19.5) for indices 0..17.
  EXPECT_EQ(scores.evaluatedPoints, 18u * 400u);
  EXPECT_EQ(scores.pointsOutside, 2u * 400u);

  const auto half = MakeField(size, spacing, [](const PointType &) { return Vec(-1, 0, 0.5); });
  const auto mismatched = ComputeInverseConsistency(forward, half);
  EXPECT_NEAR(mismatched.mean, std::sqrt(1.0 + 0.25), 1e-9);
  EXPECT_NEAR(mismatched.maximum, std::sqrt(1.0 + 0.25), 1e-9);

  const auto region = MakeMask(size, spacing, [](const Index3 & i) { return i[2] < 5; });
  const auto restricted = ComputeInverseConsistency(forward, backward, region);
  EXPECT_EQ(restricted.evaluatedPoints, 18u * 20u * 5u);
}

// ---------------------------------------------------------------- border margin

TEST(RegistrationMetrics, BorderMarginExcludesVoxelsNearTheEdge)
{
  // Margin 2 mm, voxel centres (i + 0.5) * spacing from the low face:
  //  axis 0, 1.0 mm: 0.5, 1.5 < 2 -> 2 voxels per side, 16 of 20 kept
  //  axis 1, 2.0 mm: 1.0 < 2      -> 1 voxel per side,  14 of 16 kept
  //  axis 2, 0.5 mm: 0.25..1.75   -> 4 voxels per side,  2 of 10 kept
  const auto grid = MakeMask({ { 20, 16, 10 } }, { { 1.0, 2.0, 0.5 } }, [](const Index3 &) { return false; });
  const auto region = MakeBorderMarginRegion(grid, 2.0);
  EXPECT_EQ(CountInside(region), 16u * 14u * 2u);
  EXPECT_EQ(region->GetPixel({ { 2, 1, 4 } }), 1);
  EXPECT_EQ(region->GetPixel({ { 17, 14, 5 } }), 1);
  EXPECT_EQ(region->GetPixel({ { 1, 1, 4 } }), 0);
  EXPECT_EQ(region->GetPixel({ { 18, 8, 5 } }), 0);
  EXPECT_EQ(region->GetPixel({ { 10, 0, 5 } }), 0);
  EXPECT_EQ(region->GetPixel({ { 10, 8, 3 } }), 0);
  EXPECT_EQ(region->GetPixel({ { 10, 8, 6 } }), 0);

  EXPECT_EQ(CountInside(MakeBorderMarginRegion(grid, 0.0)), 20u * 16u * 10u);
  EXPECT_THROW(MakeBorderMarginRegion(grid, 3.0), itk::ExceptionObject); // axis 2 vanishes
  EXPECT_THROW(MakeBorderMarginRegion(grid, -1.0), itk::ExceptionObject);
  EXPECT_THROW(MakeBorderMarginRegion(nullptr, 1.0), itk::ExceptionObject);

  // Used as a region it drops a structure lying in the margin.
  const auto inMargin = MakeMask({ { 20, 16, 10 } }, { { 1.0, 2.0, 0.5 } }, Box({ { 0, 0, 0 } }, { { 2, 16, 10 } }));
  const auto elsewhere = MakeMask({ { 20, 16, 10 } }, { { 1.0, 2.0, 0.5 } }, Box({ { 0, 0, 0 } }, { { 4, 16, 10 } }));
  EXPECT_NEAR(ComputeDice(inMargin, elsewhere), 2.0 * 2 / 6, 1e-12);
  EXPECT_NEAR(ComputeDice(inMargin, elsewhere, region), 0.0, 1e-12);
}

// ---------------------------------------------------------------- warping

TEST(RegistrationMetrics, WarpMaskAndImageFollowTheField)
{
  const std::array<unsigned long, 3> size{ { 30, 20, 20 } };
  const std::array<double, 3>        spacing{ { 2, 1, 1 } };
  // Fixed x maps to moving x + 6 mm = 3 voxels along axis 0.
  const auto field = MakeField(size, spacing, [](const PointType &) { return Vec(6, 0, 0); });
  const auto moving = MakeMask(size, spacing, Box({ { 10, 5, 5 } }, { { 20, 15, 15 } }));
  const auto expected = MakeMask(size, spacing, Box({ { 7, 5, 5 } }, { { 17, 15, 15 } }));
  const auto warped = WarpMask(moving, field);
  EXPECT_EQ(CountInside(warped), CountInside(expected));
  EXPECT_DOUBLE_EQ(ComputeDice(warped, expected), 1.0);

  // An intensity ramp I = x + 1 becomes x + 7 where x + 6 is inside the moving grid.
  auto image = ImageType::New();
  image->SetRegions(moving->GetLargestPossibleRegion());
  image->SetSpacing(moving->GetSpacing());
  image->Allocate();
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
  {
    it.Set(static_cast<float>(2.0 * it.GetIndex()[0] + 1.0));
  }
  const auto warpedImage = WarpImage(image, field, -5.0f);
  EXPECT_NEAR(warpedImage->GetPixel({ { 4, 3, 3 } }), 8.0 + 7.0, 1e-4);
  EXPECT_NEAR(warpedImage->GetPixel({ { 26, 3, 3 } }), 52.0 + 7.0, 1e-4);
  EXPECT_NEAR(warpedImage->GetPixel({ { 29, 3, 3 } }), -5.0, 1e-6); // maps beyond the moving grid
}

TEST(RegistrationMetrics, ResampleMaskOntoAnotherGrid)
{
  const auto fine = MakeMask({ { 40, 40, 40 } }, { { 1, 1, 1 } }, Box({ { 10, 10, 10 } }, { { 30, 30, 30 } }));
  // Identity grid: unchanged.
  EXPECT_DOUBLE_EQ(ComputeDice(ResampleMaskOnto(fine, fine), fine), 1.0);
  // A 2 mm grid over the same extent (voxel centres at 0.5, 2.5, ... mm).
  const auto coarseGrid = MakeMask({ { 20, 20, 20 } }, { { 2, 2, 2 } }, [](const Index3 &) { return false; });
  MaskType::PointType origin;
  origin.Fill(0.5);
  coarseGrid->SetOrigin(origin);
  const auto coarse = ResampleMaskOnto(fine, coarseGrid);
  EXPECT_TRUE(coarse->GetSpacing() == coarseGrid->GetSpacing());
  // Fine voxels 10..29 cover [9.5, 29.5] mm: coarse centres 10.5 .. 28.5, 10 per axis.
  EXPECT_EQ(CountInside(coarse), 10u * 10u * 10u);
  EXPECT_THROW(ResampleMaskOnto(fine, nullptr), itk::ExceptionObject);
}
