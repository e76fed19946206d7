#include "core/simulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <cmath>
#include <limits>

#ifdef _OPENMP
#include <omp.h>
#endif
#include <stdexcept>

#include "core/contact_driver.hpp"
#include "core/errors.hpp"
#include "core/kernels/gather.hpp"
#include "core/kernels/integrate.hpp"
#include "core/kernels/integrate_simd.hpp"
#include "core/parallel.hpp"
#include "core/state_io.hpp"
#include "core/rigid_rotation.hpp"
#include "geometry/ellipsoid_shape.hpp"

namespace grainlab {

const std::vector<Simulation::EngineStage>& Simulation::engineStages(Boundary kind) {
  // The engine's pipeline, in order, per boundary kind: the one place where a step is defined. Each
  // stage is the boundary's own instance (no boundary branch inside a stage); a backend other than
  // this CPU one (OpenMP loops over the kernels of core/kernels/) would bring its own lists.
  static const std::vector<EngineStage> walls{
      {"broad phase", &Simulation::updateBroadPhase, true, kPositions | kBoundary | kContacts,
       kPositions | kContacts},
      {"contacts", &Simulation::computeContactsFor<false>, false,
       kPositions | kVelocities | kRotations | kContacts | kBoundary, kContacts | kEnergy},
      {"boundary forces", &Simulation::measureWalls, false, kContacts | kBoundary, kBoundary},
      {"boundary control", &Simulation::controlWallStage, true, kBoundary, kBoundary | kEnergy},
      {"integrate", &Simulation::integrateFor<false>, false,
       kPositions | kVelocities | kRotations | kContacts | kBoundary,
       kPositions | kVelocities | kRotations | kForces | kEnergy},
      {"clock", &Simulation::advanceClock, true, kClock, kClock},
  };
  // In a cell the contact stage also sums the stress and the servo's stiffness: no wall sums.
  static const std::vector<EngineStage> periodic{
      {"broad phase", &Simulation::updateBroadPhase, true, kPositions | kBoundary | kContacts,
       kPositions | kContacts},
      {"contacts", &Simulation::computeContactsFor<true>, false,
       kPositions | kVelocities | kRotations | kContacts | kBoundary, kContacts | kEnergy | kBoundary},
      {"boundary control", &Simulation::controlCellStage, true, kBoundary, kBoundary | kEnergy},
      {"integrate", &Simulation::integrateFor<true>, false,
       kPositions | kVelocities | kRotations | kContacts | kBoundary,
       kPositions | kVelocities | kRotations | kForces | kEnergy},
      {"clock", &Simulation::advanceClock, true, kClock, kClock},
  };
  // A membrane sample: the platens are walls; the membrane stage loads the surface grains (and
  // servoes its pressure when it keeps the volume) after the platens' forces are known.
  static const std::vector<EngineStage> membrane{
      {"broad phase", &Simulation::updateBroadPhase, true, kPositions | kBoundary | kContacts,
       kPositions | kContacts},
      {"contacts", &Simulation::computeContactsFor<false>, false,
       kPositions | kVelocities | kRotations | kContacts | kBoundary, kContacts | kEnergy},
      {"boundary forces", &Simulation::measureWalls, false, kContacts | kBoundary, kBoundary},
      {"membrane", &Simulation::membraneStage, true, kPositions | kBoundary, kBoundary},
      {"boundary control", &Simulation::controlWallStage, true, kBoundary, kBoundary | kEnergy},
      {"integrate", &Simulation::integrateFor<false>, false,
       kPositions | kVelocities | kRotations | kContacts | kBoundary,
       kPositions | kVelocities | kRotations | kForces | kEnergy},
      {"clock", &Simulation::advanceClock, true, kClock, kClock},
  };
  return kind == Boundary::Periodic ? periodic : kind == Boundary::Membrane ? membrane : walls;
}

std::size_t Simulation::engineStageIndex(Boundary kind, const std::string& name) {
  const auto& stages = engineStages(kind);
  for (std::size_t k = 0; k < stages.size(); ++k)
    if (name == stages[k].name) return k;
  throw std::invalid_argument("no engine stage called \"" + name + "\"");
}

std::string Simulation::accessNames(unsigned access) {
  static const char* const names[] = {"positions", "velocities", "rotations", "forces", "contacts",
                                      "boundary", "energy", "clock", "laboratory records"};
  std::string out;
  for (unsigned b = 0; b < std::size(names); ++b)
    if (access & (1u << b)) out += (out.empty() ? "" : ", ") + std::string(names[b]);
  return out.empty() ? "nothing" : out;
}

void Simulation::initialise(double skinFraction) {
  double rMin = 1e300;
  for (double r : particles.radius) rMin = std::min(rMin, r);
  broadPhase.skin = skinFraction * rMin;
  rebuildDue_ = true;
}

namespace {
// The engine stage each thread of the team is running (step() sets it; serial() reads it).
thread_local int tStage = 0;
}  // namespace

namespace {
// Particles per call of an inner stage's body: the team shares these blocks out statically.
constexpr std::size_t kInnerBlock = 256;
}  // namespace

void Simulation::step(const std::vector<InnerStage>* inner) {
  // One parallel region per step: the stages share the team (one fork/join instead of one per
  // parallel stage). Every thread runs every stage and so meets the same work-sharing constructs
  // and barriers in the same order: outside serial parts, stages branch only on what no thread
  // changes during the step (the boundary kind, which lists are empty) and on failedStage_ at a
  // stage's start, which every thread reads after the barrier that ended the failing serial part,
  // and which a later failure cannot change for an earlier stage.
  const std::vector<EngineStage>& stages = engineStages(boundary);
  failedStage_.stage.store(StageFlag::kNone, std::memory_order_relaxed);
  stageError_ = nullptr;
  auto runInner = [&](std::size_t after) {
    for (const InnerStage& st : *inner) {
      if (st.after != after) continue;
      const std::size_t n = particles.size();
      // The loop's closing barrier publishes the stage's writes to the next stage.
#pragma omp for schedule(static)
      for (std::size_t begin = 0; begin < n; begin += kInnerBlock) st.particles(begin, std::min(n, begin + kInnerBlock));
    }
  };
  auto runStages = [&] {
    for (int k = 0; k < static_cast<int>(stages.size()); ++k) {
      if (failedStage_.stage.load(std::memory_order_relaxed) < k) break;
      tStage = k;
      (this->*stages[k].run)();
      if (failedStage_.stage.load(std::memory_order_relaxed) <= k) break;  // its serial part failed
      if (inner && !inner->empty()) runInner(static_cast<std::size_t>(k));
    }
  };
#ifdef _OPENMP
  // On one thread the stages run outside a parallel region: their work-sharing constructs and
  // barriers then bind to the implicit one-thread team and cost nothing, where a parallel region of
  // one thread still makes a futex system call at every barrier (libgomp): about 5 us a step on
  // this VM, 90 % of a step for a few particles. Same thread, same order: the same bits.
  if (omp_get_max_threads() == 1 || omp_in_parallel()) {
    runStages();
  } else {
#pragma omp parallel
    runStages();
  }
#else
  runStages();
#endif
  if (stageError_) {
    std::exception_ptr e = stageError_;
    stageError_ = nullptr;
    std::rethrow_exception(e);
  }
}

template <class F>
void Simulation::serial(F&& body) {
#pragma omp single
  {
    try {
      body();
    } catch (...) {
      stageError_ = std::current_exception();
      failedStage_.stage.store(tStage, std::memory_order_relaxed);
    }
  }
}

void Simulation::advanceClock() {
  // The last stage: the barrier that ends the step's parallel region publishes the clock.
#pragma omp single nowait
  {
    ++stepCount;
    time += dt;
  }
}

void Simulation::updateBroadPhase() {
  // Prepare on one thread (wrap, bin), scan the candidates on the whole team (one contiguous part
  // of the particles per thread), finish on one thread (join in part order, carry history): the
  // same lists for any thread count (BroadPhase::prepareWalls).
#ifdef _OPENMP
  const int team = omp_get_num_threads();
#else
  const int team = 1;
#endif
  serial([&] {
    rebuilding_ = false;
    if (boundary == Boundary::Periodic) {
      if (!rebuildDue_) return;
      wrapIntoCell();
      broadPhase.preparePeriodic(particles, cell, team);
    } else {
      if (!rebuildDue_ && !broadPhase.wallsMoved(box)) return;
      broadPhase.prepareWalls(particles, box, team);
    }
    rebuilding_ = true;
  });
  // Both read after the barrier that ended the serial part: every thread takes the same branch.
  if (failedStage_.stage.load(std::memory_order_relaxed) == tStage || !rebuilding_) return;
#pragma omp for schedule(static)
  for (int part = 0; part < team; ++part) broadPhase.scanPart(particles, cell, part);
  serial([&] {
    broadPhase.finish(particles, box, cell, contacts);
    rebuildDue_ = false;
  });
}

void Simulation::wrapIntoCell() {
  // Particles that left the cell re-enter through the opposite face: x <- x - H w with w the whole
  // periods crossed. Their contacts keep their history; only the image shifts change.
  const std::size_t n = particles.size();
  std::vector<std::array<int, 3>> wrap(n, {0, 0, 0});
  bool any = false;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 s = cell.hInverse * particles.position[i];
    for (int a = 0; a < 3; ++a) {
      const double f = std::floor(s[a]);
      if (f != 0.0) {
        if (!ImageShift::packable(static_cast<int>(f)))
          throw SimulationError(fmt::format("particle {} left the periodic cell by {} periods (step {}); "
                                            "reduce solver.dt_factor or the loading rate",
                                            particles.id[i], f, stepCount));
        wrap[i][a] = static_cast<int>(f);
        any = true;
      }
    }
    if (wrap[i] != std::array<int, 3>{0, 0, 0}) {
      particles.position[i] -= cell.h * Vec3(wrap[i][0], wrap[i][1], wrap[i][2]);
      for (int a = 0; a < 3; ++a) particles.image[i][a] += wrap[i][a];
    }
  }
  if (any) contacts.forEachPair([&](auto& list) { list.applyWrap(wrap); });
}

