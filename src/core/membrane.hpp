#pragma once
// A flexible membrane around a cylindrical sample between the two platens of a wall box
// (Boundary::Membrane; docs/physics.md §8.3). The membrane is not a body of its own: it is the cell
// pressure, plus the hoop tension of a thin elastic sleeve, applied to the grains of the lateral
// surface, found afresh every step from the current geometry.
//
// The lateral surface is cut into `around` x `along` bins (equal angles about the sample's axis,
// equal heights between the platens). In each bin the grain whose outer surface reaches furthest
// from the axis (centre in the bin, largest rho = |x - axis|_r + r) sets the membrane's radius
// rho_b there; the bin carries the inward radial force p_b A_b, with A_b = dtheta rho_b dz its patch
// of membrane at that radius and p_b = cell pressure + the sleeve's hoop term
// E_m t max(0, R_row - R0) / (R0 R_row), R_row the mean rho_b of the bin's row, shared by the bin's grains within `shell` of rho_b (weight
// falling linearly from 1 at rho_b to 0 at rho_b - shell). Were it given to the outermost grain
// alone, the load would jump between two grains of nearly equal rho at every step, and the sample
// would never come to rest.
// A bin with no grain (a hole in the surface) carries nothing; the load it would have had is shared
// by the filled bins in proportion to their area, so that the total radial force is always the
// pressure times the whole membrane area. The enclosed volume is sum_b dtheta rho_b^2 dz / 2 (an empty
// bin takes the mean radius of the filled ones).
//
// Known limits (docs/physics.md §8.3): the membrane touches one grain per bin and spans straight
// over the dips between them (the volume is that of the envelope of the outermost grains, a little
// above the true one, as for a rigid wall); it carries no axial load and no shear (it is not bonded
// to the platens and slides freely on the grains); grains are spheres.
#include <cmath>
#include <cstdint>
#include <tuple>
#include <vector>

#include "core/particles.hpp"
#include "core/types.hpp"

namespace grainlab {

// Pressure: the cell pressure is the target; ConstantVolume: the pressure is servoed so that the
// enclosed volume stays at referenceVolume (an undrained test on a dry sample).
enum class MembraneControl : std::uint8_t { Pressure = 0, ConstantVolume = 1 };

struct Membrane {
  double axisX = 0.0, axisY = 0.0;  // the sample's axis (vertical, z) [m]
  int around = 0;                   // bins about the axis
  int along = 0;                    // bins between the platens
  MembraneControl control = MembraneControl::Pressure;
  double pressure = 0.0;            // cell pressure [Pa] (compression positive)
  double stiffness = 0.0;           // E_m t of the sleeve [N/m]; 0: a pressure alone
  double referenceRadius = 0.0;     // unstretched sleeve radius R0 [m]; 0: no hoop term yet
  double referenceVolume = 0.0;     // ConstantVolume: the volume kept [m^3]
  // ConstantVolume: the pressure is base + K eps, eps = (V - V_ref) / V_ref, K = volumeGain x the
  // sample's confined modulus (a stiff pore fluid), and base learns volumeIntegral x K eps per step
  // so that eps goes to zero. An integral servo alone oscillates: the volume answers a change of
  // pressure only after a wave has crossed the sample, tens of steps later.
  double volumeGain = 0.02;
  double volumeIntegral = 2e-3;
  double basePressure = 0.0;        // [Pa]
  // Depth of the loaded shell [m]: a bin's load is shared by its grains whose rho is within `shell`
  // of the outermost one, with weights 1 - (rho_max - rho) / shell, so that the load moves
  // continuously from one grain to the next as they overtake each other.
  double shell = 0.0;
  // Rigid: while the sample is prepared and consolidated the lateral boundary is a smooth rigid
  // cylinder of radius `radius` (a linear normal penalty, a grain's wall stiffness, on every grain
  // that reaches past it), servoed to the cell pressure like a wall; the flexible membrane takes over at
  // the start of the test (the practice of DEM membrane studies: prepare in rigid walls, then
  // install the membrane). A pressure on the outermost grains keeps a sample from ever coming to
  // rest (its surface grains take turns at carrying it): fine while a test shears, not for the
  // equilibria of the preparation.
  bool rigid = true;
  double radius = 0.0;         // [m]
  double servoIntegral = 0.0;  // inward speed [m/s]
  double contactStiffness = 0.0;  // sum of the penalty over the grains touching the cylinder [N/m]
  // Measured by the membrane stage every step, from the positions the contacts saw:
  double volume = 0.0;              // enclosed volume [m^3]
  double bottom = 0.0;              // lower platen [m]
  double height = 0.0;              // platen gap [m]
  double area = 0.0;                // membrane area, sum of A_b over every bin (rigid: the cylinder's) [m^2]
  double radialForce = 0.0;         // sum of the inward radial forces [N]
  double hoopPressure = 0.0;        // area-weighted mean of the sleeve's hoop term [Pa]
  int filledBins = 0;
  std::vector<double> binRho;        // per bin (theta fastest): rho of its outermost grain, 0 if empty
  std::vector<std::int64_t> binGrain;  // that grain's index, -1 if empty
  std::vector<std::uint32_t> grain;  // the loaded grains, in particle order
  std::vector<Vec3> force;           // the force on each [N]

