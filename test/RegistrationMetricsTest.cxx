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

/** Brute force: surface voxels (inside, with a face neighbour outside or at the
 *  image edge) with their exposed face area, and all-pairs directed distances. */
struct BruteSurface
{
  std::vector<std::array<double, 3>> points; // physical (origin 0, identity direction)
  std::vector<double>                areas;
};

BruteSurface
BruteSurfaceOf(const MaskType * mask)
{
  BruteSurface s;
  const auto   size = mask->GetLargestPossibleRegion().GetSize();
  const auto   sp = mask->GetSpacing();
  const double face[3]{ sp[1] * sp[2], sp[0] * sp[2], sp[0] * sp[1] };
  for (itk::ImageRegionConstIteratorWithIndex<MaskType> it(mask, mask->GetLargestPossibleRegion()); !it.IsAtEnd();
       ++it)
  {
    if (it.Get() == 0)
    {
      continue;
    }
    const auto i = it.GetIndex();
    double     area{ 0.0 };
    for (unsigned d = 0; d < 3; ++d)
    {
      for (int step : { -1, 1 })
      {
        auto n = i;
        n[d] += step;
        if (n[d] < 0 || n[d] >= static_cast<long>(size[d]) || mask->GetPixel(n) == 0)
        {
          area += face[d];
        }
      }
    }
    if (area > 0.0)
    {
      s.points.push_back({ { i[0] * sp[0], i[1] * sp[1], i[2] * sp[2] } });
      s.areas.push_back(area);
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

  // The distance maps against an all-pairs search over the same surface voxels.
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
  // The strays carry 3 * 6 faces against the cube's 2400: far below 5 %.
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
  EXPECT_NEAR(scores.hausdorff, 4.5, 1e-4);
  EXPECT_NEAR(scores.hausdorff95, 4.5, 1e-4);
  EXPECT_NEAR(scores.meanSurfaceDistance, 4.5, 1e-4);
  // Masks made only of surface voxels, filling their whole bounding box.
  const auto c = MakeMask(size, spacing, Box({ { 0, 0, 0 } }, { { 2, 2, 2 } }));
  EXPECT_DOUBLE_EQ(ComputeSurfaceDistances(c, c).hausdorff, 0.0);
  const auto full = MakeMask(size, spacing, [](const Index3 &) { return true; });
  EXPECT_DOUBLE_EQ(ComputeSurfaceDistances(full, full).hausdorff95, 0.0);
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