template <bool Periodic>
void Simulation::computeContactsFor() {
  // The lists are as the broad phase left them (it ended with a barrier): every thread sees the
  // same kinds present.
  const bool ellipsoids = !contacts.ellipsoidEllipsoid.a.empty() || !contacts.sphereEllipsoid.a.empty() ||
                          !contacts.ellipsoidWall.a.empty();
  auto& pairs = contacts.sphereSphere;
  auto& walls = contacts.sphereWall;
  auto& ee = contacts.ellipsoidEllipsoid;
  auto& se = contacts.sphereEllipsoid;
  auto& ew = contacts.ellipsoidWall;
  serial([&] {
    // Shape matrices of the step, once per ellipsoid, shared by its contacts.
    if (ellipsoids) {
      shapeMatrices_.resize(particles.size());
      for (std::size_t i = 0; i < particles.size(); ++i)
        if (particles.shape[i] == Shape::Ellipsoid)
          shapeMatrices_[i] = geometry::shapeMatrix(particles.semiAxes[i], particles.orientation[i]);
    }
    const int pairTerms = Periodic ? kContactSums : 3;
    pairSums_.reset(pairs.size(), pairTerms);
    wallSums_.reset(walls.size(), 3);
    eeSums_.reset(ee.size(), pairTerms);
    seSums_.reset(se.size(), pairTerms);
    ewSums_.reset(ew.size(), 3);
    integrateSums_.reset(particles.size(), kIntegrateSums);  // the integrate stage's, cut here to save a barrier
    // Every slot is written once after the list changed; then apart pairs are skipped.
    int k = 0;
    contacts.forEach([&](auto& list) {
      writeAll_[k++] = list.slotsStale;
      list.slotsStale = false;
    });
  });
  const ContactContext ctx{particles, model, box, cell, dt, &shapeMatrices_};
  // Work-shared loops without a barrier between kinds: a thread done with one kind's chunks takes
  // the next kind's.
  evaluateContacts<SphereSphere, Periodic>(pairs, ctx, pairSums_, writeAll_[0]);
  if constexpr (!Periodic) evaluateContacts<SpherePlane, false>(walls, ctx, wallSums_, writeAll_[1]);
  if (ellipsoids) {
    evaluateContacts<EllipsoidEllipsoid, Periodic>(ee, ctx, eeSums_, writeAll_[2]);
    evaluateContacts<SphereEllipsoid, Periodic>(se, ctx, seSums_, writeAll_[3]);
    if constexpr (!Periodic) evaluateContacts<EllipsoidPlane, false>(ew, ctx, ewSums_, writeAll_[4]);
  }
#pragma omp barrier
  if constexpr (Periodic) {
    serial([&] { sumContactTerms<Periodic>(ellipsoids); });  // the cell servo needs the stress next
  } else {
    // Energy sums only: nothing before the next barrier (the end of the wall-force loop) reads them.
#pragma omp single nowait
    sumContactTerms<Periodic>(ellipsoids);
  }
}

