#pragma once
// ParaView snapshots: VTK XML unstructured grids (.vtu) for particles, the contact network and the
// walls, each indexed in time by a .pvd collection. Files are written whole and renamed.
#include <filesystem>
#include <string>
#include <vector>

#include "core/simulation.hpp"

namespace grainlab::io {

// Extra per-particle fields computed outside the engine (e.g. kinematics).
struct PointFields {
  std::vector<std::pair<std::string, std::vector<double>>> scalars;
  std::vector<std::pair<std::string, std::vector<Vec3>>> vectors;
};

class VtkSeries {
 public:
  // `labels`: the snapshots an interrupted run already wrote (resume continues the numbering).
  explicit VtkSeries(std::filesystem::path dir, std::vector<double> labels = {})
      : dir_(std::move(dir)), labels_(std::move(labels)) {}
  // Writes particles_NNNN.vtu, contacts_NNNN.vtu, walls_NNNN.vtu (cell_NNNN.vtu in a periodic cell)
  // and updates the three .pvd files;
  // `label` is the collection's time value (the axial strain during shearing).
  void write(const Simulation& sim, double label, const PointFields& extra = {});
  const std::vector<double>& labels() const { return labels_; }

 private:
  std::filesystem::path dir_;
  std::vector<double> labels_;
};

// The three grids as text (exposed for tests).
std::string particlesVtu(const Simulation& sim, const PointFields& extra = {});
std::string contactsVtu(const Simulation& sim);
// The boundary: six wall quads, or the periodic cell (cellVtu) when the simulation has one.
std::string wallsVtu(const Simulation& sim);
std::string cellVtu(const Simulation& sim);

}  // namespace grainlab::io
