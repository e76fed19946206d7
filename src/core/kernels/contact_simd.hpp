#pragma once
// The linear contact laws between spheres (linear normal and tangential springs with Coulomb's
// limit; Kozicki–Donzé moments with the [W] limit on the whole moment, or [R]'s linear rolling
// resistance) evaluated several contacts at a time: Highway vectors with run-time dispatch, as core/kernels/integrate_simd.hpp.
//
// The contact driver (core/contact_driver.hpp) keeps the narrow phase's first test (the branch
// vector and whether the spheres touch) and fills a tile of touching contacts in structure-of-
// arrays form; the kernel computes geometry, parameters, kinematics, the law and the torques for
// the whole tile; the driver writes the results back to the contact list. Every lane does the IEEE
// operations of the scalar path (sphereSphere, pairParams, pairKinematics, applyLaw, storePair) in
// Eigen's order, so results are bit-identical to the scalar path on every target
// (tests/unit/test_contact_simd.cpp).
//
// Covered: sphere pairs, walls or a periodic cell, the linear law with Kozicki–Donzé moments ([W]'s
// limit, beta > 0) or with [R]'s linear rolling resistance, poisson > 0. Everything else
// (Hertz–Mindlin, YADE's separate limits, a constant Kn, ellipsoids) takes the scalar path.
#include <cstddef>

#include "contact/models.hpp"

namespace grainlab::kernels {

// One tile of touching sphere–sphere contacts, structure of arrays. Inputs are filled by the
// driver; outputs are written by sphereLawTile. Lanes past `count` up to a whole vector are padded
// by the driver with a copy of lane 0 (computed and ignored).
struct SphereLawTile {
  static constexpr std::size_t kSize = 64;  // a multiple of every vector width (8 doubles at most)
  // inputs: branch x_b - x_a, radii, velocities and spins of a and b, history, new-contact flag
  alignas(64) double branch[3][kSize];
  alignas(64) double radiusA[kSize], radiusB[kSize];
  alignas(64) double va[3][kSize], vb[3][kSize], wa[3][kSize], wb[3][kSize];
  alignas(64) double shear[3][kSize], moment[3][kSize], prevNormal[3][kSize];
  alignas(64) double fresh[kSize];  // 1: the contact forms in this step (prevNormal := normal)
  alignas(64) double muA[kSize], muB[kSize];  // the grains' rolling friction ([R]'s linear law only)
  // outputs: the list's result slots, the new history (in shear, moment, prevNormal), dissipation
  alignas(64) double force[3][kSize], torqueA[3][kSize], torqueB[3][kSize];
  alignas(64) double slip[kSize], roll[kSize];
};

// The law's constants for the step.
struct SphereLawConstants {
  double young, poisson, beta, eta, tanFriction, dt;
  // [R]'s linear rolling resistance instead of Kozicki–Donzé: Kr = Ks R^2 with R = rA rB/(rA + rB),
  // bending only, |Mr| <= mu_r R |Fn| with mu_r combined from the grains' values by `combine`.
  bool linearRolling = false;
  contact::CombineRule combine = contact::CombineRule::Min;
  // A periodic cell: the relative velocity includes the homogeneous flow across the branch, L l.
  bool periodic = false;
  Mat3 velocityGradient = Mat3::Zero();
};

// Whether the vectorised law applies to this model (see the top of this file) and a vector target
// is selected.
bool sphereLawVectorised(const contact::SphereContactModel& model);

// Computes lanes [0, count) of the tile (count <= kSize; the driver pads to a whole vector).
void sphereLawTile(const SphereLawConstants& k, SphereLawTile& t, std::size_t count);

}  // namespace grainlab::kernels
