#pragma once
// The DEM engine: particles of any supported shape in a box of rigid walls or in a periodic cell.
// One call of step() runs the engine stages, listed in one place (engineStages()):
//
//   broad phase (Verlet list, rebuilt when due) -> contacts (one driver instantiated per pair kind)
//   -> boundary forces (wall sums / cell stress) -> boundary control (wall servos / cell servo)
//   -> integrate (per particle: force gather in fixed order + damping + leapfrog) -> clock
//
// Laboratory protocols run the same stages inside a Pipeline (core/pipeline.hpp) with their own
// drives, recorders and stop conditions around them.
#include <iosfwd>
#include <string>
#include <vector>

#include "contact/models.hpp"
#include "core/broad_phase.hpp"
#include "core/contact_list.hpp"
#include "core/particles.hpp"
#include "core/periodic_cell.hpp"
#include "core/servo_settings.hpp"
#include "core/walls.hpp"
#include "geometry/ellipsoid_shape.hpp"

namespace grainlab {

// Cumulative energy terms tracked by the engine [J] (PHYSICS.md §7.6, partial).
struct EnergyLedger {
  double slip = 0.0;
  double rolling = 0.0;
  double damping = 0.0;
  double boundaryWork = 0.0;  // work done on the particles by the walls or the deforming cell
};

enum class Boundary : std::uint8_t { Walls = 0, Periodic = 1 };

class Simulation {
 public:
  Particles particles;
  Boundary boundary = Boundary::Walls;
  WallBox box;         // Boundary::Walls
  PeriodicCell cell;   // Boundary::Periodic
  ContactStore contacts;
  BroadPhase broadPhase;
  contact::SphereContactModel model;
  ServoSettings servo;
  EnergyLedger energy;

  Vec3 gravity = Vec3::Zero();  // [m/s^2]; off in the triaxial tests of [W]
  double dt = 0.0;            // [s]
  double localDamping = 0.3;  // Cundall alpha [-]
  // [O]'s viscous mass- and inertia-proportional damping alpha [1/s] (PHYSICS.md §4), integrated by
  // the midpoint rule; when > 0 it replaces the local damping.
  double viscousDamping = 0.0;
  long stepCount = 0;
  double time = 0.0;          // [s]

  // Sets the neighbour skin from the particle sizes; call after adding particles or changing the
  // boundary.
  void initialise(double skinFraction = 0.2);
  // Critical time step (PHYSICS.md §4): min over particles of sqrt(m/Kn) and sqrt(I/K_theta) for
  // the stiffest contact the particle can have (against a wall).
  double criticalTimeStep() const;
  // One step: every engine stage in order.
  void step();

  // The engine stages, in the order step() runs them.
  struct EngineStage {
    const char* name;
    void (Simulation::*run)();
  };
  static const std::vector<EngineStage>& engineStages();

  // Volume enclosed by the boundary [m^3].
  double volume() const { return boundary == Boundary::Periodic ? cell.volume() : box.volume(); }
  // Number of touching particle–particle contacts at the latest step.
  std::size_t touchingPairs() const;
  // Moves particle order[k] to storage index k (ids stay with their particles); contacts, their
  // history and the broad phase follow.
  void reorder(const std::vector<std::uint32_t>& order);

  // Exact binary state for checkpoints: a loaded simulation continues bit for bit.
  void saveState(std::ostream& out) const;
  void loadState(std::istream& in);
  // Consistency of a loaded state before it is stepped (state_validate.cpp): sizes agree, indices
  // in range, numbers finite. Throws InputError saying what is wrong.
  void validateState() const;

 private:
  void updateBroadPhase();
  void computeContacts();
  void measureBoundary();
  void controlBoundary();
  void integrate();
  void advanceClock();
  void gatherParticle(std::size_t i);
  template <bool Periodic>
  void computeContactsFor();
  template <bool Periodic>
  void integrateFor();
  void controlWalls();
  void controlCell();
  void setCellGradient();
  void wrapIntoCell();
  void saveCell(std::ostream& out) const;
  void loadCell(std::istream& in);
  bool rebuildDue_ = true;
  std::vector<geometry::Sym3> shapeMatrices_;  // scratch of the contact stage (ellipsoids)
};

}  // namespace grainlab
