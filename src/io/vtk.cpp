#include "io/vtk.hpp"

#include <fmt/format.h>

#include <array>
#include <cstdint>

#include "io/results.hpp"
#include "io/vtu_piece.hpp"
#include "lab/measurements.hpp"

namespace grainlab::io {

std::string particlesVtu(const Simulation& sim, const PointFields& extra) {
  const Particles& P = sim.particles;
  const std::size_t n = P.size();
  const std::vector<int> counts = lab::contactsPerParticle(sim);
  std::vector<double> contacts(counts.begin(), counts.end()), angle(n), path(n);
  for (std::size_t i = 0; i < n; ++i) {
    angle[i] = radToDeg(P.rotationAngle(i));
    path[i] = radToDeg(P.rotationPath[i]);
  }
  VtuPiece v;
  v.points(P.position);
  for (std::size_t i = 0; i < n; ++i) v.cell({static_cast<std::int64_t>(i)}, VtuPiece::kVertex);
  v.pointScalar("radius", P.radius);
  v.pointVector("velocity", P.velocity);
  v.pointVector("angular_velocity", P.angularVelocity);
  v.pointScalar("rotation_deg", angle);
  v.pointScalar("rotation_path_deg", path);
  v.pointScalar("contacts", contacts);
  v.pointScalar("mu_r", P.rollingFriction);
  v.pointScalar("sphericity", P.sphericity);
  for (const auto& [name, values] : extra.scalars) v.pointScalar(name, values);
  for (const auto& [name, values] : extra.vectors) v.pointVector(name, values);
  return v.text();
}

std::string contactsVtu(const Simulation& sim) {
  const auto& nl = sim.neighbors;
  VtuPiece v;
  v.points(sim.particles.position);
  std::vector<double> fn, ft;
  std::vector<Vec3> force, normal;
  for (std::size_t p = 0; p < nl.pairA.size(); ++p) {
    if (!nl.pairHistory[p].touching) continue;
    const std::uint32_t a = nl.pairA[p], b = nl.pairB[p];
    const Vec3 n = (sim.particles.position[b] - sim.particles.position[a]).normalized();
    const Vec3& f = sim.pairForce[p];
    v.cell({a, b}, VtuPiece::kLine);
    fn.push_back(f.dot(n));
    ft.push_back((f - f.dot(n) * n).norm());
    force.push_back(f);
    normal.push_back(n);
  }
  v.cellScalar("normal_force", fn);
  v.cellScalar("tangential_force", ft);
  v.cellVector("force", force);
  v.cellVector("normal", normal);
  return v.text();
}

std::string wallsVtu(const Simulation& sim) {
  const WallBox& box = sim.box;
  const Vec3 lo = box.lowerCorner(), hi = box.upperCorner();
  std::vector<Vec3> corners;
  for (int k = 0; k < 8; ++k) corners.emplace_back(k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]);
  VtuPiece v;
  v.points(corners);
  std::vector<double> stress, force;
  std::vector<Vec3> normals;
  for (const Wall& w : box.walls) {
    // The four corners with this wall's coordinate, in cyclic order around the face.
    const int a = w.axis, b = (a + 1) % 3, c = (a + 2) % 3;
    const int bit = w.side << a;
    const std::array<int, 4> order{0, 1 << b, (1 << b) | (1 << c), 1 << c};
    std::vector<std::int64_t> quad;
    for (int o : order) quad.push_back(o | bit);
    v.cell(quad, VtuPiece::kQuad);
    stress.push_back(box.wallStress(static_cast<int>(&w - box.walls.data())));
    force.push_back(w.normalForce);
    normals.push_back(w.inwardNormal());
  }
  v.cellScalar("normal_stress", stress);
  v.cellScalar("normal_force", force);
  v.cellVector("inward_normal", normals);
  return v.text();
}

void VtkSeries::write(const Simulation& sim, double label, const PointFields& extra) {
  const std::size_t index = labels_.size();
  writeFileAtomic(dir_ / fmt::format("particles_{:04d}.vtu", index), particlesVtu(sim, extra));
  writeFileAtomic(dir_ / fmt::format("contacts_{:04d}.vtu", index), contactsVtu(sim));
  writeFileAtomic(dir_ / fmt::format("walls_{:04d}.vtu", index), wallsVtu(sim));
  labels_.push_back(label);
  for (const char* kind : {"particles", "contacts", "walls"})
    writeFileAtomic(dir_ / fmt::format("{}.pvd", kind), pvdCollection(kind, labels_));
}

}  // namespace grainlab::io
