#include "io/vtk.hpp"

#include <fmt/format.h>

#include <array>
#include <cstdint>

#include "io/results.hpp"
#include "core/contact_view.hpp"
#include "io/vtu_piece.hpp"
#include "lab/measurements.hpp"

namespace grainlab::io {

std::string particlesVtu(const Simulation& sim, const PointFields& extra) {
  const Particles& P = sim.particles;
  const std::size_t n = P.size();
  const std::vector<int> counts = lab::contactsPerParticle(sim);
  std::vector<double> contacts(counts.begin(), counts.end()), ids(n);
  for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<double>(P.id[i]);
  VtuPiece v;
  v.points(P.position);
  for (std::size_t i = 0; i < n; ++i) v.cell({static_cast<std::int64_t>(i)}, VtuPiece::kVertex);
  v.pointScalar("id", ids);
  v.pointScalar("radius", P.radius);
  v.pointVector("velocity", P.velocity);
  v.pointVector("angular_velocity", P.angularVelocity);
  v.pointScalar("contacts", contacts);
  v.pointScalar("mu_r", P.rollingFriction);
  // Shape and orientation: the semi-axes, each body axis scaled by its semi-axis (for arrow glyphs
  // of the long axis), and Q diag(a, b, c) Q^T, whose Tensor Glyph in ParaView is the grain itself.
  std::vector<Vec3> semiAxes(n), axisA(n);
  std::vector<Mat3> shapeTensor(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Mat3 r = P.orientation[i].toRotationMatrix();
    semiAxes[i] = P.semiAxes[i];
    axisA[i] = P.semiAxes[i][0] * r.col(0);
    shapeTensor[i] = r * P.semiAxes[i].asDiagonal() * r.transpose();
  }
  v.pointVector("semi_axes", semiAxes);
  v.pointVector("axis_a", axisA);
  v.pointTensor("shape_tensor", shapeTensor);
  if (sim.boundary == Boundary::Membrane) {  // what the membrane presses on each grain with
    std::vector<Vec3> load(n, Vec3::Zero());
    for (std::size_t k = 0; k < sim.membrane.grain.size(); ++k) load[sim.membrane.grain[k]] += sim.membrane.force[k];
    v.pointVector("membrane_force", load);
  }
  for (const auto& [name, values] : extra.scalars) v.pointScalar(name, values);
  for (const auto& [name, values] : extra.vectors) v.pointVector(name, values);
  return v.text();
}

std::string contactsVtu(const Simulation& sim) {
  // Lines between the centres; a contact across a face of a periodic cell is drawn to the image of
  // its second body (an extra point), not across the cell.
  std::vector<Vec3> points = sim.particles.position;
  VtuPiece v;
  std::vector<double> fn, ft;
  std::vector<Vec3> force, normal;
  forEachTouchingContact(sim, [&](const ContactView& c) {
    if (c.wall) return;
    std::int64_t end = c.b;
    const Vec3 image = sim.particles.position[c.a] + c.branch;
    if ((image - sim.particles.position[c.b]).squaredNorm() > 1e-24 * c.branch.squaredNorm()) {
      end = static_cast<std::int64_t>(points.size());
      points.push_back(image);
    }
    v.cell({c.a, end}, VtuPiece::kLine);
    fn.push_back(c.force.dot(c.normal));
    ft.push_back((c.force - c.force.dot(c.normal) * c.normal).norm());
    force.push_back(c.force);
    normal.push_back(c.normal);
  });
  v.points(points);
  v.cellScalar("normal_force", fn);
  v.cellScalar("tangential_force", ft);
  v.cellVector("force", force);
  v.cellVector("normal", normal);
  return v.text();
}

std::string membraneVtu(const Simulation& sim) {
  // The membrane as it is measured: one quad per bin at its radius rho_b (the row's mean radius
  // where a bin is empty), with the radial stress on it; and the two platens as polygons of the
  // mean radius, with their stresses.
  const Membrane& m = sim.membrane;
  const double dTheta = 2.0 * kPi / m.around, dz = m.height / m.along;
  const double meanRadius = m.equivalentRadius();
  VtuPiece v;
  std::vector<Vec3> points;
  std::vector<double> stress, radius;
  auto corner = [&](double rho, int a, double z) {
    const double theta = -kPi + a * dTheta;
    points.emplace_back(m.axisX + rho * std::cos(theta), m.axisY + rho * std::sin(theta), z);
    return static_cast<std::int64_t>(points.size() - 1);
  };
  const double p = m.radialStress();
  for (int k = 0; k < m.along; ++k)
    for (int a = 0; a < m.around; ++a) {
      const std::size_t b = static_cast<std::size_t>(k) * static_cast<std::size_t>(m.around) + static_cast<std::size_t>(a);
      const double rho = b < m.binGrain.size() && m.binGrain[b] >= 0 ? m.binRho[b] : meanRadius;
      const double z0 = m.bottom + k * dz;
      v.cell({corner(rho, a, z0), corner(rho, a + 1, z0), corner(rho, a + 1, z0 + dz), corner(rho, a, z0 + dz)},
             VtuPiece::kQuad);
      stress.push_back(b < m.binGrain.size() && m.binGrain[b] >= 0 ? p : 0.0);
      radius.push_back(rho);
    }
  for (int side = 0; side < 2; ++side) {
    std::vector<std::int64_t> ring;
    for (int a = 0; a < m.around; ++a) ring.push_back(corner(meanRadius, a, sim.box.walls[WallBox::index(2, side)].position));
    v.cell(ring, VtuPiece::kPolygon);
    stress.push_back(sim.wallStress(WallBox::index(2, side)));
    radius.push_back(meanRadius);
  }
  v.points(points);
  v.cellScalar("normal_stress", stress);
  v.cellScalar("radius", radius);
  return v.text();
}

std::string wallsVtu(const Simulation& sim) {
  if (sim.boundary == Boundary::Periodic) return cellVtu(sim);
  if (sim.boundary == Boundary::Membrane) return membraneVtu(sim);
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

std::string cellVtu(const Simulation& sim) {
  // The periodic cell as one hexahedron with corners H (i, j, k), i, j, k in {0, 1}, in VTK's
  // corner order, and its stress as cell data.
  const Mat3& h = sim.cell.h;
  static constexpr int kOrder[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                       {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  std::vector<Vec3> corners;
  for (const auto& c : kOrder) corners.push_back(h * Vec3(c[0], c[1], c[2]));
  VtuPiece v;
  v.points(corners);
  v.cell({0, 1, 2, 3, 4, 5, 6, 7}, VtuPiece::kHexahedron);
  const Mat3& s = sim.cell.stress;
  v.cellVector("stress_diagonal", {Vec3(s(0, 0), s(1, 1), s(2, 2))});
  v.cellVector("stress_shear_yz_xz_xy", {Vec3(0.5 * (s(1, 2) + s(2, 1)), 0.5 * (s(0, 2) + s(2, 0)), 0.5 * (s(0, 1) + s(1, 0)))});
  return v.text();
}

void VtkSeries::write(const Simulation& sim, double label, const PointFields& extra) {
  const std::size_t index = labels_.size();
  writeFileAtomic(dir_ / fmt::format("particles_{:04d}.vtu", index), particlesVtu(sim, extra));
  writeFileAtomic(dir_ / fmt::format("contacts_{:04d}.vtu", index), contactsVtu(sim));
  const char* boundary = sim.boundary == Boundary::Periodic   ? "cell"
                         : sim.boundary == Boundary::Membrane ? "membrane"
                                                              : "walls";
  writeFileAtomic(dir_ / fmt::format("{}_{:04d}.vtu", boundary, index), wallsVtu(sim));
  labels_.push_back(label);
  for (const char* kind : {"particles", "contacts", boundary})
    writeFileAtomic(dir_ / fmt::format("{}.pvd", kind), pvdCollection(kind, labels_));
}

}  // namespace grainlab::io
