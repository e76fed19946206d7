#pragma once
// Rotation of a rigid body with distinct principal moments (docs/physics.md §6; docs/ellipsoids.md):
// pure kernels for the engine's leapfrog, which keeps the orientation q^n at full steps and the
// world-frame angular velocity w^(n-1/2) at mid-steps.
//
// Scheme: leapfrog in the world-frame angular momentum L with an implicit midpoint rotation on
// SO(3) (the exponential-map form of Omelyan's implicit quaternion leapfrog, Omelyan 1998):
//     L^(n+1/2) = L^(n-1/2) + dt T^n                                  (kick, exact for L)
//     w = R(q*) I^-1 R(q*)^T L^(n+1/2),  q* = exp(w dt/2) q^n          (solved by fixed point)
//     q^(n+1) = exp(w dt) q^n,           w^(n+1/2) := w
// Euler's equations with the gyroscopic term are integrated implicitly: in the world frame L is
// constant between kicks and the body turns under it. Properties: second order, time-reversible,
// world L conserved exactly by a torque-free step, unit quaternion kept (exact exponential,
// renormalised to round-off). The stored w^(n+1/2) is the mean angular velocity over the step
// (q^(n+1) q^n* is the rotation by w dt), which is what the contact kinematics and the rotation
// path need, and no extra state is needed: L^(n+1/2) is rebuilt from (q^(n+1), w^(n+1/2))
// because the midpoint orientation is exp(-w dt/2) q^(n+1) (to round-off; an engine may store L
// instead). For equal moments it is the engine's sphere update (with the exact exponential).
#include <cmath>
#include <limits>

#include "core/types.hpp"
#include "core/kernels/damping.hpp"

