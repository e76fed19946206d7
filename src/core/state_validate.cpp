// Checks of a state read from a checkpoint, before anything is built from it: a checksum catches
// accidental corruption, these checks catch a file that is well-formed but inconsistent.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <stdexcept>

#include "core/errors.hpp"
#include "core/simulation.hpp"

namespace grainlab {

namespace {

[[noreturn]] void bad(const std::string& what) { throw InputError("inconsistent state: " + what); }

template <class T>
void sameSize(const std::vector<T>& v, std::size_t n, const char* name) {
  if (v.size() != n) bad(fmt::format("{} has {} entries for {} particles", name, v.size(), n));
}

bool finite(const Vec3& v) { return v.allFinite(); }

}  // namespace

void Simulation::validateState() const {
  const Particles& P = particles;
  const std::size_t n = P.size();
  if (n == 0) bad("no particles");
  sameSize(P.id, n, "id");
  sameSize(P.velocity, n, "velocity");
  sameSize(P.orientation, n, "orientation");
  sameSize(P.angularVelocity, n, "angular velocity");
  sameSize(P.force, n, "force");
  sameSize(P.torque, n, "torque");
  sameSize(P.shape, n, "shape");
  sameSize(P.radius, n, "radius");
  sameSize(P.semiAxes, n, "semi-axes");
  sameSize(P.mass, n, "mass");
  sameSize(P.inertia, n, "inertia");
  sameSize(P.rollingFriction, n, "rolling friction");
  sameSize(P.image, n, "image");
  sameSize(P.principalInertia, n, "principal inertia");
  sameSize(P.angularMomentum, n, "angular momentum");
  for (std::size_t i = 0; i < n; ++i) {
    if (!finite(P.position[i]) || !finite(P.velocity[i]) || !finite(P.angularVelocity[i]) || !finite(P.force[i]) ||
        !finite(P.torque[i]) || !finite(P.angularMomentum[i]) || !finite(P.principalInertia[i]) ||
        !P.orientation[i].coeffs().allFinite())
      bad(fmt::format("particle {}: non-finite state", i));
    if (P.shape[i] != Shape::Sphere && P.shape[i] != Shape::Ellipsoid) bad(fmt::format("particle {}: unknown shape", i));
    if (!(P.radius[i] > 0.0) || !std::isfinite(P.radius[i]) || !(P.semiAxes[i].minCoeff() > 0.0) ||
        !finite(P.semiAxes[i]))
      bad(fmt::format("particle {}: size not positive and finite", i));
    if (!(P.mass[i] > 0.0) || !std::isfinite(P.mass[i]) || !(P.inertia[i] > 0.0) || !std::isfinite(P.inertia[i]))
      bad(fmt::format("particle {}: mass or inertia not positive and finite", i));
    if (std::abs(P.orientation[i].norm() - 1.0) > 1e-6) bad(fmt::format("particle {}: orientation not a unit quaternion", i));
  }
  if (boundary != Boundary::Walls && boundary != Boundary::Periodic && boundary != Boundary::Membrane) bad("unknown boundary");
  if (boundary == Boundary::Periodic) {
    if (!cell.h.allFinite() || !(cell.h.determinant() > 0.0)) bad("periodic cell matrix singular or non-finite");
  } else {
    for (int k = 0; k < 6; ++k) {
      const Wall& w = box.walls[k];
      if (w.axis != k / 2 || w.side != k % 2) bad(fmt::format("wall {} has axis {} side {}", k, w.axis, w.side));
      if (!std::isfinite(w.position) || !std::isfinite(w.velocity) || !std::isfinite(w.servoIntegral))
        bad(fmt::format("wall {} has a non-finite position or speed", k));
    }
    for (int a = 0; a < 3; ++a)
      if (!(box.length(a) > 0.0) || !std::isfinite(box.length(a))) bad("wall box with a non-positive length");
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a)
        if (P.position[i][a] < box.lower(a).position - box.length(a) || P.position[i][a] > box.upper(a).position + box.length(a))
          bad(fmt::format("particle {} lies far outside the walls", i));
  }
  // The broad phase's grid has cells of about one largest diameter: a boundary very much larger than
  // its particles would ask for an absurd grid (a real sample has ~11 cells per particle at e = 20).
  double rMax = 0.0, rMin = 1e300;
  for (double r : P.radius) {
    rMax = std::max(rMax, r);
    rMin = std::min(rMin, r);
  }
  const Vec3 extent = boundary == Boundary::Periodic ? cell.widths()
                                                     : Vec3(box.length(0), box.length(1), box.length(2));
  double cells = 1.0;
  for (int a = 0; a < 3; ++a) cells *= std::max(1.0, extent[a] / (2.0 * rMax));
  if (cells > 64.0 * static_cast<double>(n) + 1e6) bad("the boundary is far too large for its particles");
  if (!(dt > 0.0) || !std::isfinite(dt)) bad("time step not positive");
  // The settings the engine carries in its state: enumerations within their values, numbers finite
  // and in the ranges a config allows (a forged file may hold anything).
  auto finiteIn = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  if (!finiteIn(model.young, 1e-300, 1e300) || !finiteIn(model.poisson, 0.0, 1.0) ||
      !finiteIn(model.tanFriction, 0.0, 1e300) || !finiteIn(model.beta, 0.0, 1e300) || !finiteIn(model.eta, 0.0, 1e300) ||
      !finiteIn(model.constantKn, 0.0, 1e300))
    bad("contact model parameters not finite or out of range");
  if (model.rolling != contact::RollingLaw::KozickiDonze && model.rolling != contact::RollingLaw::Linear &&
      model.rolling != contact::RollingLaw::None)
    bad("unknown rolling law");
  if (model.law != contact::NormalLaw::Linear && model.law != contact::NormalLaw::HertzMindlin) bad("unknown contact law");
  if (model.hertz() && (!(model.poisson < 0.5) || model.constantKn != 0.0)) bad("Hertz–Mindlin parameters out of range");
  if (!finiteIn(model.restitutionBeta, -1.0, 0.0)) bad("restitution damping ratio out of range");
  if (!finiteIn(model.referenceStress, 0.0, 1e12)) bad("Hertz reference stress out of range");
  if (model.combine != contact::CombineRule::Min && model.combine != contact::CombineRule::Mean &&
      model.combine != contact::CombineRule::Harmonic)
    bad("unknown rolling-friction combination rule");
  if (!finiteIn(servo.gain, 0.0, 1.0) || !finiteIn(servo.integralSteps, 0.0, 1e300) || !finiteIn(servo.maxSpeed, 0.0, 1e300))
    bad("servo settings not finite or out of range");
  if (!std::isfinite(energy.slip) || !std::isfinite(energy.rolling) || !std::isfinite(energy.damping) ||
      !std::isfinite(energy.boundaryWork) || !std::isfinite(energy.gravityWork) || !gravity.allFinite())
    bad("energy ledger or gravity not finite");
  if (!finiteIn(localDamping, 0.0, 1.0) || !finiteIn(viscousDamping, 0.0, 1e300)) bad("damping out of range");
  if (stepCount < 0 || !finiteIn(time, 0.0, 1e300)) bad("step count or time negative or not finite");
  for (double r : P.rollingFriction)
    if (!finiteIn(r, 0.0, 1e300)) bad("rolling friction not finite and >= 0");
  if (boundary == Boundary::Membrane) {
    const Membrane& m = membrane;
    if (m.control != MembraneControl::Pressure && m.control != MembraneControl::ConstantVolume) bad("unknown membrane control");
    if (m.around < 1 || m.along < 1 || m.around > 100000 || m.along > 100000) bad("membrane bins out of range");
    if (m.binRho.size() != static_cast<std::size_t>(m.around) * static_cast<std::size_t>(m.along) ||
        m.binGrain.size() != m.binRho.size() || m.grain.size() != m.force.size())
      bad("membrane bin lists of the wrong size");
    for (std::int64_t g : m.binGrain)
      if (g < -1 || g >= static_cast<std::int64_t>(P.size())) bad("membrane bin names a particle out of range");
    for (std::uint32_t g : m.grain)
      if (g >= P.size()) bad("membrane grain index out of range");
    for (const Vec3& f : m.force)
      if (!f.allFinite()) bad("membrane force not finite");
    for (double r : m.binRho)
      if (!finiteIn(r, 0.0, 1e300)) bad("membrane bin radius not finite and >= 0");
    if (!std::isfinite(m.axisX) || !std::isfinite(m.axisY) || !finiteIn(m.pressure, 0.0, 1e300) ||
        !finiteIn(m.stiffness, 0.0, 1e300) || !finiteIn(m.referenceRadius, 0.0, 1e300) ||
        !finiteIn(m.referenceVolume, 0.0, 1e300) || !finiteIn(m.volumeGain, 0.0, 1e3) || !finiteIn(m.volumeIntegral, 0.0, 1.0) || !finiteIn(m.basePressure, 0.0, 1e300) || !finiteIn(m.shell, 0.0, 1e300) || !std::isfinite(m.bottom) || !finiteIn(m.volume, 0.0, 1e300) ||
        !finiteIn(m.height, 0.0, 1e300) || !finiteIn(m.area, 0.0, 1e300) || !std::isfinite(m.radialForce) ||
        !std::isfinite(m.hoopPressure))
      bad("membrane settings or measurements not finite or out of range");
  }
  if (boundary != Boundary::Periodic) {
    for (const Wall& w : box.walls)
      if ((w.control != WallControl::Fixed && w.control != WallControl::Velocity && w.control != WallControl::Stress &&
           w.control != WallControl::ConstantVolume) ||
          !std::isfinite(w.targetStress) || !finiteIn(w.tanFriction, 0.0, 1e300))
        bad("wall control, target stress or friction invalid");
    for (int a = 0; a < 3; ++a)
      if ((box.lower(a).control == WallControl::ConstantVolume) != (box.upper(a).control == WallControl::ConstantVolume))
        bad("constant-volume control on one wall of an axis only");
    if (box.lower(0).control == WallControl::ConstantVolume || box.lower(1).control == WallControl::ConstantVolume ||
        box.lower(2).control == WallControl::ConstantVolume)
      if (!finiteIn(box.referenceVolume, 1e-300, 1e300)) bad("reference volume of constant-volume walls not positive");
  } else {
    auto knownControl = [](CellControl c) { return c == CellControl::StrainRate || c == CellControl::Stress; };
    int constantVolume = 0;
    for (int k = 0; k < 3; ++k) {
      constantVolume += cell.control[k] == CellControl::ConstantVolume;
      if ((!knownControl(cell.control[k]) && cell.control[k] != CellControl::ConstantVolume) ||
          !knownControl(cell.shearControl[k]))
        bad("unknown cell control");
    }
    if (constantVolume == 3) bad("every cell axis at constant volume (one must be driven)");
    if (!cell.velocityGradient.allFinite() || !cell.targetStress.allFinite() || !cell.strainRate.allFinite() ||
        !cell.referenceLength.allFinite() || !(cell.referenceLength.minCoeff() > 0.0) ||
        !cell.targetShearStress.allFinite() || !cell.shearServoIntegral.allFinite() || !std::isfinite(cell.shearRate) ||
        !cell.servoIntegral.allFinite() || !cell.stress.allFinite() || !cell.stiffness.allFinite() ||
        !cell.shearStiffness.allFinite())
      bad("periodic cell state not finite");
  }
  if (!(broadPhase.skin > 0.0) || !(broadPhase.skin <= 2.0 * rMin)) bad(fmt::format("neighbour skin {}", broadPhase.skin));
  if (!broadPhase.positionsAtBuild().empty()) sameSize(broadPhase.positionsAtBuild(), n, "build positions");
  contacts.forEach([&](const auto& list) {
    using Kind = typename std::decay_t<decltype(list)>::KindType;
    const std::size_t m = list.size();
    if (list.b.size() != m || list.shift.size() != m || list.history.size() != m || list.force.size() != m ||
        list.torqueA.size() != m || (!Kind::kPlane && list.torqueB.size() != m))
      bad(fmt::format("{} contact arrays of unequal length", Kind::kName));
    for (std::size_t c = 0; c < m; ++c) {
      if (list.a[c] >= n) bad(fmt::format("{} contact {}: particle index out of range", Kind::kName, c));
      if (Kind::kPlane ? list.b[c] >= 6 : (list.b[c] >= n || (Kind::kIndexOrdered && list.b[c] <= list.a[c])))
        bad(fmt::format("{} contact {}: second body out of range", Kind::kName, c));
      // Each kind holds the shapes it is for.
      const Shape first = std::is_same_v<Kind, EllipsoidEllipsoid> || std::is_same_v<Kind, EllipsoidPlane>
                              ? Shape::Ellipsoid : Shape::Sphere;
      const Shape second = std::is_same_v<Kind, SphereSphere> ? Shape::Sphere : Shape::Ellipsoid;
      if (P.shape[list.a[c]] != first || (!Kind::kPlane && P.shape[list.b[c]] != second))
        bad(fmt::format("{} contact {}: bodies of another shape", Kind::kName, c));
      if constexpr (std::is_same_v<typename Kind::History, contact::EllipsoidHistory>) {
        const auto& h = list.history[c];
        if (!(h.lambda >= 0.0 && h.lambda <= 1.0) || !(h.potentialLength >= 0.0) || !std::isfinite(h.potentialLength))
          bad(fmt::format("{} contact {}: lambda or potential length out of range", Kind::kName, c));
      }
      if (c > 0 && !(list.key(c - 1) < list.key(c))) bad(fmt::format("{} contacts not sorted", Kind::kName));
      const auto& h = list.history[c];
      if (!finite(h.shearForce) || !finite(h.moment) || !finite(h.prevNormal) || !finite(list.force[c]))
        bad(fmt::format("{} contact {}: non-finite history", Kind::kName, c));
      if (!(h.overlap >= 0.0) || !std::isfinite(h.overlap))
        bad(fmt::format("{} contact {}: overlap negative or not finite", Kind::kName, c));
    }
  });
}

}  // namespace grainlab
