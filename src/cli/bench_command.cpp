// `grainlab bench`: named scenes timed in particle-steps per second.
#include <fmt/format.h>
#include <omp.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <nlohmann/json.hpp>

#include "core/kernels/integrate_simd.hpp"
#include "cli/commands.hpp"
#include "cli/thread_count.hpp"
#include "core/errors.hpp"
#include "io/config.hpp"
#include "io/input_file.hpp"
#include "io/packing.hpp"
#include "io/results.hpp"
#include "lab/measurements.hpp"
#include "lab/protocols.hpp"
#include "lab/random.hpp"

namespace grainlab::cli {

namespace fs = std::filesystem;

namespace {

// Peak resident set of this process [bytes]: VmHWM of /proc/self/status. getrusage's ru_maxrss
// is not used: Linux carries it across exec, so a bench started from a large parent (a Python
// driver with matplotlib loaded) would report the parent's peak.
long peakResidentBytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::atol(line.c_str() + 6) * 1024L;  // kB
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss * 1024L;
}

// The [W] set-up: diameters 2–8 mm (straight passing curve by mass), Ec 30 GPa, nu 0.3, mu 30 deg,
// beta 0.15, eta 1, rho 2600, alpha 0.3, 100 kPa.
lab::RunConfig benchConfig(int n) {
  lab::RunConfig c;
  c.sample.nParticles = n;
  c.sample.prepFrictionDeg = 5.0;
  c.test.type = lab::TestType::Isotropic;
  c.test.confiningPressure = 100e3;
  c.output.plots = false;
  return c;
}

fs::path cacheFile(const std::string& scene, int n) {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  const char* home = std::getenv("HOME");
  fs::path base = xdg ? fs::path(xdg) : (home ? fs::path(home) / ".cache" : fs::temp_directory_path());
  return base / "grainlab" / fmt::format("{}-{}.txt", scene, n);
}

// Scene "lattice": n^3 spheres (n = round(cbrt(N))) on a simple cubic lattice of spacing d50 = 5 mm,
// radii d50/2 (1 + j) with j uniform in [5e-4, 1e-3] (seeded), between fixed walls on the lattice's
// faces: every sphere presses on its six neighbours (or the walls), every lattice line is jammed,
// so the contact density (3 contacts per sphere) does not depend on N or on how many steps run,
// and there is no preparation whose cost grows faster than N. Same law as triaxial-iso. It
// measures how the cost per particle-step scales with N (10^3 to 10^6) and the memory per particle.
void buildLattice(int requested, double density, Simulation& sim) {
  const int n = std::max(2, static_cast<int>(std::lround(std::cbrt(static_cast<double>(requested)))));
  const double a = 5e-3;
  lab::Rng rng(12345);
  sim.particles = Particles{};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double r = 0.5 * a * (1.0 + rng.uniform(5e-4, 1e-3));
        sim.particles.addSphere(Vec3((i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a), r, density);
      }
  sim.box.setBounds(Vec3::Zero(), Vec3::Constant(n * a));
}

}  // namespace