  template <class Self>
  static auto fields(Self& s) {
    return std::tie(s.axisX, s.axisY, s.around, s.along, s.control, s.pressure, s.stiffness, s.referenceRadius,
                    s.referenceVolume, s.volumeGain, s.volumeIntegral, s.basePressure, s.shell, s.rigid, s.radius, s.servoIntegral, s.contactStiffness, s.volume, s.bottom, s.height, s.area, s.radialForce, s.hoopPressure,
                    s.filledBins, s.binRho, s.binGrain, s.grain, s.force);
  }

  // The radial stress the membrane puts on the sample [Pa]: cell pressure plus the hoop term.
  double radialStress() const { return area > 0.0 ? radialForce / area : 0.0; }
  // The bin of a point between the platens of the last measure() (theta fastest).
  std::size_t binOf(const Vec3& x) const;
  // Whether a point is inside the membrane as last measured (its bin's radius; an empty bin's the
  // mean) and between the platens: the region whose volume is `volume`.
  bool contains(const Vec3& x) const;
  // Mean radius of a right cylinder of the enclosed volume and height, sqrt(V / (pi H)) [m].
  double equivalentRadius() const;
  // The platens' area [m^2]: the rigid cylinder's cross-section, or the flexible membrane's mean
  // cross-section V / H (the laboratory's area correction for a right cylinder).
  double platenArea() const { return rigid ? kPi * radius * radius : height > 0.0 ? volume / height : 0.0; }

  // One step of the membrane: measure(), servo() when ConstantVolume, applyPressure().
  // measure: the outermost grain of every bin for the platens at zLow < zHigh, the volume, the area.
  void measure(const Particles& particles, double zLow, double zHigh);
  // ConstantVolume: the pressure for the measured volume, for a sample of confined modulus
  // `modulus` [Pa]; never below zero.
  void servo(double modulus);
  // The radial bin loads for the current `pressure` (after a servo), from the last measure().
  void applyPressure(const Particles& particles);
  // Rigid: the cylinder's penalty forces (after measure()), and its servo to `pressure` over one
  // step of dt with the wall servo's gain, integral steps and speed cap.
  // `stiffness(r)` is the normal stiffness of a grain of radius r against a wall [N/m].
  template <class Stiffness>
  void applyCylinder(const Particles& particles, Stiffness&& stiffness) {
    grain.clear();
    force.clear();
    radialForce = hoopPressure = contactStiffness = 0.0;
    for (std::size_t i = 0; i < particles.size(); ++i) {
      const double dx = particles.position[i][0] - axisX, dy = particles.position[i][1] - axisY;
      const double rr = std::hypot(dx, dy);
      const double overlap = rr + particles.radius[i] - radius;
      if (!(overlap > 0.0) || !(rr > 0.0)) continue;
      const double k = stiffness(particles.radius[i]);
      const double f = k * overlap;
      grain.push_back(static_cast<std::uint32_t>(i));
      force.push_back(Vec3(-f * dx / rr, -f * dy / rr, 0.0));
      radialForce += f;
      contactStiffness += k;
    }
  }
  void servoCylinder(double dt, double gain, double integralSteps, double maxSpeed);
};

}  // namespace grainlab
