// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/Phantom.h"

#include "morea_core/Error.h"
#include "morea_core/Random.h"
#include "morea_core/ParallelForThreads.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace morea_core
{
namespace
{
// Domain and anatomy, in mm (fixed image frame).
constexpr double kDomainMin[3] = { -170.0, -120.0, -80.0 };
constexpr double kDomainMax[3] = { 170.0, 120.0, 70.0 };
constexpr double kFieldOfViewRadius = 180.0;

constexpr double kBladderCentre[3] = { 0.0, -25.0, -15.0 };
constexpr double kBladderAxes[3] = { 28.0, 22.0, 20.0 };
constexpr double kDecayLength = 1.2; // in units of the bladder's normalised radius

// "bladder-emptying": the full bladder of the fixed image, and how far the
// bowel lies higher to rest on its dome.
constexpr double kFullBladderCentre[3] = { 0.0, -28.0, -12.0 };
constexpr double kFullBladderAxes[3] = { 42.0, 32.0, 48.0 };
constexpr double kFullBladderBowelLift = 8.0;
// "gas-pocket": the rectal content (3 mm radius) that becomes a gas pocket.
constexpr double kPocketCentre[3] = { 0.0, 22.0, 12.0 };
constexpr double kPocketRadius = 3.0;
// Bounded reach of the deformation, in units of the organ's normalised radius.
constexpr double kEmptyingReach = 1.6;
constexpr double kStaticBonesReach = 2.4;
constexpr double kPocketReach = 6.0;
constexpr double kRectalGasHu = -900.0;

double
Square(double x)
{
  return x * x;
}

bool
InEllipsoid(const Vec3 & x, double cx, double cy, double cz, double ax, double ay, double az)
{
  return Square((x[0] - cx) / ax) + Square((x[1] - cy) / ay) + Square((x[2] - cz) / az) <= 1.0;
}

bool
InBody(const Vec3 & x, double shrink = 0.0)
{
  return Square(x[0] / (160.0 - shrink)) + Square(x[1] / (110.0 - shrink)) <= 1.0;
}

bool
InBones(const Vec3 & x)
{
  for (double side : { -1.0, 1.0 })
  {
    // Femoral head, femoral shaft, iliac wing.
    if (InEllipsoid(x, side * 90.0, 0.0, -35.0, 22.0, 22.0, 22.0))
      return true;
    if (x[2] < -35.0 && Square(x[0] - side * 100.0) + Square(x[1]) <= Square(14.0))
      return true;
    if (InEllipsoid(x, side * 98.0, 20.0, 25.0, 12.0, 40.0, 38.0))
      return true;
  }
  return InEllipsoid(x, 0.0, 85.0, 15.0, 38.0, 14.0, 45.0) || // sacrum
         InEllipsoid(x, 0.0, -88.0, -50.0, 28.0, 8.0, 12.0);  // pubic symphysis
}

bool
InBladder(const Vec3 & x, const Vec3 & c, const Vec3 & a)
{
  return InEllipsoid(x, c[0], c[1], c[2], a[0], a[1], a[2]);
}

bool
InRectum(const Vec3 & x)
{
  return x[2] <= 30.0 && Square(x[0]) + Square(x[1] - 22.0) <= Square(15.0);
}

bool
InRectalGas(const Vec3 & x)
{
  return x[2] >= -40.0 && x[2] <= 0.0 && Square(x[0]) + Square(x[1] - 22.0) <= Square(6.0);
}

// Bowel loop: a tube of radius 13 mm around a wavy centre line above the bladder.
double
BowelCentreY(double x)
{
  return -20.0 + 25.0 * std::sin(x / 25.0);
}
double
BowelCentreZ(double x)
{
  return 35.0 + 8.0 * std::cos(x / 18.0);
}
bool
InBowel(const Vec3 & x, double lift)
{
  if (x[0] < -75.0 || x[0] > 75.0)
    return false;
  // Distance to the curve, approximated in the local y-z plane (the curve is
  // nearly parallel to x): exact enough for a phantom, and cheap.
  return Square(x[1] - BowelCentreY(x[0])) + Square(x[2] - (BowelCentreZ(x[0]) + lift)) <= Square(13.0);
}
bool
InBowelGas(const Vec3 & x, double lift)
{
  for (double cx : { -50.0, -10.0, 30.0, 60.0 })
  {
    if (Square(x[0] - cx) + Square(x[1] - BowelCentreY(cx)) + Square(x[2] - (BowelCentreZ(cx) + lift)) <= Square(5.0))
      return true;
  }
  return false;
}

} // namespace

PhantomOptions
PhantomOptions::OfCase(const std::string & name)
{
  const auto & names = PelvisPhantom::CaseNames();
  if (std::find(names.begin(), names.end(), name) == names.end())
  {
    std::string known;
    for (const auto & n : names)
      known += (known.empty() ? "" : ", ") + n;
    throw Error("unknown phantom case " + name + " (known: " + known + ")");
  }
  PhantomOptions o;
  o.caseName = name;
  if (name == "pelvis")
    return o;
  o.translation = { { 0.0, 0.0, 0.0 } };
  o.rotationDegrees = { { 0.0, 0.0, 0.0 } };
  o.bladderGrowth = name == "bladder-emptying" ? 0.45 : name == "gas-pocket" ? 3.5 : 1.7;
  return o;
}

PelvisPhantom::PelvisPhantom(PhantomOptions options)
  : m_Options(options)
{
  if (!(m_Options.spacing >= 0.25 && m_Options.spacing <= 10.0))
    throw Error("phantom spacing must be in [0.25, 10] mm");
  PhantomOptions::OfCase(m_Options.caseName); // known name
  const std::string & name = m_Options.caseName;
  const double        k = m_Options.bladderGrowth;
  m_BladderCentre = { { kBladderCentre[0], kBladderCentre[1], kBladderCentre[2] } };
  m_BladderAxes = { { kBladderAxes[0], kBladderAxes[1], kBladderAxes[2] } };
  m_Centre = m_BladderCentre;
  m_Axes = m_BladderAxes;
  m_Reach = std::numeric_limits<double>::infinity();
  if (name == "pelvis")
  {
    // g'(rho) >= 1 - (k - 1) * sqrt(2) / L * exp(-1/2) outside the bladder, which is
    // positive only for k < 1 + L * exp(1/2) / sqrt(2) = 2.399 (L = 1.2); 2.35 keeps a margin.
    if (!(k >= 1.0 && k <= 2.35))
      throw Error("phantom bladder growth must be in [1, 2.35]"); // larger growth breaks monotonicity of g
  }
  else if (name == "bladder-emptying")
  {
    m_BladderCentre = { { kFullBladderCentre[0], kFullBladderCentre[1], kFullBladderCentre[2] } };
    m_BladderAxes = { { kFullBladderAxes[0], kFullBladderAxes[1], kFullBladderAxes[2] } };
    m_Centre = m_BladderCentre;
    m_Axes = m_BladderAxes;
    m_Reach = kEmptyingReach;
    m_BowelLift = kFullBladderBowelLift;
    if (!(k >= 0.3 && k <= 1.0))
      throw Error("phantom bladder growth of bladder-emptying must be in [0.3, 1]");
  }
  else
  {
    if (name == "gas-pocket")
    {
      m_Centre = { { kPocketCentre[0], kPocketCentre[1], kPocketCentre[2] } };
      m_Axes = { { kPocketRadius, kPocketRadius, kPocketRadius } };
    }
    m_Reach = name == "gas-pocket" ? kPocketReach : kStaticBonesReach;
    // Growth within a bounded reach: g'(rho) >= 1 - (k - 1) pi / (2 (reach - 1)),
    // kept at 0.05 or more.
    const double largest = 1.0 + 0.95 * 2.0 * (m_Reach - 1.0) / M_PI;
    if (!(k >= 1.0 && k <= largest))
      throw Error("phantom growth of " + name + " must be in [1, " + std::to_string(largest) + "]");
  }
  if (!(m_Options.noiseSigma >= 0.0))
    throw Error("phantom noise must be non-negative");
  // R = Rz * Ry * Rx.
  const double a = m_Options.rotationDegrees[0] * M_PI / 180.0;
  const double b = m_Options.rotationDegrees[1] * M_PI / 180.0;
  const double c = m_Options.rotationDegrees[2] * M_PI / 180.0;
  const double rx[3][3] = { { 1, 0, 0 }, { 0, std::cos(a), -std::sin(a) }, { 0, std::sin(a), std::cos(a) } };
  const double ry[3][3] = { { std::cos(b), 0, std::sin(b) }, { 0, 1, 0 }, { -std::sin(b), 0, std::cos(b) } };
  const double rz[3][3] = { { std::cos(c), -std::sin(c), 0 }, { std::sin(c), std::cos(c), 0 }, { 0, 0, 1 } };
  double       ryx[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      ryx[i][j] = 0;
      for (int k = 0; k < 3; ++k)
        ryx[i][j] += ry[i][k] * rx[k][j];
    }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      m_Rotation[i][j] = 0;
      for (int k = 0; k < 3; ++k)
        m_Rotation[i][j] += rz[i][k] * ryx[k][j];
    }
}

