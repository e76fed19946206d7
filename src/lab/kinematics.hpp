#pragma once
// Grain kinematics since a reference state (docs/laboratory.md §3.3): displacement, rotation, local strain
// and the shear band.
//
// Local strain: for each grain, the displacement gradient G that best maps the reference
// branch vectors to its neighbours (reference distance <= neighbourhood radius) onto their relative
// displacements, in the least-squares sense; F = I + G, Green–Lagrange E = (F^T F - I)/2 (zero for
// any rigid motion), and the equivalent shear strain eq = sqrt(2/3 e:e) of its deviator e.
// A grain is in the shear band when its eq is at least `bandFactor` times the eq of the box's own
// (homogeneous) strain: localisation means grains deforming well above the average.
// In a periodic cell neighbours are found across the faces too: the image of a neighbour in the
// reference cell moves with its own displacement plus the cell's deformation of the image shift.
// Rotation statistics and the band fraction count only grains that take part in the load-bearing
// network (`active`, e.g. at least two contacts): a rattler touches nothing, feels no damping and
// keeps whatever spin it had, which says nothing about the band.
#include <vector>

#include "core/simulation.hpp"
#include "lab/grain_records.hpp"

namespace grainlab::lab {

struct GrainKinematics {
  std::vector<Vec3> displacement;       // [m]
  std::vector<double> rotationDeg;      // angle of the composed rotation since the reference [deg]
  std::vector<double> localShearStrain; // eq of the local Green–Lagrange strain [-]
  std::vector<double> inBand;           // 1 in the band, 0 outside
  std::vector<char> active;             // the load-bearing grains counted (empty: every grain)
  double boxShearStrain = 0.0;
  // Means over the active grains, overall, inside and outside the band, and the band's fraction of
  // them; NaN (not measured) over no grain, and the last three NaN while boxShearStrain = 0 (no
  // band criterion without a homogeneous strain).
  double rotationMeanDeg = 0.0;
  double rotationBandMeanDeg = 0.0;
  double rotationOutsideMeanDeg = 0.0;
  double bandFraction = 0.0;
  // The population standard deviation of the rotations inside and outside the band (NaN below two
  // grains, and while there is no band criterion).
  double rotationBandStdDeg = 0.0, rotationOutsideStdDeg = 0.0;
};

// Equivalent shear strain sqrt(2/3 e:e) of the deviator of a strain tensor.
double equivalentShearStrain(const Mat3& strain);

// `boxStrain`: the sample's homogeneous Green–Lagrange strain; `radius`: neighbourhood radius [m];
// `bandFactor`: threshold on eq / eq_box; `active`: grains counted in the statistics (empty: all).
GrainKinematics grainKinematics(const Simulation& sim, const GrainRecords& records, const Mat3& boxStrain,
                                double radius, double bandFactor = 2.0, const std::vector<char>& active = {});

}  // namespace grainlab::lab