template <bool Periodic>
void Simulation::sumContactTerms(bool ellipsoids) {
  const ChunkedSums &pairSums = pairSums_, &wallSums = wallSums_, &eeSums = eeSums_, &seSums = seSums_,
                    &ewSums = ewSums_;
  energy.slip += pairSums.total(kSlip) + wallSums.total(kSlip);
  energy.rolling += pairSums.total(kRoll) + wallSums.total(kRoll);
  if (model.restitutionBeta != 0.0) energy.damping += pairSums.total(kViscous) + wallSums.total(kViscous);
  if (ellipsoids) {
    energy.slip += eeSums.total(kSlip) + seSums.total(kSlip) + ewSums.total(kSlip);
    energy.rolling += eeSums.total(kRoll) + seSums.total(kRoll) + ewSums.total(kRoll);
  }
  if constexpr (Periodic) {
    const double v = cell.volume();
    auto total = [&](int term) {
      double t = pairSums.total(term);
      if (ellipsoids) t += eeSums.total(term) + seSums.total(term);
      return t;
    };
    for (int i = 0; i < 9; ++i) cell.stress(i % 3, i / 3) = total(kStress0 + i) / v;
    for (int i = 0; i < 3; ++i) cell.stiffness[i] = total(kStiffness0 + i) / v;
    for (int i = 0; i < 3; ++i) cell.shearStiffness[i] = total(kShearStiffness0 + i) / v;
  }
}

