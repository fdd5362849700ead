#include "morea/Phantom.h"

#include "morea/Error.h"
#include "morea/Random.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <thread>

namespace morea
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
InBladder(const Vec3 & x)
{
  return InEllipsoid(x, kBladderCentre[0], kBladderCentre[1], kBladderCentre[2], kBladderAxes[0], kBladderAxes[1],
                     kBladderAxes[2]);
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
InBowel(const Vec3 & x)
{
  if (x[0] < -75.0 || x[0] > 75.0)
    return false;
  // Distance to the curve, approximated in the local y-z plane (the curve is
  // nearly parallel to x): exact enough for a phantom, and cheap.
  return Square(x[1] - BowelCentreY(x[0])) + Square(x[2] - BowelCentreZ(x[0])) <= Square(13.0);
}
bool
InBowelGas(const Vec3 & x)
{
  for (double cx : { -50.0, -10.0, 30.0, 60.0 })
  {
    if (Square(x[0] - cx) + Square(x[1] - BowelCentreY(cx)) + Square(x[2] - BowelCentreZ(cx)) <= Square(5.0))
      return true;
  }
  return false;
}

void
ParallelFor(std::size_t count, const std::function<void(std::size_t)> & body)
{
  const std::size_t threads = std::max<std::size_t>(1, std::min<std::size_t>(count, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (std::size_t t = 0; t < threads; ++t)
  {
    pool.emplace_back([&, t] {
      for (std::size_t i = t; i < count; i += threads)
        body(i);
    });
  }
  for (auto & th : pool)
    th.join();
}
} // namespace

PelvisPhantom::PelvisPhantom(PhantomOptions options)
  : m_Options(options)
{
  if (!(m_Options.spacing >= 0.25 && m_Options.spacing <= 10.0))
    throw Error("phantom spacing must be in [0.25, 10] mm");
  // g'(rho) >= 1 - (k - 1) * sqrt(2) / L * exp(-1/2) outside the bladder, which is
  // positive only for k < 1 + L * exp(1/2) / sqrt(2) = 2.399 (L = 1.2); 2.35 keeps a margin.
  if (!(m_Options.bladderGrowth >= 1.0 && m_Options.bladderGrowth <= 2.35))
    throw Error("phantom bladder growth must be in [1, 2.35]"); // larger growth breaks monotonicity of g
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

// g(rho): inside the bladder (rho <= 1) a uniform growth by k; outside, the
// extra displacement decays as a Gaussian of the distance to the wall. With
// k <= 2.35 and the decay length 1.2, g' > 0 everywhere, so T is invertible.
double
PelvisPhantom::RadialProfile(double rho) const
{
  const double k = m_Options.bladderGrowth;
  if (rho <= 1.0)
    return k * rho;
  return rho + (k - 1.0) * std::exp(-Square((rho - 1.0) / kDecayLength));
}

double
PelvisPhantom::InverseRadialProfile(double rhoPrime) const
{
  // g(rho) lies between rho and k*rho, so the root is in [rho'/k, rho'].
  double lo = rhoPrime / m_Options.bladderGrowth;
  double hi = rhoPrime;
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
    u[d] = (x[d] - kBladderCentre[d]) / kBladderAxes[d];
    rho2 += u[d] * u[d];
  }
  const double rho = std::sqrt(rho2);
  const double scale = rho > 0.0 ? RadialProfile(rho) / rho : m_Options.bladderGrowth;
  Vec3         y;
  for (int d = 0; d < 3; ++d)
    y[d] = kBladderCentre[d] + kBladderAxes[d] * u[d] * scale;
  return y;
}

Vec3
PelvisPhantom::Contract(const Vec3 & y) const
{
  Vec3   u;
  double rho2 = 0.0;
  for (int d = 0; d < 3; ++d)
  {
    u[d] = (y[d] - kBladderCentre[d]) / kBladderAxes[d];
    rho2 += u[d] * u[d];
  }
  const double rho = std::sqrt(rho2);
  const double scale = rho > 0.0 ? InverseRadialProfile(rho) / rho : 1.0 / m_Options.bladderGrowth;
  Vec3         x;
  for (int d = 0; d < 3; ++d)
    x[d] = kBladderCentre[d] + kBladderAxes[d] * u[d] * scale;
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
      return InBladder(x);
    case 3:
      return InRectum(x);
    case 4:
      return InBowel(x);
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
  if (InBladder(x))
    return 5.0; // urine: low contrast to the surrounding tissue, as in CT
  if (InRectum(x))
    return InRectalGas(x) ? -900.0 : 50.0;
  if (InBowel(x))
    return InBowelGas(x) ? -800.0 : 25.0;
  if (!InBody(x, 12.0))
    return -100.0; // subcutaneous fat
  return 40.0;     // soft tissue
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
  ParallelFor(size[2], [&](std::size_t k) {
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
        c.movingImage.data[o] = inView ? static_cast<float>(HounsfieldAt(q) + nm) : OutsideFieldOfView;
        for (int d = 0; d < 3; ++d)
          c.movingToFixed.data[o][d] = q[d] - p[d];
        for (std::size_t s = 0; s < numStructures; ++s)
          c.movingMasks[s].data[o] = InStructure(s, q) ? 1 : 0;
      }
  });

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
  for (const auto & p : c.fixedLandmarks)
    c.movingLandmarks.push_back(FixedToMoving(p));
  return c;
}
} // namespace morea
