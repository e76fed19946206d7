#pragma once
// The shear band as a plane through the grains that deform well above the sample's homogeneous
// strain (issue 26 §2; docs/laboratory.md §3.3).
//
// Given each grain's position, its local equivalent shear strain eq (lab/kinematics.hpp: the
// best-fit deformation gradient of its neighbourhood) and whether it is in the band (eq at least
// output.band_factor times the sample's), findShearBand:
//   1. takes the load-bearing grains flagged in the band; fewer than `minGrains`, or more than
//      `maxFraction` of the load-bearing grains (then the whole sample deforms, nothing localises):
//      no band;
//   2. fits a plane to them: the centroid and the covariance of their positions, whose eigenvector
//      of the smallest eigenvalue is the band's normal. The flagged grains form a band only when
//      they lie in a slab: smallest / middle eigenvalue <= `maxFlatness` (a slab of thickness t and
//      width L gives (t/L)^2; scattered grains give about 1): otherwise no band;
//   3. builds the profile of eq across the plane (the mean eq of the load-bearing grains in bins of
//      `binWidth` along the normal) and measures the band's thickness as the profile's full width
//      at half height above the background (the median eq of the grains outside the band), with
//      the half-height crossings interpolated linearly between bins; a peak less than `minContrast`
//      times the background is no band.
// The inclination is the angle between the band's plane and the horizontal (0: horizontal, 90 deg:
// vertical), acos |n_z|. A band that is not found is nullopt (null in the summary), never a guess.
// The positions are those of a wall box; in a periodic cell a band may wrap across the faces and a
// single plane does not describe it (the report leaves it null there).
#include <cstddef>
#include <functional>
#include <optional>
#include <tuple>
#include <vector>

#include "core/types.hpp"

namespace grainlab::lab {

struct ShearBandSettings {
  double binWidth = 0.0;        // [m], d50 in the report
  std::size_t minGrains = 20;
  double maxFraction = 0.5;
  double maxFlatness = 0.25;
  double minContrast = 2.0;
};

struct ShearBand {
  Vec3 normal = Vec3::UnitZ();  // unit, n_z >= 0
  Vec3 centre = Vec3::Zero();   // the flagged grains' centroid, on the band's mid-plane [m]
  double inclinationDeg = 0.0;  // band plane to the horizontal [deg]
  double thickness = 0.0;       // full width at half height of the eq profile [m]
  double flatness = 0.0;        // smallest / middle eigenvalue of the flagged grains' covariance
  double peakStrain = 0.0, backgroundStrain = 0.0;  // of the profile [-]
  std::size_t grains = 0;       // load-bearing grains flagged in the band
  // Every field, in the order a checkpoint holds them (stateio::Listed).
  template <class Self>
  static auto fields(Self& s) {
    return std::tie(s.normal, s.centre, s.inclinationDeg, s.thickness, s.flatness, s.peakStrain, s.backgroundStrain,
                    s.grains);
  }
};

// `inBand`, `active` (empty: every grain) per grain as in GrainKinematics.
std::optional<ShearBand> findShearBand(const std::vector<Vec3>& position, const std::vector<double>& strain,
                                       const std::vector<double>& inBand, const std::vector<char>& active,
                                       const ShearBandSettings& settings);

// The void ratio inside the band (the slab |n.(x - c)| <= thickness/2) and outside it, in the
// box [lo, hi]. The solid in the slab is exact for spheres (each grain's part between the two
// planes, by the spherical caps; a non-spherical grain as its volume-equivalent sphere); the slab's
// volume within the box is integrated on a 128^3 grid of the box. Null where either part holds no
// solid.
struct BandVoidRatios {
  double inside = 0.0, outside = 0.0;
};
// `inSample` (when given) says which points of the box [lo, hi] belong to the sample (a membrane
// sample's cylinder); otherwise the whole box does.
std::optional<BandVoidRatios> bandVoidRatios(const ShearBand& band, const std::vector<Vec3>& position,
                                             const std::vector<Vec3>& semiAxes, const Vec3& lo, const Vec3& hi,
                                             const std::function<bool(const Vec3&)>& inSample = {});

}  // namespace grainlab::lab