const std::vector<std::string> &
PelvisPhantom::StructureNames()
{
  static const std::vector<std::string> names = { "body", "bones", "bladder", "rectum", "bowel" };
  return names;
}

const std::vector<std::string> &
PelvisPhantom::CaseNames()
{
  static const std::vector<std::string> names = { "pelvis", "bladder-emptying", "gas-pocket", "static-bones" };
  return names;
}

// g(rho): inside the bladder (rho <= 1) a uniform growth by k; outside, the
// extra displacement decays as a Gaussian of the distance to the wall. With
// k <= 2.35 and the decay length 1.2, g' > 0 everywhere, so T is invertible.
// Within a bounded reach R (the other cases) the extra displacement fades as
// (1 + cos(pi (rho - 1) / (R - 1))) / 2 and is exactly 0 from R on.
double
PelvisPhantom::RadialProfile(double rho) const
{
  const double k = m_Options.bladderGrowth;
  if (rho <= 1.0)
    return k * rho;
  if (std::isinf(m_Reach))
    return rho + (k - 1.0) * std::exp(-Square((rho - 1.0) / kDecayLength));
  if (rho >= m_Reach)
    return rho;
  return rho + (k - 1.0) * 0.5 * (1.0 + std::cos(M_PI * (rho - 1.0) / (m_Reach - 1.0)));
}

