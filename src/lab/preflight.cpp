#include "lab/preflight.hpp"

#include <fmt/format.h>

#include <cfloat>
#include <cmath>

#include "core/errors.hpp"
#include "io/input_file.hpp"
#include "lab/protocols.hpp"

namespace grainlab::lab {

namespace {

constexpr double kMembraneMinDiameterD50 = 8.0;

// Finite and not subnormal (zero allowed where `zeroAllowed`).
bool usable(double v, bool zeroAllowed) { return std::isfinite(v) && (std::abs(v) >= DBL_MIN || (zeroAllowed && v == 0.0)); }

// Derived parameters of every grain: what the engine divides by or multiplies into forces.
void checkDerived(const RunConfig& c, const Simulation& sim) {
  const Particles& P = sim.particles;
  const std::string source = c.sample.packing.empty() ? "sample.grading, sample.density" : "sample.packing, sample.density";
  const std::string stiffness = c.contact.kn                       ? "contact.kn"
                                : c.contact.model == "hertz-mindlin" ? "contact.shear_modulus"
                                                                    : "contact.young";
  for (std::size_t i = 0; i < P.size(); ++i) {
    const double r = P.radius[i];
    auto refuse = [&](const char* what, double v, const std::string& keys) {
      throw InputError(fmt::format("config error: {}: grain {} (radius {:.6g} m) has {} = {:.6g}, which is not a finite, "
                                   "normal number; allowed: values for which every derived parameter is finite and "
                                   "normal (|x| >= 2.2e-308)",
                                   keys, P.id[i], r, what, v));
    };
    if (!usable(P.mass[i], false)) refuse("mass = density x volume", P.mass[i], source);
    if (!usable(P.inertia[i], false)) refuse("moment of inertia", P.inertia[i], source);
    const double kn = sim.model.maxNormalStiffness(r);
    if (!usable(kn, false)) refuse("normal stiffness Kn", kn, stiffness + ", " + source);
    const double ks = sim.model.maxShearStiffness(r);
    if (!usable(ks, true)) refuse("shear stiffness Ks", ks, stiffness + ", contact.poisson");
    const double kr = sim.model.maxRotationalStiffness(r) - ks * r * r;
    if (!usable(kr, true))
      refuse("rolling stiffness Kr = beta x Ks x R^2", kr, stiffness + ", contact.beta, contact.poisson");
    if (!P.rollingFriction.empty() && !usable(P.rollingFriction[i], true))
      refuse("rolling friction mu_r", P.rollingFriction[i], "contact.sphericity (mu_r = c psi^k)");
  }
  const double dtc = sim.criticalTimeStep();
  if (!usable(dtc, false) || !usable(sim.dt, false))
    throw InputError(fmt::format("config error: {}, {}: the critical time step is {:.6g} s and dt {:.6g} s, not finite "
                                 "and normal numbers; allowed: stiffnesses, densities and sizes that give a usable time step",
                                 stiffness, source, dtc, sim.dt));
}

// The steps of the test phase, final strain / (rate x dt), against solver.max_steps.
void checkTestSteps(const RunConfig& c, const Simulation& sim, double d50) {
  const TestConfig& t = c.test;
  // The oedometer's and the cyclic tests' lengths follow from the sample's response (where the stress
  // reaches its target, when it liquefies), not from a final strain: solver.max_steps guards them.
  if (t.type == TestType::Isotropic || t.type == TestType::Oedometer || t.type == TestType::CyclicTriaxial ||
      t.type == TestType::CyclicSimpleShear || t.type == TestType::StressPath)
    return;
  const bool shear = t.type == TestType::SimpleShear;
  const std::optional<double> given = shear ? t.shearStrainRate : t.axialStrainRate;
  const double rate = given.value_or(Laboratory::kAutoInertialNumber / (d50 * std::sqrt(c.sample.density / t.confiningPressure)));
  const double final = shear ? t.finalShearStrain : t.finalAxialStrain;
  const double steps = final / (rate * sim.dt);
  if (std::isfinite(steps) && steps <= static_cast<double>(c.solver.maxSteps)) return;
  const std::string rateKey = shear ? "test.shear_strain_rate" : "test.axial_strain_rate";
  const std::string finalKey = shear ? "test.final_shear_strain" : "test.final_axial_strain";
  const std::string rateText =
      given ? fmt::format("{} = {:.6g}", rateKey, rate)
            : fmt::format("{} = \"auto\" (= {:.6g} 1/s from inertial number {} x sqrt(test.confining_pressure / "
                          "sample.density) / d50, d50 = {:.6g} m)",
                          rateKey, rate, Laboratory::kAutoInertialNumber, d50);
  throw InputError(fmt::format(
      "config error: {}: the test needs about {:.3g} steps ({} = {:.6g} / (rate x dt = {:.6g} s)), above solver.max_steps "
      "= {}; allowed: a rate of at least {:.3g} 1/s, a larger solver.max_steps, or a smaller {}",
      rateText, steps, finalKey, final, sim.dt, c.solver.maxSteps,
      final / (static_cast<double>(c.solver.maxSteps) * sim.dt), finalKey));
}

}  // namespace

void preflight(const RunConfig& config, const Simulation* packed) {
  const std::uint64_t n = packed ? packed->particles.size() : static_cast<std::uint64_t>(config.sample.nParticles);
  const std::uint64_t need = estimatedRunBytes(n), have = io::physicalMemoryBytes();
  if (have > 0 && need > have)
    throw InputError(fmt::format("config error: {} = {}: a run of {} particles needs about {:.1f} GiB (~{} bytes per "
                                 "particle), more than this machine's {:.1f} GiB of memory; allowed: at most about {} "
                                 "particles here",
                                 packed ? "sample.packing particles" : "sample.n_particles", n, n,
                                 static_cast<double>(need) / (1ull << 30), kBytesPerParticle,
                                 static_cast<double>(have) / (1ull << 30), (have - std::min(have, estimatedRunBytes(0))) / kBytesPerParticle));
  Laboratory lab(config);
  lab.checkSample(packed);
  if (lab.simulation().boundary == Boundary::Membrane) {
    // A band 8-20 d50 thick (x-ray studies) needs room: refuse a cylinder under kMembraneMinDiameterD50
    // across once compacted (the cloud shrinks to about (1 + e0) / (1 + e_placement) of its volume).
    const double shrink = std::cbrt((1.0 + config.sample.e0) / (1.0 + config.sample.initialVoidRatio));
    const double across = 2.0 * lab.simulation().membrane.radius * shrink / lab.d50();
    if (across < kMembraneMinDiameterD50) {
      const double need = static_cast<double>(config.sample.nParticles) * std::pow(kMembraneMinDiameterD50 / across, 3.0);
      throw InputError(fmt::format(
          "config error: sample.n_particles = {}: a membrane sample of {} grains would be about {:.1f} d50 across, too "
          "small to hold a shear band; allowed: a diameter of at least {:g} d50, about {:.0f} grains or more at "
          "test.aspect_ratio = {:g}",
          config.sample.nParticles, config.sample.nParticles, across, kMembraneMinDiameterD50, std::ceil(need),
          config.test.aspectRatio));
    }
  }
  checkDerived(config, lab.simulation());
  checkTestSteps(config, lab.simulation(), lab.d50());
}

}  // namespace grainlab::lab
