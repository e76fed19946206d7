#pragma once
// Micromechanics snapshots: the contact network and the particles of a run at chosen instants, so
// that `grainlab analyse DIR` can recompute the analysis later without rerunning. Plain CSV in
// DIR/micro/ (docs/micromechanics.md §5 documents every column):
//
//   snapshots.csv        index,step,eps1,volume,sxx,syy,szz,sxy,sxz,syz    (one row per snapshot;
//                        the measured stress, compression positive, or six empty fields)
//   particles_NNNN.csv   id,shape,x,y,z,a,b,c,ux,uy,uz,frictionless      (shape sphere: a = radius,
//                        b..uz empty; ellipsoid: semi-axes a ≥ b ≥ c, unit long axis u)
//   contacts_NNNN.csv    a,b,nx,ny,nz,fx,fy,fz,ax,ay,az,bx,by,bz          (b = particle id or wK for
//                        wall K, whose branch bx..bz is empty; f = force of A on B; a.., b.. =
//                        contact point − centre of A, of B)
//
// Numbers are written with 17 significant digits (the analysis of a read snapshot is that of the
// written network). Each file is written whole and renamed; the index is rewritten last.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lab/micromechanics.hpp"

namespace grainlab::io {

struct MicroSnapshotInfo {
  int index = 0;                // NNNN of the two files
  long step = 0;                // engine step when taken
  double eps1 = 0.0;            // axial strain when taken
  double volume = 0.0;          // V [m³]
  std::optional<Mat3> stress;   // measured stress [Pa], compression positive (symmetric)
};

// Writes the snapshots of one run into a folder (DIR/micro), numbering them on from `previous`
// (the snapshots an interrupted run already wrote, e.g. kept in its checkpoint).
class MicroSnapshotSeries {
 public:
  explicit MicroSnapshotSeries(std::filesystem::path dir, std::vector<MicroSnapshotInfo> previous = {})
      : dir_(std::move(dir)), snapshots_(std::move(previous)) {}
  void write(const lab::MicroNetwork& network, long step, double eps1);
  const std::vector<MicroSnapshotInfo>& snapshots() const { return snapshots_; }

 private:
  std::filesystem::path dir_;
  std::vector<MicroSnapshotInfo> snapshots_;
};

// The list of snapshots as a checkpoint keeps it (so that a resumed run numbers on as an
// uninterrupted one), and back; the reader throws InputError on anything malformed.
nlohmann::json microSnapshotsJson(const std::vector<MicroSnapshotInfo>& snapshots);
std::vector<MicroSnapshotInfo> microSnapshotsFromJson(const nlohmann::json& list, const std::string& where);

std::string microIndexCsv(const std::vector<MicroSnapshotInfo>& snapshots);
std::string microParticlesCsv(const lab::MicroNetwork& network);
std::string microContactsCsv(const lab::MicroNetwork& network);

// Readers. A missing, unreadable or malformed file throws InputError naming the file, the line,
// the field and its value (cut to 80 characters) and what is allowed.
std::vector<MicroSnapshotInfo> readMicroIndex(const std::filesystem::path& dir);
lab::MicroNetwork readMicroSnapshot(const std::filesystem::path& dir, const MicroSnapshotInfo& info);

}  // namespace grainlab::io
