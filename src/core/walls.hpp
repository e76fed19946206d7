#pragma once
// A box of six rigid planar walls (docs/physics.md §8.1). Wall k = 2*axis + side (side 0: lower, 1: upper).
#include <array>

#include "core/types.hpp"

namespace grainlab {

// Fixed: still; Velocity: moves at `velocity`; Stress: servo to `targetStress`; ConstantVolume: the
// two walls of the axis move apart or together so that the box keeps WallBox::referenceVolume
// after the step, given how the other axes' walls move (an undrained test on a dry sample).
enum class WallControl { Fixed, Velocity, Stress, ConstantVolume };

struct Wall {
  int axis = 0;            // 0 x, 1 y, 2 z
  int side = 0;            // 0 lower (normal +axis), 1 upper (normal -axis)
  double position = 0.0;   // coordinate of the plane along its axis [m]
  double velocity = 0.0;   // [m/s], along +axis
  WallControl control = WallControl::Fixed;
  double targetStress = 0.0;   // [Pa], compression positive (Stress control)
  double tanFriction = 0.0;    // wall material friction; 0 = smooth (default, as in [W])
  double servoIntegral = 0.0;  // integral term of the stress servo, as an inward speed [m/s]
  // Measured every step by the contact stage:
  double normalForce = 0.0;    // total force pushed onto the wall by particles, >0 in compression [N]
  double contactStiffness = 0.0;  // sum of Kn of its contacts (and of their dashpots' c/dt) [N/m]
  int contacts = 0;

  // Signed distance of a point from the plane, positive on the inside of the box [m].
  double distance(const Vec3& x) const { return (x[axis] - position) * (side == 0 ? 1.0 : -1.0); }

  Vec3 inwardNormal() const {
    Vec3 n = Vec3::Zero();
    n[axis] = side == 0 ? 1.0 : -1.0;
    return n;
  }
};

struct WallBox {
  std::array<Wall, 6> walls;
  // The volume ConstantVolume walls keep [m^3] (set when the control is chosen).
  double referenceVolume = 0.0;

  static constexpr int index(int axis, int side) { return 2 * axis + side; }
  Wall& lower(int axis) { return walls[index(axis, 0)]; }
  Wall& upper(int axis) { return walls[index(axis, 1)]; }
  const Wall& lower(int axis) const { return walls[index(axis, 0)]; }
  const Wall& upper(int axis) const { return walls[index(axis, 1)]; }

  void setBounds(const Vec3& lo, const Vec3& hi) {
    for (int a = 0; a < 3; ++a) {
      walls[index(a, 0)].axis = a;
      walls[index(a, 0)].side = 0;
      walls[index(a, 0)].position = lo[a];
      walls[index(a, 1)].axis = a;
      walls[index(a, 1)].side = 1;
      walls[index(a, 1)].position = hi[a];
    }
  }
  double length(int axis) const { return upper(axis).position - lower(axis).position; }
  double area(int axis) const { return length((axis + 1) % 3) * length((axis + 2) % 3); }
  double volume() const { return length(0) * length(1) * length(2); }
  // Wall stress along an axis: mean of the two opposing walls' force over the current area [Pa].
  double stress(int axis) const {
    return 0.5 * (lower(axis).normalForce + upper(axis).normalForce) / area(axis);
  }
  double wallStress(int k) const { return walls[k].normalForce / area(walls[k].axis); }
  Vec3 lowerCorner() const { return {lower(0).position, lower(1).position, lower(2).position}; }
  Vec3 upperCorner() const { return {upper(0).position, upper(1).position, upper(2).position}; }
};

}  // namespace grainlab