int runBench(const BenchOptions& opt) {
  if (!opt.config.empty() && opt.packing.empty())
    throw InputError("bench --config: applies with --packing only (the scenes have their own law)");
  if (opt.packing.empty() && opt.scene != "triaxial-iso" && opt.scene != "lattice")
    throw InputError(fmt::format("bench scene \"{}\" is unknown; available: triaxial-iso, lattice", opt.scene));
  if (opt.particles < 10) throw InputError(fmt::format("--particles = {}: must be >= 10", opt.particles));
  if (opt.steps < 1) throw InputError(fmt::format("--steps = {}: must be >= 1", opt.steps));
  if (opt.threads < 1 || opt.threads > kMaxThreads)
    throw InputError(fmt::format("--threads = {}: must be in [1, {}]", opt.threads, kMaxThreads));
  lab::RunConfig config = benchConfig(opt.particles);
  if (!opt.config.empty()) config = io::parseConfig(io::loadConfigTable(opt.config), io::configBaseDir(opt.config));
  const fs::path cache = cacheFile(opt.scene, opt.particles);
  const std::string scene = opt.packing.empty() ? opt.scene : "packing";

  Simulation sim;
  setOpenMPThreads(std::max(2, opt.threads));  // preparation uses what is there
  if (!opt.packing.empty()) {
    // Any packing (a run's packing.txt, another program's sample converted): its grains, shapes and
    // boundary as they are, held at the config's pressure by its walls or cell.
    io::simulationFromPacking(io::readPackingFile(opt.packing, "bench --packing"), config.sample.density, sim,
                              fmt::format("bench --packing {}", io::quotedPath(opt.packing)));
  } else if (opt.scene == "lattice") {
    buildLattice(opt.particles, config.sample.density, sim);
  } else if (fs::exists(cache)) {
    const std::string subject = fmt::format("bench cache {}", io::quotedPath(cache));
    io::simulationFromPacking(io::parsePacking(io::readInputFile(cache, subject, io::kMaxPackingBytes), subject),
                              config.sample.density, sim, subject);
  } else {
    if (!opt.json) fmt::print(stderr, "preparing the {}-particle sample (cached in {})\n", opt.particles, cache.string());
    lab::Laboratory lab(config);
    lab.prepare();
    sim = lab.simulation();
    io::writeFileAtomic(cache, io::packingText(io::packingFromSimulation(sim, "grainlab bench sample " + opt.scene)));
  }
  lab::configureSolver(config, sim);
  if (scene != "lattice") lab::holdIsotropicStress(sim, config.test.confiningPressure);
  // A benchmark times the threads it is asked for, but says when other processes share the cores.
  const ThreadChoice choice = chooseThreads(opt.threads, /*adapt=*/false);
  if (!choice.warning.empty()) fmt::print(stderr, "{}\n", choice.warning);
  setOpenMPThreads(opt.threads);
  for (int i = 0; i < 200; ++i) sim.step();  // rebuild contacts and their history
  const long buildsBefore = sim.broadPhase.builds;
  const auto t0 = std::chrono::steady_clock::now();
  for (long i = 0; i < opt.steps; ++i) sim.step();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double rate = static_cast<double>(opt.steps) * sim.particles.size() / seconds;
  const long peakRss = peakResidentBytes();
  std::size_t ellipsoids = 0;
  for (Shape s : sim.particles.shape) ellipsoids += s == Shape::Ellipsoid;
  nlohmann::json j{{"scene", scene},
                   {"packing", opt.packing.empty() ? nlohmann::json(nullptr) : nlohmann::json(opt.packing)},
                   {"boundary", sim.boundary == Boundary::Periodic ? "periodic" : "walls"},
                   {"n_ellipsoids", ellipsoids},
                   {"n_particles", sim.particles.size()},
                   {"n_contacts", sim.touchingPairs()},
                   {"steps", opt.steps},
                   {"seconds", seconds},
                   {"particle_steps_per_s", rate},
                   {"threads", opt.threads},
                   {"simd_target", kernels::simdTarget()},
                   {"dt", sim.dt},
                   {"peak_rss_bytes", peakRss},
                   {"bytes_per_particle", static_cast<double>(peakRss) / sim.particles.size()},
                   {"neighbor_rebuilds", sim.broadPhase.builds - buildsBefore},
                   {"coordination", lab::coordinationNumber(sim)}};
  if (opt.json) {
    fmt::print("{}\n", j.dump());
  } else {
    fmt::print("{}: {} particles, {} contacts, {} steps on {} thread(s), {} kernels: {:.3f} s, {:.3g} particle-steps/s\n",
               scene, sim.particles.size(), sim.touchingPairs(), opt.steps, opt.threads, kernels::simdTarget(), seconds,
               rate);
  }
  return 0;
}

}  // namespace grainlab::cli
