#pragma once
// The two damping laws of the integrator (docs/physics.md §5), one function each, used for forces
// and torques, spheres and ellipsoids alike.
#include "core/types.hpp"

namespace grainlab::kernels {

// Cundall's local damping: -alpha |f_k| sign(v_k) per component (zero where v_k = 0), the force
// (or torque) to add to f against the current mid-step velocity v (or angular velocity). One array
// expression: built component by component, it went through the stack and was read back with a
// wider load than it was written with (a store-forwarding stall, the integrator's hottest
// instructions in the profile). Multiplying by sign(v) = +-1 is exact.
GRAINLAB_ALWAYS_INLINE Vec3 localDamping(const Vec3& f, const Vec3& v, double alpha) {
  return ((-alpha) * f.array().abs() * v.array().sign()).matrix();
}

// [O]'s viscous mass/inertia-proportional damping, x'' + alpha x' = F/m and (generalised with the
// gyroscopic term) dL/dt = T - alpha L, by the midpoint rule of [O] eq. 3.27-3.28 (Cundall &
// Strack 1979): (p_new - p_old)/dt = F - alpha (p_old + p_new)/2 for a momentum p (m v or L).
struct ViscousKick {
  Vec3 momentum;      // p^(n+1/2)
  Vec3 dampingForce;  // -alpha (p_old + p_new)/2: the damping force (torque) over the step
};
inline ViscousKick viscousMidpointKick(const Vec3& momentum, const Vec3& force, double alpha, double dt) {
  const double ha = 0.5 * alpha * dt;
  ViscousKick k;
  k.momentum = ((1.0 - ha) * momentum + dt * force) / (1.0 + ha);
  k.dampingForce = -0.5 * alpha * (momentum + k.momentum);
  return k;
}

// One damped leapfrog kick of a velocity v (or a sphere's angular velocity) under the load f (or
// torque) with mass m and 1/m (or I and 1/I): [O]'s viscous midpoint kick when viscous > 0, else
// Cundall's local damping with alpha. Updates v and returns the damping force over the step.
GRAINLAB_ALWAYS_INLINE Vec3 dampedKick(Vec3& v, const Vec3& f, double m, double invM, double h, double viscous, double alpha) {
  if (viscous > 0.0) {
    const ViscousKick kick = viscousMidpointKick(m * v, f, viscous, h);
    v = kick.momentum * invM;
    return kick.dampingForce;
  }
  const Vec3 fd = localDamping(f, v, alpha);
  v += (f + fd) * (h * invM);
  return fd;
}

}  // namespace grainlab::kernels
