#include "lab/boundary_control.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "core/errors.hpp"
#include "lab/measurements.hpp"

namespace grainlab::lab {

BoundaryControl::BoundaryControl(Simulation& sim) : sim_(sim) {
  lengths0_ = sampleLengths(sim);
  volume0_ = sim.volume();
}

void BoundaryControl::checkAxis(int axis) {
  if (axis < 0 || axis > 2) throw std::invalid_argument(fmt::format("axis = {}; allowed: 0 (x), 1 (y), 2 (z)", axis));
}

Vec3 BoundaryControl::strain() const {
  const Vec3 l = lengths();
  return {(lengths0_[0] - l[0]) / lengths0_[0], (lengths0_[1] - l[1]) / lengths0_[1], (lengths0_[2] - l[2]) / lengths0_[2]};
}

namespace {

class WallBoundary final : public BoundaryControl {
 public:
  explicit WallBoundary(Simulation& sim) : BoundaryControl(sim) {}
  void holdStress(int axis, double target) override {
    checkAxis(axis);
    for (int side = 0; side < 2; ++side) holdFaceStress(axis, side, target);
  }
  void holdFaceStress(int axis, int side, double target) override {
    checkAxis(axis);
    if (side != 0 && side != 1) throw std::invalid_argument(fmt::format("side = {}; allowed: 0 (lower), 1 (upper)", side));
    Wall& w = sim_.box.walls[WallBox::index(axis, side)];
    // Under gravity the face the grains weigh on is the pedestal and stays put: were it servoed too,
    // it would carry the weight above the other face's stress and the sample would sink at the
    // servo's speed. The sample is held by the opposite face alone.
    const double g = sim_.gravity[axis];
    if ((g < 0.0 && side == 0) || (g > 0.0 && side == 1)) {
      w.control = WallControl::Fixed;
      w.velocity = 0.0;
      return;
    }
    w.control = WallControl::Stress;
    w.targetStress = target;
  }
  void imposeStrainRate(int axis, double rate, double factor) override {
    checkAxis(axis);
    const double speed = factor * (0.5 * rate * lengths0_[axis]);
    sim_.box.lower(axis).control = WallControl::Velocity;
    sim_.box.upper(axis).control = WallControl::Velocity;
    sim_.box.lower(axis).velocity = speed;
    sim_.box.upper(axis).velocity = -speed;
  }
  void fix(int axis) override {
    checkAxis(axis);
    for (Wall* w : {&sim_.box.lower(axis), &sim_.box.upper(axis)}) {
      w->control = WallControl::Fixed;
      w->velocity = 0.0;
    }
  }
  void constantVolume(int axis) override {
    checkAxis(axis);
    sim_.box.lower(axis).control = WallControl::ConstantVolume;
    sim_.box.upper(axis).control = WallControl::ConstantVolume;
    sim_.box.referenceVolume = sim_.box.volume();
  }
  void holdShape() override {}  // a box of walls keeps its principal axes
  void freeShape() override {}
  void imposeShearRate(double, double) override {
    throw InputError("simple shear needs a periodic cell (test.boundary = \"periodic\"): a wall box has no shearing walls");
  }
  void setReference() override {
    lengths0_ = lengths();
    volume0_ = volume();
  }
  void beginTest() override { setReference(); }
  Vec3 stress() const override { return {sim_.box.stress(0), sim_.box.stress(1), sim_.box.stress(2)}; }
  std::array<double, 6> faceStresses() const override {
    std::array<double, 6> s{};
    for (int k = 0; k < 6; ++k) s[k] = sim_.box.wallStress(k);
    return s;
  }
  Vec3 lengths() const override { return {sim_.box.length(0), sim_.box.length(1), sim_.box.length(2)}; }
};

class CellBoundary final : public BoundaryControl {
 public:
  explicit CellBoundary(Simulation& sim) : BoundaryControl(sim) {}
  void holdStress(int axis, double target) override {
    checkAxis(axis);
    sim_.cell.control[axis] = CellControl::Stress;
    sim_.cell.targetStress[axis] = target;
  }
  void holdFaceStress(int axis, int, double target) override { holdStress(axis, target); }
  void imposeStrainRate(int axis, double rate, double factor) override {
    checkAxis(axis);
    sim_.cell.control[axis] = CellControl::StrainRate;
    sim_.cell.strainRate[axis] = factor * rate;
  }
  void fix(int axis) override { imposeStrainRate(axis, 0.0, 1.0); }
  void constantVolume(int axis) override {
    checkAxis(axis);
    sim_.cell.control[axis] = CellControl::ConstantVolume;
  }
  void holdShape() override {
    for (int k = 0; k < 3; ++k) {
      if (sim_.cell.shearControl[k] == CellControl::Stress) sim_.cell.shearServoIntegral[k] = 0.0;
      sim_.cell.shearControl[k] = CellControl::StrainRate;
    }
  }
  void freeShape() override {
    for (int k = 0; k < 3; ++k) {
      sim_.cell.shearControl[k] = CellControl::Stress;
      sim_.cell.targetShearStress[k] = 0.0;
    }
    sim_.cell.shearRate = 0.0;
  }
  void imposeShearRate(double rate, double factor) override { sim_.cell.shearRate = factor * rate; }
  void setReference() override {
    lengths0_ = lengths();
    volume0_ = volume();
    sim_.cell.referenceLength = sim_.cell.h.diagonal();
  }
  void beginTest() override {
    setReference();
    sim_.cell.servoIntegral.setZero();
  }
  Vec3 stress() const override { return sim_.cell.stress.diagonal(); }
  std::array<double, 6> faceStresses() const override {
    std::array<double, 6> s{};
    for (int k = 0; k < 6; ++k) s[k] = sim_.cell.stress(k / 2, k / 2);
    return s;
  }
  Vec3 lengths() const override { return sim_.cell.h.diagonal(); }
};

// A cylinder between the platens (the box's z walls) in a membrane (core/membrane.hpp): axis 2 is
// the platens', axes 0 and 1 are both the membrane's one lateral stress (radial, the same for x
// and y), which can be held at a pressure or servoed to constant volume but not strained.
class MembraneBoundary final : public BoundaryControl {
 public:
  explicit MembraneBoundary(Simulation& sim) : BoundaryControl(sim), walls_(sim) {}
  void holdStress(int axis, double target) override {
    checkAxis(axis);
    if (axis == 2) return walls_.holdStress(2, target);
    // x and y are the same radial stress (a test's lateral targets are equal: io/config.cpp).
    sim_.membrane.control = MembraneControl::Pressure;
    sim_.membrane.pressure = target;
  }
  void holdFaceStress(int axis, int side, double target) override {
    if (axis == 2) return walls_.holdFaceStress(2, side, target);
    holdStress(axis, target);
  }
  void imposeStrainRate(int axis, double rate, double factor) override {
    checkAxis(axis);
    if (axis != 2) refuse("a lateral strain rate");
    // As the wall box's platens, on this boundary's reference height (walls_ keeps no reference).
    const double speed = factor * (0.5 * rate * lengths0_[2]);
    sim_.box.lower(2).control = WallControl::Velocity;
    sim_.box.upper(2).control = WallControl::Velocity;
    sim_.box.lower(2).velocity = speed;
    sim_.box.upper(2).velocity = -speed;
  }
  void fix(int axis) override {
    checkAxis(axis);
    if (axis != 2) refuse("no lateral strain");
    walls_.fix(2);
  }
  void constantVolume(int axis) override {
    checkAxis(axis);
    if (axis == 2) refuse("the platens at constant volume");
    Membrane& m = sim_.membrane;
    if (m.control != MembraneControl::ConstantVolume) m.basePressure = m.pressure;
    m.control = MembraneControl::ConstantVolume;
    m.referenceVolume = m.volume;
  }
  void holdShape() override {}
  void freeShape() override {}
  void imposeShearRate(double, double) override {
    throw InputError("simple shear needs a periodic cell (test.boundary = \"periodic\"): a membrane sample has no shearing walls");
  }
  void setReference() override {
    lengths0_ = lengths();
    volume0_ = volume();
  }
  // The sleeve is unstretched: its hoop tension counts from here. (The flexible membrane replaced
  // the rigid cylinder at the end of the preparation, Laboratory::installMembrane; a sample set up
  // otherwise gets it here.)
  void beginTest() override {
    Membrane& m = sim_.membrane;
    if (m.rigid) sim_.installFlexibleMembrane();
    setReference();
    m.referenceRadius = m.equivalentRadius();
  }
  Vec3 stress() const override {
    const double r = sim_.membrane.radialStress();
    return {r, r, 0.5 * (sim_.wallStress(WallBox::index(2, 0)) + sim_.wallStress(WallBox::index(2, 1)))};
  }
  std::array<double, 6> faceStresses() const override {
    const double r = sim_.membrane.radialStress();
    return {r, r, r, r, sim_.wallStress(WallBox::index(2, 0)), sim_.wallStress(WallBox::index(2, 1))};
  }
  // The diameter of the right cylinder of the enclosed volume, twice (x, y), and the height.
  Vec3 lengths() const override {
    const double d = 2.0 * sim_.membrane.equivalentRadius();
    return {d, d, sim_.membrane.height};
  }

 private:
  [[noreturn]] static void refuse(const char* what) {
    throw InputError(fmt::format("test.boundary = \"membrane\": a membrane cannot impose {} (it holds a lateral "
                                 "stress or a constant volume); allowed: test types whose lateral boundary holds a "
                                 "stress: isotropic, triaxial, constant-p, cyclic-triaxial, stress-path", what));
  }
  WallBoundary walls_;
};

}  // namespace

std::unique_ptr<BoundaryControl> BoundaryControl::of(Simulation& sim) {
  if (sim.boundary == Boundary::Periodic) return std::unique_ptr<BoundaryControl>(new CellBoundary(sim));
  if (sim.boundary == Boundary::Membrane) return std::unique_ptr<BoundaryControl>(new MembraneBoundary(sim));
  return std::unique_ptr<BoundaryControl>(new WallBoundary(sim));
}

void holdIsotropicStress(BoundaryControl& boundary, double pressure) {
  for (int k = 0; k < 3; ++k) boundary.holdStress(k, pressure);
  boundary.freeShape();
}

}  // namespace grainlab::lab