double
PelvisPhantom::InverseRadialProfile(double rhoPrime) const
{
  // g(rho) lies between rho and k*rho, so the root is between rho'/k and rho'.
  double lo = std::min(rhoPrime / m_Options.bladderGrowth, rhoPrime);
  double hi = std::max(rhoPrime / m_Options.bladderGrowth, rhoPrime);
  for (int i = 0; i < 60 && hi - lo > 1e-13 * std::max(1.0, hi); ++i)
  {
    const double mid = 0.5 * (lo + hi);
    (RadialProfile(mid) < rhoPrime ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Vec3
PelvisPhantom::Expand(const Vec3 & x) const
{
  Vec3   u;
  double rho2 = 0.0;
  for (int d = 0; d < 3; ++d)
  {
    u[d] = (x[d] - m_Centre[d]) / m_Axes[d];
    rho2 += u[d] * u[d];
  }
  const double rho = std::sqrt(rho2);
  if (rho >= m_Reach)
    return x; // exactly: beyond the reach nothing deforms
  const double scale = rho > 0.0 ? RadialProfile(rho) / rho : m_Options.bladderGrowth;
  Vec3         y;
  for (int d = 0; d < 3; ++d)
    y[d] = m_Centre[d] + m_Axes[d] * u[d] * scale;
  return y;
}

Vec3
PelvisPhantom::Contract(const Vec3 & y) const
{
  Vec3   u;
  double rho2 = 0.0;
  for (int d = 0; d < 3; ++d)
  {
    u[d] = (y[d] - m_Centre[d]) / m_Axes[d];
    rho2 += u[d] * u[d];
  }
  const double rho = std::sqrt(rho2);
  if (rho >= m_Reach)
    return y;
  const double scale = rho > 0.0 ? InverseRadialProfile(rho) / rho : 1.0 / m_Options.bladderGrowth;
  Vec3         x;
  for (int d = 0; d < 3; ++d)
    x[d] = m_Centre[d] + m_Axes[d] * u[d] * scale;
  return x;
}

Vec3
PelvisPhantom::FixedToMoving(const Vec3 & x) const
{
  const Vec3 e = Expand(x);
  Vec3       y;
  for (int i = 0; i < 3; ++i)
  {
    y[i] = m_Options.translation[i];
    for (int j = 0; j < 3; ++j)
      y[i] += m_Rotation[i][j] * e[j];
  }
  return y;
}

Vec3
PelvisPhantom::MovingToFixed(const Vec3 & y) const
{
  Vec3 e;
  for (int i = 0; i < 3; ++i)
  {
    e[i] = 0.0;
    for (int j = 0; j < 3; ++j)
      e[i] += m_Rotation[j][i] * (y[j] - m_Options.translation[j]); // R^T (y - t)
  }
  return Contract(e);
}

bool
PelvisPhantom::InStructure(std::size_t index, const Vec3 & x) const
{
  switch (index)
  {
    case 0:
      return InBody(x);
    case 1:
      return InBones(x);
    case 2:
      return InBladder(x, m_BladderCentre, m_BladderAxes);
    case 3:
      return InRectum(x);
    case 4:
      return InBowel(x, m_BowelLift);
    default:
      throw Error("phantom structure index out of range");
  }
}

double
PelvisPhantom::HounsfieldAt(const Vec3 & x) const
{
  if (!InBody(x))
    return -1000.0; // air
  if (InBones(x))
  {
    // Trabecular texture, fixed to the bone: gives intensity-based alignment
    // something to hold on to inside the bone, as real marrow does.
    return 550.0 + 250.0 * std::sin(x[0] / 1.7) * std::sin(x[1] / 1.3 + 0.5) * std::sin(x[2] / 1.9 + 1.0);
  }
  if (InBladder(x, m_BladderCentre, m_BladderAxes))
    return 5.0; // urine: low contrast to the surrounding tissue, as in CT
  if (InRectum(x))
    return InRectalGas(x) ? kRectalGasHu : 50.0;
  if (InBowel(x, m_BowelLift))
    return InBowelGas(x, m_BowelLift) ? -800.0 : 25.0;
  if (!InBody(x, 12.0))
    return -100.0; // subcutaneous fat
  return 40.0;     // soft tissue
}

double
PelvisPhantom::MovingHounsfieldAt(const Vec3 & x) const
{
  // The rectal content that becomes the gas pocket: gas in the moving image only.
  if (m_Options.caseName == "gas-pocket" &&
      InEllipsoid(x, m_Centre[0], m_Centre[1], m_Centre[2], m_Axes[0], m_Axes[1], m_Axes[2]))
    return kRectalGasHu;
  return HounsfieldAt(x);
}

PelvisPhantom::Case
PelvisPhantom::Generate() const
{
  const double               h = m_Options.spacing;
  std::array<std::size_t, 3> size;
  for (int d = 0; d < 3; ++d)
    size[d] = static_cast<std::size_t>(std::floor((kDomainMax[d] - kDomainMin[d]) / h)) + 1;
  const Vec3 spacing{ { h, h, h } };
  const Vec3 origin{ { kDomainMin[0], kDomainMin[1], kDomainMin[2] } };

  Case c;
  c.fixedImage = Volume<float>(size, spacing, origin);
  c.movingImage = c.fixedImage;
  c.fixedToMoving = c.fixedImage.Like<Vec3>();
  c.movingToFixed = c.fixedImage.Like<Vec3>();
  const std::size_t numStructures = StructureNames().size();
  c.fixedMasks.assign(numStructures, c.fixedImage.Like<std::uint8_t>());
  c.movingMasks = c.fixedMasks;

  // One pass per image; slices in parallel, noise seeded per slice so the
  // result does not depend on the number of threads.
  ParallelForOnNewThreads(size[2], [&](std::size_t k) {
    RandomGenerator fixedNoise(HashCombine(m_Options.seed, 2 * k));
    RandomGenerator movingNoise(HashCombine(m_Options.seed, 2 * k + 1));
    for (std::size_t j = 0; j < size[1]; ++j)
      for (std::size_t i = 0; i < size[0]; ++i)
      {
        const Vec3        p = c.fixedImage.PointAt(i, j, k);
        const std::size_t o = c.fixedImage.Offset(i, j, k);
        const bool        inView = Square(p[0]) + Square(p[1]) <= Square(kFieldOfViewRadius);
        // Fixed image: anatomy at p.
        const double nf = fixedNoise.Normal() * m_Options.noiseSigma;
        c.fixedImage.data[o] = inView ? static_cast<float>(HounsfieldAt(p) + nf) : OutsideFieldOfView;
        const Vec3 tp = FixedToMoving(p);
        for (int d = 0; d < 3; ++d)
          c.fixedToMoving.data[o][d] = tp[d] - p[d];
        for (std::size_t s = 0; s < numStructures; ++s)
          c.fixedMasks[s].data[o] = InStructure(s, p) ? 1 : 0;
        // Moving image: the anatomy that T carried to p.
        const Vec3   q = MovingToFixed(p);
        const double nm = movingNoise.Normal() * m_Options.noiseSigma;
        c.movingImage.data[o] = inView ? static_cast<float>(MovingHounsfieldAt(q) + nm) : OutsideFieldOfView;
        for (int d = 0; d < 3; ++d)
          c.movingToFixed.data[o][d] = q[d] - p[d];
        for (std::size_t s = 0; s < numStructures; ++s)
          c.movingMasks[s].data[o] = InStructure(s, q) ? 1 : 0;
      }
  });

  if (m_Options.caseName != "pelvis")
  {
    c.fixedLandmarks = SuiteLandmarks(c.landmarkKinds);
    for (const auto & p : c.fixedLandmarks)
      c.movingLandmarks.push_back(FixedToMoving(p));
    return c;
  }
  // Landmarks on stable bones and on the deforming organs.
  const double bc[3] = { kBladderCentre[0], kBladderCentre[1], kBladderCentre[2] };
  c.fixedLandmarks = {
    { -90.0, 0.0, -35.0 },                        // right femoral head centre
    { 90.0, 0.0, -35.0 },                         // left femoral head centre
    { -90.0, 0.0, -13.5 },                        // right femoral head top
    { 90.0, 0.0, -13.5 },                         // left femoral head top
    { 0.0, 85.0, 15.0 },                          // sacrum
    { 0.0, 85.0, -25.0 },                         // sacrum, inferior
    { 0.0, -88.0, -50.0 },                        // pubic symphysis
    { -98.0, 20.0, 25.0 },                        // right iliac wing
    { 98.0, 20.0, 25.0 },                         // left iliac wing
    { bc[0], bc[1], bc[2] + 19.0 },               // bladder dome
    { bc[0], bc[1] - 21.0, bc[2] },               // bladder anterior wall
    { bc[0] - 27.0, bc[1], bc[2] },               // bladder right wall
    { bc[0] + 27.0, bc[1], bc[2] },               // bladder left wall
    { 0.0, 22.0, -40.0 },                         // rectum, inferior
    { 0.0, 22.0, -10.0 },                         // rectum, middle
    { 0.0, 22.0, 20.0 },                          // rectum, superior
    { -40.0, BowelCentreY(-40.0), BowelCentreZ(-40.0) }, // bowel loop
    { 0.0, BowelCentreY(0.0), BowelCentreZ(0.0) },
    { 40.0, BowelCentreY(40.0), BowelCentreZ(40.0) },
  };
  c.landmarkKinds.assign(9, "bone");
  c.landmarkKinds.resize(13, "wall");
  c.landmarkKinds.resize(c.fixedLandmarks.size(), "organ");
  for (const auto & p : c.fixedLandmarks)
    c.movingLandmarks.push_back(FixedToMoving(p));
  return c;
}

std::vector<Vec3>
PelvisPhantom::SuiteLandmarks(std::vector<std::string> & kinds) const
{
  std::vector<Vec3> points;
  const auto        add = [&](const Vec3 & p, const char * kind) {
    points.push_back(p);
    kinds.emplace_back(kind);
  };
  // Bone: femoral heads, shafts, iliac wings, sacrum, pubic symphysis.
  for (double side : { -1.0, 1.0 })
  {
    add({ { side * 90.0, 0.0, -35.0 } }, "bone");
    add({ { side * 90.0, 0.0, -16.0 } }, "bone");
    add({ { side * 100.0, 0.0, -60.0 } }, "bone");
    add({ { side * 98.0, 20.0, 25.0 } }, "bone");
    add({ { side * 98.0, 20.0, 50.0 } }, "bone");
    add({ { side * 15.0, -88.0, -50.0 } }, "bone");
  }
  add({ { 0.0, 85.0, 15.0 } }, "bone");
  add({ { 0.0, 85.0, -20.0 } }, "bone");
  add({ { 0.0, -88.0, -50.0 } }, "bone");
  // Walls: the bladder's along its axes and diagonals (the deforming wall,
  // but in "gas-pocket"), and the rectum's around the gas pocket.
  const Vec3 & bc = m_BladderCentre;
  const Vec3 & ba = m_BladderAxes;
  for (int a = 0; a < 3; ++a)
    for (double side : { -1.0, 1.0 })
    {
      Vec3 p = bc;
      p[a] += side * ba[a];
      add(p, "wall");
    }
  for (double sx : { -1.0, 1.0 })
    for (double sy : { -1.0, 1.0 })
      for (double sz : { -1.0, 1.0 })
        add({ { bc[0] + sx * ba[0] / std::sqrt(3.0), bc[1] + sy * ba[1] / std::sqrt(3.0),
                bc[2] + sz * ba[2] / std::sqrt(3.0) } },
            "wall");
  for (double angle : { 0.0, 0.5 * M_PI, M_PI, 1.5 * M_PI })
    add({ { 15.0 * std::cos(angle), 22.0 + 15.0 * std::sin(angle), kPocketCentre[2] } }, "wall");
  // Inside organs: the rectum's and the bowel's centre lines (and the gas pocket).
  for (double z : { -40.0, -10.0, 20.0 })
    add({ { 0.0, 22.0, z } }, "organ");
  for (double x : { -40.0, 0.0, 40.0 })
    add({ { x, BowelCentreY(x), BowelCentreZ(x) + m_BowelLift } }, "organ");
  if (m_Options.caseName == "gas-pocket")
    add(m_Centre, "organ");
  // Soft tissue: a grid through the body, 5 mm or more from every structure.
  const auto clearOfStructures = [&](const Vec3 & p) {
    if (!InBody(p, 15.0))
      return false;
    for (int a = 0; a < 3; ++a)
      for (double step : { -5.0, 0.0, 5.0 })
      {
        Vec3 q = p;
        q[a] += step;
        for (std::size_t s = 1; s < StructureNames().size(); ++s)
          if (InStructure(s, q))
            return false;
      }
    return true;
  };
  for (double z : { -65.0, -25.0, 15.0, 55.0 })
    for (double y : { -80.0, -50.0, 50.0 })
      for (double x : { -120.0, -60.0, -30.0, 30.0, 60.0, 120.0 })
        if (clearOfStructures({ { x, y, z } }))
          add({ { x, y, z } }, "soft");
  return points;
}
} // namespace morea_core
