#pragma once
// One boundary-control seam for every laboratory protocol, the small-strain probe and the Python
// module: per axis a control (a stress target the boundary servoes to, an imposed strain rate, a
// fixed length, or constant volume taken up by that axis), plus the shear of a periodic cell; and
// what the boundary reports (stresses per axis and per face, lengths, volume, strains since the
// reference). The wall box and the periodic cell implement it; the servo laws live with them in the
// engine (Simulation::controlWalls / controlCell, core/servo_settings.hpp), so every protocol sets
// controls and never moves a wall itself.
//
// A control is engine state (it lives in the Wall and PeriodicCell structs, which checkpoints
// keep), so a protocol that resumes from a checkpoint finds its controls as it left them.
#include <array>
#include <memory>

#include "core/simulation.hpp"

namespace grainlab::lab {

class BoundaryControl {
 public:
  virtual ~BoundaryControl() = default;
  // The wall box or the cell of `sim`, whichever sim.boundary says.
  static std::unique_ptr<BoundaryControl> of(Simulation& sim);

  // ---- controls (axis 0 x, 1 y, 2 z) ----
  // Servo the axis's normal stress to `target` [Pa, compression positive]. Only the target changes
  // when the axis is already stress-controlled (the servo keeps what it has learnt).
  virtual void holdStress(int axis, double target) = 0;
  // Walls: servo one wall (side 0 lower, 1 upper) to its own target; a cell has one face per axis.
  virtual void holdFaceStress(int axis, int side, double target) = 0;
  // Impose an engineering strain rate of the reference length [1/s, compression positive], times
  // `factor` (a start-up ramp or a reversal): walls move at factor (rate L0/2) each, the cell's H_ii
  // at -factor rate H0_ii.
  virtual void imposeStrainRate(int axis, double rate, double factor = 1.0) = 0;
  // No strain of the axis (walls still, or L_ii = 0).
  virtual void fix(int axis) = 0;
  // The axis takes up the volume change of the others so that the volume stays at the current one
  // (several such axes share it equally).
  virtual void constantVolume(int axis) = 0;
  // Periodic cell only (walls refuse): shear components held (no shear strain; the principal axes
  // stay the cell's), servoed to zero shear stress, or simple shear L_xz = factor rate.
  virtual void holdShape() = 0;
  virtual void freeShape() = 0;
  virtual void imposeShearRate(double rate, double factor = 1.0) = 0;
  // The state strains and engineering rates are measured from: the current one (a cell also makes
  // it H0 of its engineering rates).
  virtual void setReference() = 0;
  // After a resume: the reference a test measured from (ShearState keeps it), without touching the
  // engine.
  void restoreReference(const Vec3& lengths, double volume) {
    lengths0_ = lengths;
    volume0_ = volume;
  }
  // A test starts from the current state: setReference(), and the cell's stress servos restart
  // their integral terms from zero (the rates a test needs are unrelated to those of the
  // consolidation before it); walls keep theirs (speeds, at rest after consolidation).
  virtual void beginTest() = 0;

  // ---- reports ----
  // Normal stress per axis [Pa]: the mean of the two walls, or the cell's diagonal.
  virtual Vec3 stress() const = 0;
  // Per face (index 2 axis + side); a cell reports its axis stress for both faces.
  virtual std::array<double, 6> faceStresses() const = 0;
  virtual Vec3 lengths() const = 0;
  double volume() const { return sim_.volume(); }
  // Engineering strains since the reference, compression positive, and the volumetric strain.
  Vec3 strain() const;
  double volumetricStrain() const { return (volume0_ - volume()) / volume0_; }
  const Vec3& referenceLengths() const { return lengths0_; }
  double referenceVolume() const { return volume0_; }
  bool periodic() const { return sim_.boundary == Boundary::Periodic; }
  const Simulation& simulation() const { return sim_; }

 protected:
  explicit BoundaryControl(Simulation& sim);
  Simulation& sim_;
  Vec3 lengths0_ = Vec3::Ones();
  double volume0_ = 1.0;
  static void checkAxis(int axis);
};

// Every normal stress of the boundary held at p, the cell's shear stresses servoed to zero.
void holdIsotropicStress(BoundaryControl& boundary, double pressure);

}  // namespace grainlab::lab