namespace grainlab::rotation {

// Unit quaternion of the rotation by the rotation vector theta (angle |theta| about its axis).
// Below |theta| = 0.1 the half-angle functions come from their series, exact to round-off there.
inline Quat rotationQuaternion(const Vec3& theta) {
  const double a2 = theta.squaredNorm();
  double c, s;  // cos(|theta|/2), sin(|theta|/2)/|theta|
  if (a2 < 1e-6) {
    // A DEM step (|theta| < 1e-3): three terms leave x^3/720 < 2e-20; the shorter polynomial
    // shortens the dependency chain of the rotation fixed point.
    constexpr double c1 = -1.0 / 2, c2 = 1.0 / 24, s1 = -1.0 / 6, s2 = 1.0 / 120;
    const double x = 0.25 * a2;
    c = 1.0 + x * (c1 + x * c2);
    s = 0.5 * (1.0 + x * (s1 + x * s2));
  } else if (a2 < 1e-2) {
    // Taylor coefficients as constants: a division by a literal is not turned into a
    // multiplication (it would round differently), and ten divisions per call dominated the cost.
    constexpr double c1 = -1.0 / 2, c2 = 1.0 / 24, c3 = -1.0 / 720, c4 = 1.0 / 40320, c5 = -1.0 / 3628800;
    constexpr double s1 = -1.0 / 6, s2 = 1.0 / 120, s3 = -1.0 / 5040, s4 = 1.0 / 362880, s5 = -1.0 / 39916800;
    const double x = 0.25 * a2;  // (half angle)^2
    c = 1.0 + x * (c1 + x * (c2 + x * (c3 + x * (c4 + x * c5))));
    s = 0.5 * (1.0 + x * (s1 + x * (s2 + x * (s3 + x * (s4 + x * s5)))));
  } else {
    const double a = std::sqrt(a2);
    c = std::cos(0.5 * a);
    s = std::sin(0.5 * a) / a;
  }
  return Quat(c, s * theta.x(), s * theta.y(), s * theta.z());
}

// Renormalises a quaternion that is unit to a few ulp (products of unit quaternions) by the
// series of 1/sqrt(1 + eps), exact to round-off for |eps| < 1e-6.
inline Quat renormalised(Quat q) {
  const double eps = q.coeffs().squaredNorm() - 1.0;
  q.coeffs() *= std::abs(eps) < 1e-6 ? 1.0 - 0.5 * eps + 0.375 * eps * eps : 1.0 / std::sqrt(1.0 + eps);
  return q;
}

// R(q) diag(d) R(q)^T v: the world-frame inertia tensor (d = principal moments) or its inverse
// (d = their inverses) applied to v.
inline Vec3 worldInertiaTimes(const Quat& q, const Vec3& d, const Vec3& v) {
  return q * d.cwiseProduct(q.conjugate() * v);
}
inline Vec3 worldInertiaSolve(const Quat& q, const Vec3& inertia, const Vec3& v) {
  return worldInertiaTimes(q, inertia.cwiseInverse(), v);
}

// L^(n-1/2) from the stored state after a step of length dtPrev: q^n and w^(n-1/2).
inline Vec3 midStepAngularMomentum(const Quat& q, const Vec3& omegaMid, const Vec3& inertia, double dtPrev) {
  return worldInertiaTimes(rotationQuaternion(-0.5 * dtPrev * omegaMid) * q, inertia, omegaMid);
}

struct RotationStep {
  Quat orientation;      // q^(n+1)
  Vec3 angularVelocity;  // w^(n+1/2), world, mean over the step
  int iterations = 0;
  bool converged = false;  // the fixed point converges for |w| dt up to ~0.5 with aspect <= 3
};

// The fixed point w = Phi(w) of the midpoint relation contracts by at most
// kappa = |w| dt (1 + I_max/I_min)/2 per pass (Phi turns with q* by dt/2 per unit change of w), so
// after a pass that changed w by c the remaining error is at most kappa c/(1 - kappa): the
// iteration stops when that is below tolerance |w|. When L is rebuilt from (q, w) the fixed point
// must hold to round-off (kRebuiltMomentumTolerance: two passes at |w| dt = 1e-4 from the guess
// of leapfrogRotationWithMomentum, whose error is O(dt^2)); when L is stored, an error of the
// fixed point only shifts the orientation by tolerance |w| dt per step and L stays exact, so
// kStoredMomentumTolerance allows one pass.
constexpr double kRebuiltMomentumTolerance = 1e-15;
constexpr double kStoredMomentumTolerance = 1e-10;
constexpr int kRotationIterations = 60;

// Free rotation over dt with constant world angular momentum L from orientation q (invInertia:
// the inverses of the principal moments); omegaGuess starts the fixed point.
inline RotationStep rotateUnderMomentum(const Quat& q, const Vec3& angularMomentum, const Vec3& invInertia,
                                        const Vec3& omegaGuess, double dt, double tolerance) {
  RotationStep out;
  Vec3 w = omegaGuess;
  const double anisotropy = 1.0 + invInertia.maxCoeff() / invInertia.minCoeff();
  double prevChange2 = std::numeric_limits<double>::infinity();
  for (int it = 1; it <= kRotationIterations; ++it) {
    const Quat mid = rotationQuaternion(0.5 * dt * w) * q;
    const Vec3 next = worldInertiaTimes(mid, invInertia, angularMomentum);
    const double change2 = (next - w).squaredNorm();
    const double size2 = next.squaredNorm();
    w = next;
    out.iterations = it;
    const double kappa = 0.5 * dt * std::sqrt(size2) * anisotropy;
    const double bound = kappa < 0.5 ? kappa / (1.0 - kappa) : 1.0;
    // Done when the bound on the remaining error is at the tolerance, or when the change
    // stopped shrinking at the level of a few ulp (round-off).
    const bool small = bound * bound * change2 <= tolerance * tolerance * size2;
    const bool stalled = change2 >= prevChange2 && change2 <= 1e-28 * size2;
    if (small || stalled || size2 == 0.0) {
      out.converged = true;
      break;
    }
    prevChange2 = change2;
  }
  out.angularVelocity = w;
  out.orientation = renormalised(rotationQuaternion(dt * w) * q);
  return out;
}

// The damping laws (core/kernels/damping.hpp), shared with the translational and sphere updates.
using kernels::localDamping;
using kernels::viscousMidpointKick;
using kernels::ViscousKick;

enum class Damping { None, Local, Viscous };

struct LeapfrogRotation {
  RotationStep step;
  Vec3 angularMomentum;  // L^(n+1/2)
  Vec3 dampingTorque;    // what the damping added to the torque over the step (energy ledger)
};

// One rotational leapfrog step of a rigid body from q^n, w^(n-1/2), L^(n-1/2) and the torque T^n
// to q^(n+1), w^(n+1/2), L^(n+1/2). alpha is the local damping coefficient or [O]'s alpha_R
// [1/s], by `damping`. For an engine that stores L per particle (tolerance
// kStoredMomentumTolerance); leapfrogRotation below rebuilds it instead.
inline LeapfrogRotation leapfrogRotationWithMomentum(const Quat& q, const Vec3& omegaMid, const Vec3& angularMomentum,
                                                     const Vec3& inertia, const Vec3& torque, double dt,
                                                     Damping damping, double alpha,
                                                     double tolerance = kStoredMomentumTolerance) {
  LeapfrogRotation out;
  const Vec3& l0 = angularMomentum;
  if (damping == Damping::Viscous) {
    const ViscousKick k = viscousMidpointKick(l0, torque, alpha, dt);
    out.angularMomentum = k.momentum;
    out.dampingTorque = k.dampingForce;
  } else {
    out.dampingTorque = damping == Damping::Local ? localDamping(torque, omegaMid, alpha) : Vec3::Zero();
    out.angularMomentum = l0 + dt * (torque + out.dampingTorque);
  }
  // Guess for w^(n+1/2): w^(n-1/2) advanced over dt by the kick and by the gyroscopic turn of the
  // inertia under L (dw/dt = I_world^-1 (L x w) when torque-free), both at q^n; error O(dt^2).
  const Vec3 invInertia = inertia.cwiseInverse();
  const Vec3 change = out.angularMomentum - l0 + dt * l0.cross(omegaMid);
  const Vec3 guess = omegaMid + worldInertiaTimes(q, invInertia, change);
  out.step = rotateUnderMomentum(q, out.angularMomentum, invInertia, guess, dt, tolerance);
  return out;
}

// The same step with no extra state: L^(n-1/2) rebuilt from q^n and w^(n-1/2) (stored after a step
// of dtPrev). The rebuild repeats near-identical roundings every step, so a torque-free body's L
// drifts at round-off rate (measured 2e-16 relative per step, tests); storing L removes that.
inline LeapfrogRotation leapfrogRotation(const Quat& q, const Vec3& omegaMid, const Vec3& inertia,
                                         const Vec3& torque, double dt, double dtPrev, Damping damping,
                                         double alpha) {
  return leapfrogRotationWithMomentum(q, omegaMid, midStepAngularMomentum(q, omegaMid, inertia, dtPrev), inertia,
                                      torque, dt, damping, alpha, kRebuiltMomentumTolerance);
}

// The mid-step angular velocity w^(-1/2) that starts a run whose body has angular velocity
// omega0 at t = 0 with orientation q0: L = I_world(q0) omega0 held over the half step before.
inline Vec3 startingMidStepOmega(const Quat& q0, const Vec3& omega0, const Vec3& inertia, double dt) {
  const Vec3 l = worldInertiaTimes(q0, inertia, omega0);
  // A backward step from q0 under L: its mean angular velocity is w^(-1/2).
  return rotateUnderMomentum(q0, -l, inertia.cwiseInverse(), -omega0, dt, kRebuiltMomentumTolerance).angularVelocity *
         -1.0;
}

// Rotational kinetic energy of the mid-step state: L.w/2 = L^T I_world(q*)^-1 L / 2, the energy of
// the body turning with momentum L at the step's midpoint orientation.
inline double rotationalKineticEnergy(const Vec3& angularMomentum, const Vec3& omegaMid) {
  return 0.5 * angularMomentum.dot(omegaMid);
}

}  // namespace grainlab::rotation
