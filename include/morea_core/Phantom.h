// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: a deterministic synthetic pelvis-like image
// pair with a known large deformation (a bladder that fills), for examples,
// tests and the default run. No ITK here: the ITK layer converts the volumes.
#ifndef morea_Phantom_h
#define morea_Phantom_h

#include "morea_core/Volume.h"

#include <cstdint>
#include <string>
#include <vector>

namespace morea_core
{
/** The cases of the phantom suite (PelvisPhantom::CaseNames()):
 *  - "pelvis": the bladder fills (fixed small, moving full) and the table
 *    moves; the deformation decays smoothly, so bones hardly deform;
 *  - "bladder-emptying": fixed full (270 cc), moving empty (volume ratio 11,
 *    the dome 26 mm lower); the bowel above descends into the space; bones
 *    do not move;
 *  - "gas-pocket": a gas pocket (10.5 mm radius) appears in the rectum of
 *    the moving image only, pushing the wall aside: its content has no
 *    counterpart in the fixed image; bones do not move;
 *  - "static-bones": the pelvis's bladder filling without table motion and
 *    with a deformation of bounded reach: the truth is exactly 0 on bone.
 *  The new cases carry landmarks on bone, on organ walls, inside organs and
 *  throughout the soft tissue (at least 40). */
struct PhantomOptions
{
  double        spacing{ 2.0 };      ///< isotropic voxel size in mm
  std::uint64_t seed{ 1 };           ///< noise seed
  double        noiseSigma{ 15.0 };  ///< HU
  /** Linear growth of the deforming organ from fixed to moving: the bladder
   *  (below 1 when it empties), the gas pocket in "gas-pocket". */
  double        bladderGrowth{ 1.9 };
  Vec3          translation{ { 4.0, -7.0, 12.0 } }; ///< rigid part (table shift), mm
  Vec3          rotationDegrees{ { 3.0, 0.0, -2.0 } }; ///< rigid part, about x, y, z
  std::string   caseName{ "pelvis" }; ///< one of PelvisPhantom::CaseNames()

  /** The defaults of case `name` (no rigid part except for "pelvis"); throws
   *  on an unknown name, listing the known ones. */
  static PhantomOptions
  OfCase(const std::string & name);
};

/** The anatomy is defined on the fixed image. The true mapping T from fixed
 *  to moving points is a rigid motion after a radial deformation centred on
 *  the deforming organ (its ellipsoid's normalised radius rho maps to
 *  g(rho): k rho inside, then back to rho: for "pelvis" smoothly with
 *  distance, for the other cases within a bounded reach, beyond which T is
 *  exactly the rigid part). g is monotone, so T is a diffeomorphism with a
 *  closed-form profile and both directions are exact to numerical precision.
 *  Coordinates are LPS mm: x to the patient's left, y posterior, z superior. */
class PelvisPhantom
{
public:
  explicit PelvisPhantom(PhantomOptions options = {});

  /** Structure names, in the order of the mask vectors: body, bones, bladder, rectum, bowel. */
  static const std::vector<std::string> &
  StructureNames();

  /** The cases of the suite: pelvis, bladder-emptying, gas-pocket, static-bones. */
  static const std::vector<std::string> &
  CaseNames();

  /** T(x): fixed point to moving point. */
  Vec3
  FixedToMoving(const Vec3 & x) const;
  /** T^-1(y): moving point to fixed point. */
  Vec3
  MovingToFixed(const Vec3 & y) const;

  /** Whether fixed point x lies in structure `index` (see StructureNames()). */
  bool
  InStructure(std::size_t index, const Vec3 & x) const;
  /** Noise-free CT value (HU) of the anatomy at fixed point x, as the fixed
   *  image shows it; the moving image shows MovingHounsfieldAt(x) at T(x)
   *  (the same but where content appears in the moving image only). */
  double
  HounsfieldAt(const Vec3 & x) const;
  double
  MovingHounsfieldAt(const Vec3 & x) const;

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
    /** Per landmark: "bone", "wall" (on an organ's wall), "organ" (inside
     *  one) or "soft" (soft tissue between the structures). */
    std::vector<std::string>           landmarkKinds;
  };
  /** Renders both images, masks, true fields and landmarks (multi-threaded, deterministic). */
  Case
  Generate() const;

  const PhantomOptions &
  Options() const
  {
    return m_Options;
  }

  /** Where the radial deformation acts (fixed frame): the deforming organ's
   *  ellipsoid centre and semi-axes, and the reach in units of its
   *  normalised radius (infinite for "pelvis"). */
  const Vec3 &
  DeformationCentre() const
  {
    return m_Centre;
  }
  const Vec3 &
  DeformationAxes() const
  {
    return m_Axes;
  }
  double
  DeformationReach() const
  {
    return m_Reach;
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

  std::vector<Vec3>
  SuiteLandmarks(std::vector<std::string> & kinds) const;

  PhantomOptions m_Options;
  double         m_Rotation[3][3]{};
  Vec3           m_Centre{};
  Vec3           m_Axes{};
  double         m_Reach{ 0.0 };
  Vec3           m_BladderCentre{};
  Vec3           m_BladderAxes{};
  double         m_BowelLift{ 0.0 }; ///< mm the bowel lies higher than in "pelvis"
};
} // namespace morea_core

#endif