void Simulation::gatherParticle(std::size_t i) {
  const kernels::Wrench sum = kernels::gatherParticle(contacts, i);  // core/kernels/gather.hpp
  particles.force[i] = sum.force;
  particles.torque[i] = sum.torque;
}

void Simulation::measureWalls() {
  // The walls' forces, which their servos need. The walls are shared out across the team (thread g
  // of T takes the walls k with k mod T = g, in one pass over the lists), and each wall sums its own
  // contacts in list order, as one thread would: the same bits for any thread count. The loop's
  // closing barrier publishes the sums to the servo stage.
#ifdef _OPENMP
  const int team = omp_get_num_threads();
#else
  const int team = 1;
#endif
#pragma omp for schedule(static)
  for (int g = 0; g < team; ++g) sumWallForces(g, team);
}

void Simulation::sumWallForces(int group, int groups) {
  constexpr std::size_t walls = std::tuple_size_v<decltype(box.walls)>;
  std::array<double, walls> force{}, stiffness{};
  std::array<int, walls> touching{};
  auto sum = [&](const auto& list, const std::vector<double>& radius) {
    for (std::size_t c = 0; c < list.size(); ++c) {
      const std::uint32_t k = list.b[c];
      if (static_cast<int>(k % groups) != group || !list.history[c].touching) continue;
      const Wall& wall = box.walls[k];
      force[k] += list.force[c].dot(wall.inwardNormal());
      contact::PairParams p = model.wallParams(radius[list.a[c]], wall.tanFriction);
      contact::SphereContactModel::resolve(p, list.history[c].overlap);  // Hertz–Mindlin: tangent Kn
      stiffness[k] += p.kn;
      // A normal dashpot answers the wall's own speed: moved by u in one step, the wall meets
      // Kn u + c u / dt. Counted in, the servo's step stays stable with stiff dashpots (without it
      // the wall rings between its speed limits).
      if (model.restitutionBeta != 0.0)
        stiffness[k] += model.dampingFactor(particles.mass[list.a[c]]) * std::sqrt(p.kn) / dt;
      ++touching[k];
    }
  };
  sum(contacts.sphereWall, particles.radius);
  sum(contacts.ellipsoidWall, particles.equivalentRadius);
  for (std::size_t k = static_cast<std::size_t>(group); k < walls; k += static_cast<std::size_t>(groups)) {
    box.walls[k].normalForce = force[k];
    box.walls[k].contactStiffness = stiffness[k];
    box.walls[k].contacts = touching[k];
  }
}

void Simulation::controlWallStage() {
  serial([&] { controlWalls(); });
}

void Simulation::controlCellStage() {
  serial([&] { controlCell(); });
}

