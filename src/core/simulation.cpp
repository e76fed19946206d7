#include "core/simulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "core/state_io.hpp"
#include "geometry/sphere_contacts.hpp"

namespace grainlab {

void Simulation::initialise(double skinFraction) {
  double rMin = 1e300;
  for (double r : particles.radius) rMin = std::min(rMin, r);
  neighbors.skin = skinFraction * rMin;
  rebuildDue_ = true;
}

void Simulation::step() {
  if (rebuildDue_ || neighbors.wallsMoved(box)) {
    neighbors.build(particles, box);
    rebuildDue_ = false;
    slotsStale_ = true;
  }
  computeContacts();
  sumWallForces();
  updateWalls();
  integrate();
  ++stepCount;
  time += dt;
}

void Simulation::computeContacts() {
  const auto& x = particles.position;
  const auto& v = particles.velocity;
  const auto& w = particles.angularVelocity;
  const auto& rad = particles.radius;
  const auto& muR = particles.rollingFriction;
  const std::size_t nPairs = neighbors.pairA.size();
  pairForce.resize(nPairs);
  pairTorqueA.resize(nPairs);
  pairTorqueB.resize(nPairs);
  const std::size_t nWall = neighbors.wallParticle.size();
  wallForce.resize(nWall);
  wallTorque.resize(nWall);
  // Slip and rolling dissipation, summed per fixed chunk (see parallel.hpp); pairs first, then
  // wall contacts. Chunks are scheduled dynamically: only touching pairs run the contact law.
  ChunkedSums pairSums(nPairs, 2), wallSums(nWall, 2);
  // A pair that was apart and still is keeps its zero slots, so it is skipped without a write;
  // after a rebuild (pairs renumbered) or a load every slot is written once.
  const bool writeAll = slotsStale_;
  slotsStale_ = false;

#pragma omp parallel
  {
#pragma omp for schedule(dynamic, 1) nowait
  for (std::size_t chunk = 0; chunk < pairSums.chunks(); ++chunk) {
  double slip = 0.0, roll = 0.0;
  for (std::size_t p = pairSums.begin(chunk); p < pairSums.end(chunk); ++p) {
    const std::uint32_t a = neighbors.pairA[p], b = neighbors.pairB[p];
    contact::ContactHistory& h = neighbors.pairHistory[p];
    const Vec3 branch = x[b] - x[a];
    const double dist2 = branch.squaredNorm();
    const double reach = rad[a] + rad[b];
    if (dist2 >= reach * reach) {
      if (!h.touching && !writeAll) continue;
      h = contact::ContactHistory{};
      pairForce[p].setZero();
      pairTorqueA[p].setZero();
      pairTorqueB[p].setZero();
      continue;
    }
    const geometry::ContactGeometry g = geometry::sphereSphere(branch, dist2, rad[a], rad[b]);
    if (!h.touching) {
      h.touching = true;
      h.prevNormal = g.normal;
    }
    contact::ContactKinematics k;
    k.normal = g.normal;
    k.prevNormal = h.prevNormal;
    k.overlap = g.overlap;
    k.relativeVelocity = (v[b] + w[b].cross(g.branchB)) - (v[a] + w[a].cross(g.branchA));
    k.relativeSpin = w[b] - w[a];
    k.meanSpinNormal = 0.5 * (w[a] + w[b]).dot(g.normal);
    k.dt = dt;
    const contact::ContactResponse res =
        contact::applyLaw(model.pairParams(rad[a], rad[b], muR[a], muR[b]), k, h);
    pairForce[p] = res.force;
    pairTorqueA[p] = g.branchA.cross(-res.force) + res.moment;
    pairTorqueB[p] = g.branchB.cross(res.force) - res.moment;
    slip += res.slipDissipation;
    roll += res.rollDissipation;
  }
  pairSums.at(chunk, 0) = slip;
  pairSums.at(chunk, 1) = roll;
  }

#pragma omp for schedule(dynamic, 1)
  for (std::size_t chunk = 0; chunk < wallSums.chunks(); ++chunk) {
  double slip = 0.0, roll = 0.0;
  for (std::size_t c = wallSums.begin(chunk); c < wallSums.end(chunk); ++c) {
    const std::uint32_t i = neighbors.wallParticle[c];
    const Wall& wall = box.walls[neighbors.wallIndex[c]];
    contact::ContactHistory& h = neighbors.wallHistory[c];
    const Vec3 n = wall.inwardNormal();
    Vec3 planePoint = x[i];
    planePoint[wall.axis] = wall.position;
    const geometry::ContactGeometry g = geometry::spherePlane(x[i], rad[i], planePoint, n);
    if (g.overlap <= 0.0) {
      if (!h.touching && !writeAll) continue;
      h = contact::ContactHistory{};
      wallForce[c].setZero();
      wallTorque[c].setZero();
      continue;
    }
    if (!h.touching) {
      h.touching = true;
      h.prevNormal = n;
    }
    Vec3 wallVelocity = Vec3::Zero();
    wallVelocity[wall.axis] = wall.velocity;
    contact::ContactKinematics k;
    k.normal = n;
    k.prevNormal = h.prevNormal;
    k.overlap = g.overlap;
    k.relativeVelocity = v[i] + w[i].cross(g.branchB) - wallVelocity;
    k.relativeSpin = w[i];
    k.meanSpinNormal = 0.5 * w[i].dot(n);
    k.dt = dt;
    const contact::ContactResponse res =
        contact::applyLaw(model.wallParams(rad[i], wall.tanFriction, muR[i]), k, h);
    wallForce[c] = res.force;
    wallTorque[c] = g.branchB.cross(res.force) - res.moment;
    slip += res.slipDissipation;
    roll += res.rollDissipation;
  }
  wallSums.at(chunk, 0) = slip;
  wallSums.at(chunk, 1) = roll;
  }
  }
  energy.slip += pairSums.total(0) + wallSums.total(0);
  energy.rolling += pairSums.total(1) + wallSums.total(1);
}

void Simulation::gatherParticle(std::size_t i) {
  // Each particle sums its own contacts in a fixed order: no races, and the sums do not depend on
  // the number of threads (bit-identical results for any thread count).
  Vec3 fi = Vec3::Zero(), ti = Vec3::Zero();
  for (std::uint32_t s = neighbors.incidentStart[i]; s < neighbors.incidentStart[i + 1]; ++s) {
    const std::uint32_t e = neighbors.incident[s];
    const std::uint32_t p = e >> 1;
    if (e & 1u) {
      fi += pairForce[p];
      ti += pairTorqueB[p];
    } else {
      fi -= pairForce[p];
      ti += pairTorqueA[p];
    }
  }
  for (std::uint32_t c = neighbors.wallStart[i]; c < neighbors.wallStart[i + 1]; ++c) {
    fi += wallForce[c];
    ti += wallTorque[c];
  }
  particles.force[i] = fi;
  particles.torque[i] = ti;
}

void Simulation::sumWallForces() {
  // The particles' own sums are done in integrate() (one pass over the particles instead of two,
  // one parallel region less per step); here only the walls' forces, which the servos need first.
  for (Wall& wall : box.walls) {
    wall.normalForce = 0.0;
    wall.contactStiffness = 0.0;
    wall.contacts = 0;
  }
  for (std::size_t c = 0; c < neighbors.wallParticle.size(); ++c) {
    if (!neighbors.wallHistory[c].touching) continue;
    Wall& wall = box.walls[neighbors.wallIndex[c]];
    wall.normalForce += wallForce[c].dot(wall.inwardNormal());
    wall.contactStiffness += model.wallParams(particles.radius[neighbors.wallParticle[c]],
                                              wall.tanFriction).kn;
    ++wall.contacts;
  }
}

void Simulation::updateWalls() {
  for (Wall& wall : box.walls) {
    if (wall.control != WallControl::Stress) continue;
    const double sigma = wall.normalForce / box.area(wall.axis);
    const double error = wall.targetStress - sigma;  // > 0: push further in
    double inwardSpeed = servo.maxSpeed;
    if (wall.contactStiffness > 0.0) {
      const double u = error * box.area(wall.axis) / wall.contactStiffness;
      if (servo.integralSteps > 0.0)
        wall.servoIntegral = std::clamp(wall.servoIntegral + servo.gain * u / (servo.integralSteps * dt),
                                        -servo.maxSpeed, servo.maxSpeed);
      inwardSpeed = servo.gain * u / dt + wall.servoIntegral;
    } else {
      wall.servoIntegral = 0.0;
    }
    inwardSpeed = std::clamp(inwardSpeed, -servo.maxSpeed, servo.maxSpeed);
    wall.velocity = wall.side == 0 ? inwardSpeed : -inwardSpeed;
  }
  for (Wall& wall : box.walls) {
    // Work done on the particles by the wall: its force on them times its inward displacement.
    const double inward = wall.side == 0 ? wall.velocity : -wall.velocity;
    energy.boundaryWork += wall.normalForce * inward * dt;
    wall.position += wall.velocity * dt;
  }
}

void Simulation::integrate() {
  const std::size_t n = particles.size();
  auto& x = particles.position;
  auto& v = particles.velocity;
  auto& q = particles.orientation;
  auto& w = particles.angularVelocity;
  const auto& xBuild = neighbors.positionsAtBuild();
  const double alpha = localDamping;
  const double h = dt;
  const Vec3 lo = box.lowerCorner(), hi = box.upperCorner();
  double maxDisp2 = 0.0;
  long badParticle = -1;
  ChunkedSums dampingWork(n, 1);

#pragma omp parallel for schedule(static) reduction(max : maxDisp2)
  for (std::size_t chunk = 0; chunk < dampingWork.chunks(); ++chunk) {
  double work = 0.0;
  for (std::size_t i = dampingWork.begin(chunk); i < dampingWork.end(chunk); ++i) {
    gatherParticle(i);
    // Cundall local damping per component, against the sign of the current (mid-step) velocity.
    Vec3 f = particles.force[i] + particles.mass[i] * gravity;
    Vec3 t = particles.torque[i];
    Vec3 fd, td;
    for (int k = 0; k < 3; ++k) {
      fd[k] = -alpha * std::copysign(std::abs(f[k]), v[i][k]) * (v[i][k] != 0.0);
      td[k] = -alpha * std::copysign(std::abs(t[k]), w[i][k]) * (w[i][k] != 0.0);
    }
    const Vec3 vOld = v[i], wOld = w[i];
    v[i] += (f + fd) * (h * particles.invMass[i]);
    w[i] += (t + td) * (h * particles.invInertia[i]);
    // Work of the damping forces over the step, with the mean of old and new velocities.
    work += h * (fd.dot(0.5 * (vOld + v[i])) + td.dot(0.5 * (wOld + w[i])));
    x[i] += v[i] * h;
    const double wNorm = w[i].norm();
    if (wNorm > 0.0) {
      // q <- exp(w dt / 2) q with the exponential to first order, renormalised (PHYSICS.md §4).
      const Vec3 half = 0.5 * h * w[i];
      Quat qn = Quat(1.0, half.x(), half.y(), half.z()) * q[i];
      // |qn|^2 = 1 + eps with eps ~ |w dt|^2 / 4 (~1e-10): 1/sqrt(1 + eps) by its series
      // 1 - eps/2 + 3 eps^2/8, exact to round-off below 1e-6; the square root otherwise.
      const double eps = qn.coeffs().squaredNorm() - 1.0;
      qn.coeffs() *= std::abs(eps) < 1e-6 ? 1.0 - 0.5 * eps + 0.375 * eps * eps : 1.0 / std::sqrt(1.0 + eps);
      q[i] = qn;
      particles.rotationPath[i] += wNorm * h;
    }
    if (!xBuild.empty()) maxDisp2 = std::max(maxDisp2, (x[i] - xBuild[i]).squaredNorm());
    const bool finite = x[i].allFinite() && v[i].allFinite() && w[i].allFinite();
    const double r = particles.radius[i];
    const bool inside = ((x[i] - lo).array() > -r).all() && ((hi - x[i]).array() > -r).all();
    if (!finite || !inside) {
#pragma omp critical
      if (badParticle < 0 || static_cast<long>(i) < badParticle) badParticle = static_cast<long>(i);
    }
  }
  dampingWork.at(chunk, 0) = work;
  }
  energy.damping -= dampingWork.total(0);
  if (badParticle >= 0) {
    const std::size_t i = static_cast<std::size_t>(badParticle);
    const bool finite = x[i].allFinite() && v[i].allFinite() && w[i].allFinite();
    throw SimulationError(fmt::format(
        "numerical instability at step {}: particle {} {} (position {:.6g} {:.6g} {:.6g}, "
        "velocity {:.6g} {:.6g} {:.6g}); reduce solver.dt_factor or the loading rate",
        stepCount + 1, i, finite ? "left the box" : "has a non-finite state", x[i][0], x[i][1],
        x[i][2], v[i][0], v[i][1], v[i][2]));
  }
  const double halfSkin = neighbors.halfSkin();
  if (maxDisp2 > halfSkin * halfSkin) rebuildDue_ = true;
}

void Simulation::saveState(std::ostream& out) const {
  using namespace stateio;
  particles.saveState(out);
  put(out, box);
  neighbors.saveState(out);
  put(out, model);
  put(out, servo);
  put(out, energy);
  put(out, gravity);
  put(out, dt);
  put(out, localDamping);
  put(out, stepCount);
  put(out, time);
  putVector(out, pairForce);
  putVector(out, pairTorqueA);
  putVector(out, pairTorqueB);
  putVector(out, wallForce);
  putVector(out, wallTorque);
  put(out, rebuildDue_);
}

void Simulation::loadState(std::istream& in) {
  using namespace stateio;
  particles.loadState(in);
  get(in, box);
  neighbors.loadState(in);
  get(in, model);
  get(in, servo);
  get(in, energy);
  get(in, gravity);
  get(in, dt);
  get(in, localDamping);
  get(in, stepCount);
  get(in, time);
  getVector(in, pairForce);
  getVector(in, pairTorqueA);
  getVector(in, pairTorqueB);
  getVector(in, wallForce);
  getVector(in, wallTorque);
  get(in, rebuildDue_);
  slotsStale_ = true;
}

std::size_t Simulation::touchingPairs() const {
  std::size_t count = 0;
  for (const auto& h : neighbors.pairHistory) count += h.touching;
  return count;
}

}  // namespace grainlab
