#pragma once
// The periodic cell ([O] §3.4.6–3.4.8, docs/physics.md §8.2): a parallelepiped whose edge vectors are the
// columns of H, deformed by a homogeneous velocity gradient L (dH/dt = L H). A particle leaving
// through a face re-enters through the opposite one; a contact with a periodic image carries the
// integer image shift s of its second body, whose image sits at x_B + H s.
//
// Particle velocities are stored relative to the homogeneous flow (the fluctuating velocity v~): a
// particle moves with x' = v~ + L x, and the relative velocity of two bodies at a contact is
// v~_B - v~_A + L (x_B + H s - x_A) plus the rotational terms. Local damping, the kinetic energy and
// the quasi-static criteria then see only the fluctuations, not the imposed deformation, and a
// particle that wraps keeps its velocity. (The term -L v~ that the fluctuating velocity would get
// from the change of the mean flow along its path is dropped: it is O(strain rate x v~), negligible
// in quasi-static flow; YADE's homothetic mode makes a similar choice.)
#include <array>
#include <cstdint>

#include "core/types.hpp"

namespace grainlab {

// Integer image shift of a contact's second body, packed into 32 bits (10 bits per axis).
struct ImageShift {
  static constexpr int kBias = 512;
  static std::uint32_t pack(int x, int y, int z) {
    return (static_cast<std::uint32_t>(x + kBias) << 20) | (static_cast<std::uint32_t>(y + kBias) << 10) |
           static_cast<std::uint32_t>(z + kBias);
  }
  static std::array<int, 3> unpack(std::uint32_t code) {
    return {static_cast<int>((code >> 20) & 1023u) - kBias, static_cast<int>((code >> 10) & 1023u) - kBias,
            static_cast<int>(code & 1023u) - kBias};
  }
  static constexpr std::uint32_t kZero = (512u << 20) | (512u << 10) | 512u;
  // Whether a shift is small enough to pack.
  static bool packable(int v) { return v > -kBias && v < kBias - 1; }
};

// How one component of the cell's deformation is driven.
enum class CellControl : std::uint8_t {
  StrainRate,  // the component of L is imposed
  Stress,      // the component of L follows the stress servo
  // Diagonal components only: L_kk = -(sum of the other diagonal components)/(number of such
  // components), so that tr L = 0 and the cell's volume is kept (det exp(L dt) = exp(tr L dt) = 1):
  // an undrained (constant-volume) test on a dry sample.
  ConstantVolume,
};

struct PeriodicCell {
  Mat3 h = Mat3::Identity();          // H: columns are the edge vectors [m]
  Mat3 hInverse = Mat3::Identity();   // H^-1, kept in step with h
  Mat3 velocityGradient = Mat3::Zero();  // L [1/s]
  // Control of the diagonal components (xx, yy, zz) and of the shear components (yz, xz, xy, as
  // Voigt indices 3, 4, 5: L_ij = L_ji = rate/2 for a symmetric rate, or simple shear when `simple`
  // is set, see below). Targets in Pa, compression positive; rates are engineering strain rates of
  // the initial length (dH_ii/dt = -rate H0_ii), compression positive.
  std::array<CellControl, 3> control{CellControl::StrainRate, CellControl::StrainRate, CellControl::StrainRate};
  Vec3 targetStress = Vec3::Zero();   // [Pa]
  Vec3 strainRate = Vec3::Zero();     // [1/s] for strain-rate components
  Vec3 referenceLength = Vec3::Ones();  // H0_ii for the engineering rates [m]
  // Shear components (yz, xz, xy): StrainRate holds the shape (no shear strain; the default),
  // Stress drives the symmetric shear strain rate so that the symmetrised shear stress meets its
  // target (e.g. zero during isotropic consolidation, so a small sample ends truly isotropic).
  std::array<CellControl, 3> shearControl{CellControl::StrainRate, CellControl::StrainRate, CellControl::StrainRate};
  Vec3 targetShearStress = Vec3::Zero();  // [Pa]
  Vec3 shearServoIntegral = Vec3::Zero();
  // Simple shear: L_xz = shearRate (dx/dt = shearRate z), the x faces tilting; 0: none.
  double shearRate = 0.0;             // [1/s]
  Vec3 servoIntegral = Vec3::Zero();  // integral term of the stress servo, as a strain rate [1/s]
  // When set, L is whatever the caller put in velocityGradient (a scripted deformation): no servo,
  // no imposed rates, the cell only follows L.
  bool prescribedGradient = false;
  // Measured every step by the contact stage (Love–Weber over the contacts, docs/physics.md §9) and
  // the affine stiffness of the assembly for the servo: K_k = (1/V) sum |l|^2 n_k^2 (kn n_k^2 +
  // ks (1 - n_k^2)), the stress change per unit compressive strain of axis k if every contact
  // deformed with the mean strain.
  Mat3 stress = Mat3::Zero();         // [Pa], full (not symmetrised) tensor, compression positive
  Vec3 stiffness = Vec3::Zero();      // [Pa]
  Vec3 shearStiffness = Vec3::Zero(); // [Pa] the same for pure shear in the yz, xz, xy planes
  // The symmetrised shear stresses (yz, xz, xy) [Pa].
  Vec3 shearStress() const {
    return {0.5 * (stress(1, 2) + stress(2, 1)), 0.5 * (stress(0, 2) + stress(2, 0)), 0.5 * (stress(0, 1) + stress(1, 0))};
  }

  void setBox(const Vec3& lengths) {
    h = lengths.asDiagonal();
    refresh();
    referenceLength = lengths;
  }
  void refresh() { hInverse = h.inverse(); }
  double volume() const { return h.determinant(); }
  // Distance between opposite faces: 1 / |row k of H^-1|.
  Vec3 widths() const {
    return {1.0 / hInverse.row(0).norm(), 1.0 / hInverse.row(1).norm(), 1.0 / hInverse.row(2).norm()};
  }
  Vec3 shiftVector(std::uint32_t code) const {
    const auto s = ImageShift::unpack(code);
    return h * Vec3(s[0], s[1], s[2]);
  }
  // The map of one step of the homogeneous flow, x <- x + M x with M = exp(L dt) - I (series to third
  // order: |L dt| is ~1e-4 or less, so the truncation is ~1e-17). The exponential, not I + L dt,
  // keeps a spin a rotation: (I + W dt) stretches every length by (1 + |W dt|^2/2) per step, which
  // over a rotation of 30 degrees is a strain of ~1e-4, far above the ~1e-6 overlaps of stiff grains.
  Mat3 flowStep(double dt) const {
    const Mat3 a = velocityGradient * dt;
    const Mat3 a2 = a * a;
    return a + 0.5 * a2 + (1.0 / 6.0) * a2 * a;
  }
  // Advances H over one step with the current L, by the same map that carries every particle with
  // the homogeneous flow, so a purely affine motion keeps scaled coordinates fixed.
  void advance(double dt) {
    h += flowStep(dt) * h;
    refresh();
  }
};

}  // namespace grainlab
