// MultiObjectiveRegistration core: a deterministic synthetic pelvis-like image
// pair with a known large deformation (a bladder that fills), for examples,
// tests and the default run. No ITK here: the ITK layer converts the volumes.
#ifndef morea_Phantom_h
#define morea_Phantom_h

#include "morea/Volume.h"

#include <cstdint>
#include <string>
#include <vector>

namespace morea
{
struct PhantomOptions
{
  double        spacing{ 2.0 };      ///< isotropic voxel size in mm
  std::uint64_t seed{ 1 };           ///< noise seed
  double        noiseSigma{ 15.0 };  ///< HU
  double        bladderGrowth{ 1.9 }; ///< linear growth of the bladder from fixed to moving
  Vec3          translation{ { 4.0, -7.0, 12.0 } }; ///< rigid part (table shift), mm
  Vec3          rotationDegrees{ { 3.0, 0.0, -2.0 } }; ///< rigid part, about x, y, z
};

/** The anatomy is defined on the fixed image (small bladder). The true mapping
 *  T from fixed to moving points is a rigid motion after a radial expansion
 *  centred on the bladder, which decays smoothly with distance so that bones
 *  hardly deform. T is a diffeomorphism with a closed-form radial profile, so
 *  both directions are exact to numerical precision.
 *  Coordinates are LPS mm: x to the patient's left, y posterior, z superior. */
class PelvisPhantom
{
public:
  explicit PelvisPhantom(PhantomOptions options = {});

  /** Structure names, in the order of the mask vectors: body, bones, bladder, rectum, bowel. */
  static const std::vector<std::string> &
  StructureNames();

  /** T(x): fixed point to moving point. */
  Vec3
  FixedToMoving(const Vec3 & x) const;
  /** T^-1(y): moving point to fixed point. */
  Vec3
  MovingToFixed(const Vec3 & y) const;

  /** Whether fixed point x lies in structure `index` (see StructureNames()). */
  bool
  InStructure(std::size_t index, const Vec3 & x) const;
  /** Noise-free CT value (HU) of the anatomy at fixed point x. */
  double
  HounsfieldAt(const Vec3 & x) const;

  /** Value written where the scanner did not see (outside a cylindrical field of view). */
  static constexpr float OutsideFieldOfView = -2048.0f;

  struct Case
  {
    Volume<float>                      fixedImage;
    Volume<float>                      movingImage;
    std::vector<Volume<std::uint8_t>>  fixedMasks;  ///< one per structure name
    std::vector<Volume<std::uint8_t>>  movingMasks;
    Volume<Vec3>                       fixedToMoving; ///< u(x) = T(x) - x on the fixed grid
    Volume<Vec3>                       movingToFixed; ///< v(y) = T^-1(y) - y on the moving grid
    std::vector<Vec3>                  fixedLandmarks;
    std::vector<Vec3>                  movingLandmarks; ///< T(fixed landmark)
  };
  /** Renders both images, masks, true fields and landmarks (multi-threaded, deterministic). */
  Case
  Generate() const;

  const PhantomOptions &
  Options() const
  {
    return m_Options;
  }

private:
  double
  RadialProfile(double rho) const; // g(rho)
  double
  InverseRadialProfile(double rhoPrime) const;
  Vec3
  Expand(const Vec3 & x) const;
  Vec3
  Contract(const Vec3 & y) const;

  PhantomOptions m_Options;
  double         m_Rotation[3][3]{};
};
} // namespace morea

#endif