void Simulation::membraneStage() {
  serial([&] {
    for (std::uint32_t g : membrane.grain) membraneLoad_[g] = Vec3::Zero();
    membrane.measure(particles, box.lower(2).position, box.upper(2).position);
    if (membrane.rigid) {
      // Forces from where the cylinder is, then it moves (as a wall's force, then its servo).
      membrane.applyCylinder(particles, [&](double r) { return model.wallParams(r, 0.0).kn; });
      const double before = membrane.radius;
      membrane.servoCylinder(dt, servo.gain, servo.integralSteps, servo.maxSpeed);
      energy.boundaryWork += membrane.radialForce * (before - membrane.radius);
    } else {
      // The confined modulus the volume servo scales its correction by: the platens' contact
      // stiffness over the area, times the height (the sample's axial stiffness as a modulus).
      const double area = membrane.platenArea();
      const double platens = 0.5 * (box.lower(2).contactStiffness + box.upper(2).contactStiffness);
      if (area > 0.0) membrane.servo(platens * membrane.height / area);
      membrane.applyPressure(particles);
    }
    refreshMembrane();
  });
}

void Simulation::installFlexibleMembrane() {
  membrane.rigid = false;
  membrane.servoIntegral = 0.0;
  membrane.measure(particles, box.lower(2).position, box.upper(2).position);
  membrane.applyPressure(particles);
  refreshMembrane();
}

void Simulation::refreshMembrane() {
  if (membraneLoad_.size() != particles.size()) membraneLoad_.assign(particles.size(), Vec3::Zero());
  for (std::size_t k = 0; k < membrane.grain.size(); ++k) membraneLoad_[membrane.grain[k]] = membrane.force[k];
}

