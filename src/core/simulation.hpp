#pragma once
// The DEM engine: particles of any supported shape in a box of rigid walls or in a periodic cell.
// One call of step() runs the engine stages, listed in one place (engineStages(Boundary)):
//
//   broad phase (Verlet list, rebuilt when due) -> contacts (one driver instantiated per pair kind)
//   -> boundary forces (walls: wall sums; a cell's stress is summed by the contacts) -> boundary control
//   (wall servos / cell servo) -> integrate (per particle: gather + damping + leapfrog) -> clock
//
// Laboratory protocols run the same stages inside a Pipeline (core/pipeline.hpp) with their own
// drives, recorders and stop conditions around them.
#include <array>
#include <atomic>
#include <exception>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "contact/models.hpp"
#include "core/broad_phase.hpp"
#include "core/contact_list.hpp"
#include "core/membrane.hpp"
#include "core/parallel.hpp"
#include "core/particles.hpp"
#include "core/periodic_cell.hpp"
#include "core/servo_settings.hpp"
#include "core/walls.hpp"
#include "geometry/ellipsoid_shape.hpp"

namespace grainlab {

// Cumulative energy terms tracked by the engine [J] (docs/physics.md §10, partial).
struct EnergyLedger {
  double slip = 0.0;
  double rolling = 0.0;
  double damping = 0.0;       // local or viscous damping of the particles, and Hertz–Mindlin's dashpots
  double boundaryWork = 0.0;  // work done on the particles by the walls or the deforming cell
  double gravityWork = 0.0;   // work done on the particles by gravity, sum of m g . dx (-dE_potential)
};

// The engine stage that failed during a step, shared by the threads of the step's team (an atomic,
// but copyable: a copied simulation starts its next step clean).
struct StageFlag {
  static constexpr int kNone = 1 << 30;
  std::atomic<int> stage{kNone};
  StageFlag() = default;
  StageFlag(const StageFlag&) {}
  StageFlag& operator=(const StageFlag&) {
    stage.store(kNone, std::memory_order_relaxed);
    return *this;
  }
};

// Membrane: a cylindrical sample between the z walls of the box (the platens) inside a flexible
// membrane (core/membrane.hpp); the box's x and y walls stand well clear of it.
enum class Boundary : std::uint8_t { Walls = 0, Periodic = 1, Membrane = 2 };

class Simulation {
 public:
  Particles particles;
  Boundary boundary = Boundary::Walls;
  WallBox box;         // Boundary::Walls
  PeriodicCell cell;   // Boundary::Periodic
  Membrane membrane;   // Boundary::Membrane (with the z walls of `box`)
  ContactStore contacts;
  BroadPhase broadPhase;
  contact::SphereContactModel model;
  ServoSettings servo;
  EnergyLedger energy;

  Vec3 gravity = Vec3::Zero();  // [m/s^2]; off in the triaxial tests of [W]
  double dt = 0.0;            // [s]
  double localDamping = 0.3;  // Cundall alpha [-]
  // [O]'s viscous mass- and inertia-proportional damping alpha [1/s] (docs/physics.md §5), integrated by
  // the midpoint rule; when > 0 it replaces the local damping.
  double viscousDamping = 0.0;
  long stepCount = 0;
  double time = 0.0;          // [s]

  // Sets the neighbour skin from the particle sizes; call after adding particles or changing the
  // boundary.
  void initialise(double skinFraction = 0.2);
  // Critical time step (docs/physics.md §7): min over particles of sqrt(m/Kn) and sqrt(I/K_theta) for
  // the stiffest contact the particle can have (against a wall).
  double criticalTimeStep() const;
  // What a stage reads and writes, declared with the stage (docs/architecture.md, "One step").
  enum Access : unsigned {
    kNothing = 0,
    kPositions = 1u << 0,         // positions, images
    kVelocities = 1u << 1,        // translational velocities
    kRotations = 1u << 2,         // orientations, angular velocities and momenta
    kForces = 1u << 3,            // per-particle force and torque
    kContacts = 1u << 4,          // contact lists, their history and results
    kBoundary = 1u << 5,          // walls or cell: geometry, velocities, servo state, stresses
    kEnergy = 1u << 6,            // the energy ledger
    kClock = 1u << 7,             // step count and time
    kLaboratory = 1u << 8,        // the laboratory's own records (outside the engine)
  };
  // Names of the set bits, e.g. "positions, velocities".
  static std::string accessNames(unsigned access);

