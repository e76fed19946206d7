#include "lab/micro_network.hpp"

#include "core/contact_view.hpp"
#include "lab/measurements.hpp"

namespace grainlab::lab {

MicroNetwork microNetwork(const Simulation& sim) {
  const Particles& P = sim.particles;
  MicroNetwork net;
  net.particles.resize(P.size());
  const bool frictionless = !(sim.model.tanFriction > 0.0);
  for (std::size_t i = 0; i < P.size(); ++i) {
    MicroParticle& m = net.particles[i];
    m.id = static_cast<std::int64_t>(P.id[i]);
    m.centre = P.position[i];
    m.radius = P.radius[i];
    m.frictionless = frictionless;
    if (P.shape[i] == Shape::Ellipsoid) {
      m.shape = MicroParticle::Shape::Ellipsoid;
      m.semiAxes = P.semiAxes[i];
      m.longAxis = P.orientation[i] * Vec3::UnitX();  // a lies on the body x axis
    }
  }
  forEachTouchingContact(sim, [&](const ContactView& c) {
    MicroContact m;
    m.a = static_cast<std::int64_t>(P.id[c.a]);
    if (c.wall) {
      // The analysis takes the particle as A and the wall as B: normal from the particle to the
      // wall and the force of the particle on the wall.
      m.wall = true;
      m.b = c.b;
      m.normal = -c.normal;
      m.force = -c.force;
      m.branchA = c.armA;
    } else {
      m.b = static_cast<std::int64_t>(P.id[c.b]);
      m.normal = c.normal;
      m.force = c.force;
      m.branchA = c.armA;
      m.branchB = c.armB;
    }
    net.contacts.push_back(m);
  });
  net.volume = sim.volume();
  if (sim.boundary == Boundary::Periodic) {
    net.measuredStress = 0.5 * (sim.cell.stress + sim.cell.stress.transpose());
  } else {
    net.measuredStress = Mat3(boundaryStress(sim).asDiagonal());
  }
  return net;
}

}  // namespace grainlab::lab