void Simulation::controlWalls() {
  for (Wall& wall : box.walls) {
    if (wall.control != WallControl::Stress) continue;
    const double area = wallArea(wall.axis);
    const double sigma = wall.normalForce / area;
    const double error = wall.targetStress - sigma;  // > 0: push further in
    double inwardSpeed = servo.maxSpeed;
    if (wall.contactStiffness > 0.0) {
      const double u = error * area / wall.contactStiffness;
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
  controlWallVolume();
  for (Wall& wall : box.walls) {
    // Work done on the particles by the wall: its force on them times its inward displacement.
    const double inward = wall.side == 0 ? wall.velocity : -wall.velocity;
    energy.boundaryWork += wall.normalForce * inward * dt;
    wall.position += wall.velocity * dt;
  }
}

void Simulation::controlWallVolume() {
  // Constant-volume axes: their walls move symmetrically so that the box after this step has the
  // reference volume, given the lengths the other axes will have. The target is the reference
  // volume itself, not the current one, so rounding does not accumulate into a drift.
  int free = 0;
  double fixedProduct = 1.0, freeProduct = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double next = box.length(a) + (box.upper(a).velocity - box.lower(a).velocity) * dt;
    if (box.lower(a).control == WallControl::ConstantVolume) {
      ++free;
      freeProduct *= box.length(a);
    } else {
      fixedProduct *= next;
    }
  }
  if (free == 0) return;
  const double scale = std::pow(box.referenceVolume / (fixedProduct * freeProduct), 1.0 / free);
  for (int a = 0; a < 3; ++a) {
    if (box.lower(a).control != WallControl::ConstantVolume) continue;
    const double speed = 0.5 * (scale - 1.0) * box.length(a) / dt;  // outward speed of each wall
    box.lower(a).velocity = -speed;
    box.upper(a).velocity = speed;
  }
}

void Simulation::controlCell() {
  // L from the servo and the imposed rates, or as the caller prescribed it.
  Mat3& L = cell.velocityGradient;
  if (!cell.prescribedGradient) setCellGradient();
  // Work done on the particles by the cell: -V sigma:L dt with sigma the Love–Weber stress
  // (compression positive), the rate at which the imposed deformation loads the contacts.
  energy.boundaryWork -= cell.volume() * cell.stress.cwiseProduct(L).sum() * dt;
  cell.advance(dt);
}

void Simulation::setCellGradient() {
  // The cell's stress servo (docs/physics.md §8.2), the strain-space twin of the wall servo
  // (servo_settings.hpp): the stress error over the assembly's affine stiffness K is the
  // compressive strain u that would cancel it if every contact deformed with the mean strain; the
  // cell strains by gain u per step plus an integral term that learns the rate a dilating or
  // contracting sample needs. The affine stiffness overestimates the real one (grains rearrange), so
  // the loop undershoots rather than oscillates, whatever Ec and p. Rates are capped so that a face
  // never closes faster than two walls would (2 servo.maxSpeed).
  auto servoRate = [&](double error, double stiffness, double& integral, double maxRate) {
    double rate = 0.0;  // compressive (true) strain rate [1/s]
    if (stiffness > 0.0) {
      const double u = error / stiffness;
      if (servo.integralSteps > 0.0)
        integral = std::clamp(integral + servo.gain * u / (servo.integralSteps * dt), -maxRate, maxRate);
      rate = servo.gain * u / dt + integral;
    } else {
      integral = 0.0;
      rate = error > 0.0 ? maxRate : 0.0;  // no contact yet: close at the cap
    }
    return std::clamp(rate, -maxRate, maxRate);
  };
  Mat3& L = cell.velocityGradient;
  L.setZero();
  const Vec3 lengths = cell.h.diagonal();
  for (int k = 0; k < 3; ++k) {
    if (cell.control[k] == CellControl::ConstantVolume) continue;  // below
    const double maxRate = 2.0 * servo.maxSpeed / lengths[k];
    const double rate = cell.control[k] == CellControl::StrainRate
                            ? cell.strainRate[k] * cell.referenceLength[k] / lengths[k]  // engineering rate on H0
                            : servoRate(cell.targetStress[k] - cell.stress(k, k), cell.stiffness[k],
                                        cell.servoIntegral[k], maxRate);
    L(k, k) = -rate;
  }
  // Constant-volume components take up what the others change, so that tr L = 0.
  int free = 0;
  double driven = 0.0;
  for (int k = 0; k < 3; ++k) {
    if (cell.control[k] == CellControl::ConstantVolume) ++free;
    else driven += L(k, k);
  }
  if (free > 0)
    for (int k = 0; k < 3; ++k)
      if (cell.control[k] == CellControl::ConstantVolume) L(k, k) = -driven / free;
  const Vec3 shear = cell.shearStress();
  for (int k = 0; k < 3; ++k) {
    if (cell.shearControl[k] != CellControl::Stress) continue;
    const int i = k == 0 ? 1 : 0, j = k == 2 ? 1 : 2;
    const double maxRate = 2.0 * servo.maxSpeed / std::max(lengths[i], lengths[j]);
    // Pure shear (no spin): L_ij = L_ji = -rate raises the symmetrised sigma_ij by K_ij rate dt.
    const double rate = servoRate(cell.targetShearStress[k] - shear[k], cell.shearStiffness[k],
                                  cell.shearServoIntegral[k], maxRate);
    L(i, j) = L(j, i) = -rate;
  }
  L(0, 2) += cell.shearRate;
}

template <bool Periodic>
void Simulation::integrateFor() {
  // The per-particle kernel (core/kernels/integrate.hpp) over a view of the arrays, or its
  // vectorised twin; this loop only shares the particles out, gathers each one's contacts and
  // keeps the chunk sums (the kernels' work terms in particle order, the checks of each chunk).
  const kernels::IntegratorView view = kernels::IntegratorView::of(particles);
  kernels::IntegratorStep stepParams;
  stepParams.h = dt;
  stepParams.localDamping = localDamping;
  stepParams.viscousDamping = viscousDamping;
  stepParams.gravity = gravity;
  stepParams.gravityOn = gravity.squaredNorm() > 0.0;
  // Periodic cell: particles move with the homogeneous flow too, x <- x + v h + M x, the same map
  // M = exp(L h) - I that advanced H; the rebuild test measures displacements from where that flow
  // has carried each particle's build position (F x_build, F = H H_build^-1).
  stepParams.flowStep = cell.flowStep(dt);
  const auto& xBuild = broadPhase.positionsAtBuild();
  const Vec3 lo = box.lowerCorner(), hi = box.upperCorner();
  const Mat3 deformation = Periodic ? broadPhase.cellDeformation(cell) : Mat3::Identity();
  // Per chunk: the IntegrateSum terms; the sums were cut for the particles by the contact stage.
  ChunkedSums& sums = integrateSums_;

  // Spheres under local damping take the vectorised kernel (core/kernels/integrate_simd.hpp), a
  // chunk at a time after the chunk's gather: the same bits as the per-particle kernel.
  const bool vectorised = kernels::simdEnabled() && viscousDamping <= 0.0;
  const Shape* shape = particles.shape.data();
  const bool membraneOn = boundary == Boundary::Membrane;
  if (membraneOn && membraneLoad_.size() != particles.size()) membraneLoad_.assign(particles.size(), Vec3::Zero());
  const Vec3* membraneLoad = membraneLoad_.data();
  kernels::StepChecks checks;
  checks.positionsAtBuild = xBuild.empty() ? nullptr : xBuild.data();
  checks.deformation = deformation;
  checks.radius = particles.radius.data();
  checks.lower = lo;
  checks.upper = hi;

#pragma omp for schedule(static)
  for (std::size_t chunk = 0; chunk < sums.chunks(); ++chunk) {
    double work = 0.0, gravityWork = 0.0;
    const std::size_t first = sums.begin(chunk), last = sums.end(chunk);
    kernels::ParticleWork chunkWork[ChunkedSums::kChunk];
    kernels::ChecksResult r;
    if (vectorised && std::all_of(shape + first, shape + last, [](Shape s) { return s == Shape::Sphere; })) {
      for (std::size_t i = first; i < last; ++i) gatherParticle(i);
      if (membraneOn)
        for (std::size_t i = first; i < last; ++i) particles.force[i] += membraneLoad[i];
      r = kernels::integrateSpheres(view, first, last, stepParams, Periodic, chunkWork, checks);
    } else {
      for (std::size_t i = first; i < last; ++i) {
        gatherParticle(i);
        if (membraneOn) particles.force[i] += membraneLoad[i];
        chunkWork[i - first] = kernels::integrateParticle<Periodic>(view, i, stepParams);
        kernels::checkParticle<Periodic>(view, i, checks, r);
      }
    }
    for (std::size_t i = first; i < last; ++i) {
      work += chunkWork[i - first].damping;
      if (stepParams.gravityOn) gravityWork += chunkWork[i - first].gravity;
    }
    sums.at(chunk, kDampingWork) = work;
    sums.at(chunk, kDisp2) = r.maxDisplacement2;
    sums.at(chunk, kBadParticle) = r.firstBad == kernels::ChecksResult::kNoParticle ? std::numeric_limits<double>::infinity()
                                                                                    : static_cast<double>(r.firstBad);
    sums.at(chunk, kGravityWork) = gravityWork;
  }
  serial([&] { finishIntegration<Periodic>(deformation); });
}

template <bool Periodic>
void Simulation::finishIntegration(const Mat3& deformation) {
  const ChunkedSums& sums = integrateSums_;
  auto& x = particles.position;
  auto& v = particles.velocity;
  auto& w = particles.angularVelocity;
  energy.damping -= sums.total(kDampingWork);
  if (gravity.squaredNorm() > 0.0) energy.gravityWork += sums.total(kGravityWork);
  // The flexible membrane's work on its grains over the step: F . (x_new - x_old) = F . v dt
  // (leapfrog); the rigid cylinder's is counted by its servo, as a wall's.
  if (boundary == Boundary::Membrane && !membrane.rigid)
    for (std::size_t k = 0; k < membrane.grain.size(); ++k)
      energy.boundaryWork += membrane.force[k].dot(v[membrane.grain[k]]) * dt;
  const double maxDisp2 = std::max(0.0, sums.maxOf(kDisp2));
  const double bad = sums.minOf(kBadParticle);
  if (std::isfinite(bad)) {
    const std::size_t i = static_cast<std::size_t>(bad);
    const bool finite = x[i].allFinite() && v[i].allFinite() && w[i].allFinite();
    throw SimulationError(fmt::format(
        "numerical instability at step {}: particle {} {} (position {:.6g} {:.6g} {:.6g}, "
        "velocity {:.6g} {:.6g} {:.6g}); reduce solver.dt_factor or the loading rate",
        stepCount + 1, particles.id[i], finite ? "left the box" : "has a non-finite state", x[i][0], x[i][1],
        x[i][2], v[i][0], v[i][1], v[i][2]));
  }
  const double halfSkin = broadPhase.halfSkin();
  if constexpr (Periodic) {
    // The homogeneous deformation since the build changes a distance b by at most |F^T F - I| b (a
    // rotation changes none); for the pairs that matter, b <= reach + skin, and together with the
    // fluctuations that change must stay within the skin.
    const double affine = (deformation.transpose() * deformation - Mat3::Identity()).norm() *
                          (broadPhase.reach(particles) + broadPhase.skin);
    if (2.0 * std::sqrt(maxDisp2) + affine > broadPhase.skin) rebuildDue_ = true;
  } else {
    if (maxDisp2 > halfSkin * halfSkin) rebuildDue_ = true;
  }
}

// Every field of PeriodicCell but hInverse, which follows from h.
static_assert(stateio::fieldCount<PeriodicCell>() == 16, "PeriodicCell changed: update saveCell/loadCell");

void Simulation::saveCell(std::ostream& out) const {
  using namespace stateio;
  put(out, cell.h);
  put(out, cell.velocityGradient);
  put(out, cell.control);
  put(out, cell.targetStress);
  put(out, cell.strainRate);
  put(out, cell.referenceLength);
  put(out, cell.shearControl);
  put(out, cell.targetShearStress);
  put(out, cell.shearServoIntegral);
  put(out, cell.shearRate);
  put(out, cell.servoIntegral);
  put(out, cell.prescribedGradient);
  put(out, cell.stress);
  put(out, cell.stiffness);
  put(out, cell.shearStiffness);
}

void Simulation::loadCell(std::istream& in) {
  using namespace stateio;
  get(in, cell.h);
  get(in, cell.velocityGradient);
  get(in, cell.control);
  get(in, cell.targetStress);
  get(in, cell.strainRate);
  get(in, cell.referenceLength);
  get(in, cell.shearControl);
  get(in, cell.targetShearStress);
  get(in, cell.shearServoIntegral);
  get(in, cell.shearRate);
  get(in, cell.servoIntegral);
  get(in, cell.prescribedGradient);
  get(in, cell.stress);
  get(in, cell.stiffness);
  get(in, cell.shearStiffness);
  cell.refresh();
}

std::size_t Simulation::touchingPairs() const {
  std::size_t count = 0;
  contacts.forEachPair([&](const auto& list) {
    for (const auto& h : list.history) count += h.touching;
  });
  return count;
}

void Simulation::saveState(std::ostream& out) const {
  using namespace stateio;
  particles.saveState(out);
  put(out, boundary);
  // The box and the model have padding: written field by field into their layout, padding zero.
  static_assert(sizeof(WallBox) == sizeof(box.walls) + sizeof(double) && offsetof(WallBox, referenceVolume) == sizeof(box.walls),
                "WallBox changed: update its writer");
  for (const Wall& w : box.walls)
    putFields(out, w, &Wall::axis, &Wall::side, &Wall::position, &Wall::velocity, &Wall::control, &Wall::targetStress,
              &Wall::tanFriction, &Wall::servoIntegral, &Wall::normalForce, &Wall::contactStiffness, &Wall::contacts);
  put(out, box.referenceVolume);
  saveCell(out);
  put(out, membrane);
  broadPhase.saveState(out);
  contacts.forEach([&](const auto& list) { list.saveState(out); });
  using M = contact::SphereContactModel;
  putFields(out, model, &M::young, &M::poisson, &M::tanFriction, &M::rolling, &M::beta, &M::eta, &M::combine,
            &M::yadeMomentLimit, &M::constantKn, &M::law, &M::restitutionBeta, &M::referenceStress);
  put(out, servo);
  put(out, energy);
  put(out, gravity);
  put(out, dt);
  put(out, localDamping);
  put(out, viscousDamping);
  put(out, stepCount);
  put(out, time);
  put(out, rebuildDue_);
}

void Simulation::loadState(std::istream& in) {
  using namespace stateio;
  particles.loadState(in);
  get(in, boundary);
  get(in, box);
  loadCell(in);
  get(in, membrane);
  broadPhase.loadState(in);
  contacts.forEach([&](auto& list) { list.loadState(in); });
  get(in, model);
  get(in, servo);
  get(in, energy);
  get(in, gravity);
  get(in, dt);
  get(in, localDamping);
  get(in, viscousDamping);
  get(in, stepCount);
  get(in, time);
  get(in, rebuildDue_);
  // Everything above is raw data from a file: check it before anything is derived from it.
  validateState();
  particles.deriveAfterLoad();
  contacts.forEach([&](auto& list) { list.deriveAfterLoad(particles.size()); });
  membraneLoad_.clear();
  if (boundary == Boundary::Membrane) refreshMembrane();
}

}  // namespace grainlab