  // A stage from outside the engine (a laboratory pipeline's, core/pipeline.hpp) that step() runs
  // inside the step, right after engine stage `after`. Its body gets a range [begin, end) of
  // particles and may write only to items in that range; every thread of the step's team runs it on
  // its static share, so the result does not depend on the thread count. It must not throw.
  struct InnerStage {
    std::size_t after = 0;  // index in stages()
    std::function<void(std::size_t begin, std::size_t end)> particles;
  };
  // One step: every engine stage in order, inside one OpenMP parallel region (one fork/join per
  // step), with `inner` stages (if given) after the engine stages they name. Stages share the team:
  // loops are work-shared, serial parts run on one thread between barriers (serial()). An error in
  // a serial part skips the rest of the step and is rethrown here.
  void step(const std::vector<InnerStage>* inner = nullptr);

  // The engine stages of a boundary kind, in the order step() runs them (stages() for this one's).
  struct EngineStage {
    const char* name;
    void (Simulation::*run)();
    bool serial;      // runs on one thread (the others wait); otherwise its loops are shared out
    unsigned reads;   // Access bits
    unsigned writes;  // Access bits
  };
  static const std::vector<EngineStage>& engineStages(Boundary kind);
  const std::vector<EngineStage>& stages() const { return engineStages(boundary); }
  // The index of the engine stage called `name` (std::invalid_argument when there is none).
  static std::size_t engineStageIndex(Boundary kind, const std::string& name);

  // Volume enclosed by the boundary [m^3].
  double volume() const {
    return boundary == Boundary::Periodic ? cell.volume() : boundary == Boundary::Membrane ? membrane.volume : box.volume();
  }
  // The area a wall's force is spread over [m^2]: the box's face, or a membrane sample's mean
  // cross-section for the platens.
  double wallArea(int axis) const {
    return boundary == Boundary::Membrane && axis == 2 ? membrane.platenArea() : box.area(axis);
  }
  // Wall k's stress [Pa], compression positive, over wallArea.
  double wallStress(int k) const { return box.walls[k].normalForce / wallArea(box.walls[k].axis); }
  // The membrane's grains and forces of the current step, from its lists (after a load or a change
  // made outside step()).
  void refreshMembrane();
  // The flexible membrane replaces the rigid cylinder of the preparation, its loads measured from
  // the current positions.
  void installFlexibleMembrane();
  // Number of touching particle–particle contacts at the latest step.
  std::size_t touchingPairs() const;

  // Exact binary state for checkpoints: a loaded simulation continues bit for bit.
  void saveState(std::ostream& out) const;
  void loadState(std::istream& in);
  // Consistency of a loaded state before it is stepped (state_validate.cpp): sizes agree, indices
  // in range, numbers finite. Throws InputError saying what is wrong.
  void validateState() const;

 private:
  void updateBroadPhase();
  void measureWalls();
  void controlWallStage();
  void controlCellStage();
  void membraneStage();
  void advanceClock();
  void gatherParticle(std::size_t i);
  template <bool Periodic>
  void computeContactsFor();
  template <bool Periodic>
  void integrateFor();
  // The serial ends of the stages (one thread, inside serial()).
  template <bool Periodic>
  void sumContactTerms(bool ellipsoids);
  void sumWallForces(int group, int groups);
  template <bool Periodic>
  void finishIntegration(const Mat3& deformation);
  void controlWalls();
  void controlWallVolume();
  void controlCell();
  void setCellGradient();
  void wrapIntoCell();
  void saveCell(std::ostream& out) const;
  void loadCell(std::istream& in);
  // Runs `body` on one thread of the team (all threads wait at its end); an exception is kept and
  // rethrown by step() after the parallel region, and the stages after it are skipped.
  template <class F>
  void serial(F&& body);
  // Per particle, the membrane's force of the step (zero off the surface): filled from
  // membrane.grain/force, added after the gather.
  std::vector<Vec3> membraneLoad_;
  bool rebuildDue_ = true;
  bool rebuilding_ = false;  // the broad phase is rebuilding in this step (set by its serial part)
  std::vector<geometry::Sym3> shapeMatrices_;  // scratch of the contact stage (ellipsoids)
  // Per-chunk sums of the step, shared by the team (core/parallel.hpp): contact energies and cell
  // terms per pair kind, then the integrator's terms below.
  enum IntegrateSum : int {
    kDampingWork = 0,  // work of the damping forces
    kDisp2,            // largest squared displacement since the list was built
    kBadParticle,      // first particle that went bad (+inf when none)
    kGravityWork,      // work of gravity, m g . dx (summed only when gravity is on)
    kIntegrateSums,
  };
  ChunkedSums pairSums_, wallSums_, eeSums_, seSums_, ewSums_, integrateSums_;
  std::array<bool, 5> writeAll_{};
  // Index of the engine stage whose serial part threw during the current step (a large value when
  // none); the stages after it do nothing.
  StageFlag failedStage_;
  std::exception_ptr stageError_;
};

}  // namespace grainlab
