#pragma once
// The integrator as a per-particle kernel: a pure function of a view of the particle arrays
// (pointers and a size, no containers, no OpenMP, no knowledge of walls or cells beyond the flow
// map it is handed). The CPU loop (Simulation::integrateFor) calls it per particle and sums what
// it returns per chunk; a vectorised or GPU loop would call the same function (docs/architecture.md,
// "Kernels").
//
// Per particle, from the gathered force f and torque t at step n and the mid-step velocities:
//   translation  v += (f + m g + f_d) h / m  (local damping), or [O]'s viscous midpoint kick
//   rotation     spheres: w += (t + t_d) h / I, q <- exp(w h / 2) q renormalised
//                ellipsoids: the rotational leapfrog of core/rigid_rotation.hpp (Euler's equations,
//                angular momentum kept exact)
//   position     x += v h (+ M x in a periodic cell, M = exp(L h) - I)
// and the work of the damping and of gravity over the step.
#include <cmath>
#include <cstddef>

#include "core/kernels/damping.hpp"
#include "core/particles.hpp"
#include "core/rigid_rotation.hpp"
#include "core/types.hpp"

namespace grainlab::kernels {

// The arrays the integrator reads and writes, as pointers into Particles (not owned).
struct IntegratorView {
  std::size_t size = 0;
  // written
  Vec3* position = nullptr;
  Vec3* velocity = nullptr;
  Quat* orientation = nullptr;
  Vec3* angularVelocity = nullptr;
  Vec3* angularMomentum = nullptr;  // ellipsoids only
  // read
  const Vec3* force = nullptr;
  const Vec3* torque = nullptr;
  const Shape* shape = nullptr;
  const double* mass = nullptr;
  const double* invMass = nullptr;
  const double* inertia = nullptr;
  const double* invInertia = nullptr;
  const Vec3* principalInertia = nullptr;

  static IntegratorView of(Particles& p) {
    IntegratorView v;
    v.size = p.size();
    v.position = p.position.data();
    v.velocity = p.velocity.data();
    v.orientation = p.orientation.data();
    v.angularVelocity = p.angularVelocity.data();
    v.angularMomentum = p.angularMomentum.data();
    v.force = p.force.data();
    v.torque = p.torque.data();
    v.shape = p.shape.data();
    v.mass = p.mass.data();
    v.invMass = p.invMass.data();
    v.inertia = p.inertia.data();
    v.invInertia = p.invInertia.data();
    v.principalInertia = p.principalInertia.data();
    return v;
  }
};

// What is the same for every particle of a step.
struct IntegratorStep {
  double h = 0.0;               // time step [s]
  double localDamping = 0.0;    // Cundall alpha [-], used when viscousDamping is 0
  double viscousDamping = 0.0;  // [O]'s alpha [1/s]; > 0 replaces the local damping
  Vec3 gravity = Vec3::Zero();  // [m/s^2]
  bool gravityOn = false;       // gravity != 0 (its work is summed only then)
  Mat3 flowStep = Mat3::Zero(); // periodic cell: M = exp(L h) - I, the homogeneous flow of the step
};

// What one particle's step adds to the step's sums.
struct ParticleWork {
  double damping = 0.0;  // work of the damping force and torque [J] (<= 0)
  double gravity = 0.0;  // work of gravity, m g . v h [J]
};

// Advances particle i by one step (see the top of this file). Periodic: the position also follows
// the homogeneous flow of the cell.
template <bool Periodic>
GRAINLAB_ALWAYS_INLINE ParticleWork integrateParticle(const IntegratorView& p, std::size_t i, const IntegratorStep& s) {
  Vec3* const x = p.position;
  Vec3* const v = p.velocity;
  Quat* const q = p.orientation;
  Vec3* const w = p.angularVelocity;
  const double h = s.h, alpha = s.localDamping;
  const bool viscous = s.viscousDamping > 0.0;
  // Damping per component against the sign of the current (mid-step) velocity.
  const Vec3 f = p.force[i] + p.mass[i] * s.gravity;
  const Vec3 t = p.torque[i];
  Vec3 fd, td;
  const Vec3 vOld = v[i], wOld = w[i];
  // [O] eq. 3.27-3.28 (viscous), or Cundall's local damping (core/kernels/damping.hpp).
  fd = dampedKick(v[i], f, p.mass[i], p.invMass[i], h, s.viscousDamping, alpha);
  if (p.shape[i] == Shape::Ellipsoid) {
    // Distinct principal moments: the rotational leapfrog of core/rigid_rotation.hpp (Euler's
    // equations with the gyroscopic term, second order, angular momentum kept exact; local damping
    // on the torque against the mid-step spin, as for spheres).
    const rotation::LeapfrogRotation r = rotation::leapfrogRotationWithMomentum(
        q[i], w[i], p.angularMomentum[i], p.principalInertia[i], t, h,
        viscous ? rotation::Damping::Viscous : (alpha > 0.0 ? rotation::Damping::Local : rotation::Damping::None),
        viscous ? s.viscousDamping : alpha);
    td = r.dampingTorque;
    w[i] = r.step.angularVelocity;
    q[i] = r.step.orientation;
    p.angularMomentum[i] = r.angularMomentum;
  } else {
    td = dampedKick(w[i], t, p.inertia[i], p.invInertia[i], h, s.viscousDamping, alpha);
    if (w[i].squaredNorm() > 0.0) {
      // q <- exp(w dt / 2) q with the exponential to first order, renormalised (docs/physics.md §6).
      const Vec3 half = 0.5 * h * w[i];
      Quat qn = Quat(1.0, half.x(), half.y(), half.z()) * q[i];
      // |qn|^2 = 1 + eps with eps ~ |w dt|^2 / 4 (~1e-10): 1/sqrt(1 + eps) by its series
      // 1 - eps/2 + 3 eps^2/8, exact to round-off below 1e-6; the square root otherwise.
      const double eps = qn.coeffs().squaredNorm() - 1.0;
      qn.coeffs() *= std::abs(eps) < 1e-6 ? 1.0 - 0.5 * eps + 0.375 * eps * eps : 1.0 / std::sqrt(1.0 + eps);
      q[i] = qn;
    }
  }
  ParticleWork work;
  // Work of the damping forces over the step, with the mean of old and new velocities.
  work.damping = h * (fd.dot(0.5 * (vOld + v[i])) + td.dot(0.5 * (wOld + w[i])));
  if constexpr (Periodic) x[i] += v[i] * h + s.flowStep * x[i];
  else x[i] += v[i] * h;
  // Gravity's work is exact for the leapfrog: the particle moves by v h under the constant m g.
  if (s.gravityOn) work.gravity = p.mass[i] * s.gravity.dot(v[i]) * h;
  return work;
}

}  // namespace grainlab::kernels
