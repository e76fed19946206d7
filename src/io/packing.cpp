#include "io/packing.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/errors.hpp"

namespace grainlab::io {

std::string packingText(const Simulation& sim, const std::string& comment) {
  std::string s = "# " + comment + "\n";
  for (const Wall& w : sim.box.walls) s += fmt::format("{:.17g} ", w.position);
  s += "\n";
  for (std::size_t i = 0; i < sim.particles.size(); ++i) {
    const Vec3& x = sim.particles.position[i];
    s += fmt::format("{:.17g} {:.17g} {:.17g} {:.17g}\n", sim.particles.radius[i], x[0], x[1], x[2]);
  }
  return s;
}

void loadPacking(const std::filesystem::path& file, double density, Simulation& sim) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("config error: sample.packing = \"{}\": cannot be read", file.string()));
  auto bad = [&](int line, const std::string& what) {
    return InputError(fmt::format("config error: sample.packing = \"{}\": line {}: {}", file.string(), line, what));
  };
  std::string line;
  int lineNo = 0;
  std::array<double, 6> walls{};
  bool haveWalls = false;
  Particles particles;
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    if (!haveWalls) {
      for (double& w : walls)
        if (!(fields >> w) || !std::isfinite(w)) throw bad(lineNo, "expected six wall positions xlo xhi ylo yhi zlo zhi");
      for (int a = 0; a < 3; ++a)
        if (!(walls[2 * a + 1] > walls[2 * a])) throw bad(lineNo, "each upper wall must lie above its lower wall");
      haveWalls = true;
      continue;
    }
    double r, x, y, z;
    if (!(fields >> r >> x >> y >> z) || !(r > 0.0) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
      throw bad(lineNo, "expected 'radius x y z' with radius > 0 [m]");
    particles.addSphere(Vec3(x, y, z), r, density);
  }
  if (particles.size() < 2) throw bad(lineNo, "fewer than two spheres");
  sim.particles = std::move(particles);
  sim.boundary = Boundary::Walls;
  sim.box.setBounds(Vec3(walls[0], walls[2], walls[4]), Vec3(walls[1], walls[3], walls[5]));
}

}  // namespace grainlab::io
