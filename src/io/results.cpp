#include "io/results.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>

#include "core/errors.hpp"
#include "io/input_file.hpp"

namespace grainlab::io {

void createDirectories(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw FileError(fileErrorMessage("cannot create the folder", dir, ec.value()));
}

void writeFileAtomic(const std::filesystem::path& path, const std::string& content) {
  if (path.has_parent_path()) createDirectories(path.parent_path());
  const std::filesystem::path tmp = path.string() + fmt::format(".tmp{}", ::getpid());
  auto failWith = [&](int err, int fd) {
    if (fd >= 0) ::close(fd);
    ::unlink(tmp.c_str());
    throw FileError(fileErrorMessage("cannot write", path, err));
  };
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw FileError(fileErrorMessage("cannot write", path, errno));
  std::size_t done = 0;
  while (done < content.size()) {
    const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) failWith(errno, fd);
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) failWith(errno, -1);
  if (::rename(tmp.c_str(), path.c_str()) != 0) failWith(errno, -1);
}

TimeseriesColumns timeseriesColumns(const lab::RunConfig& config) {
  TimeseriesColumns c;
  c.periodic = config.test.boundary == "periodic";
  c.simpleShear = lab::info(config.test.type).strain == lab::DrivingStrain::Shear;
  c.trueTriaxial = config.test.type == lab::TestType::TrueTriaxial;
  c.undrained = lab::info(config.test.type).drainage && config.test.drainage == lab::Drainage::Undrained;
  c.cyclic = config.test.type == lab::TestType::CyclicTriaxial || config.test.type == lab::TestType::CyclicSimpleShear;
  c.reversing = config.test.type == lab::TestType::Oedometer || c.cyclic;
  c.loops = !config.test.unloadReloadAt.empty();
  c.stressPath = config.test.type == lab::TestType::StressPath;
  c.cyclicShear = config.test.type == lab::TestType::CyclicSimpleShear;
  c.gravity = config.sample.gravity.has_value();
  return c;
}

std::string timeseriesCsv(const std::vector<lab::Record>& records, const TimeseriesColumns& columns) {
  std::string s =
      "step,time,eps1,eps_v,sigma1,sigma2,sigma3,q,p,e,phi_deg,Z,unbalanced,eps2,eps3,"
      "inertial_number,sigma1_contact,sigma2_contact,sigma3_contact,E_kinetic,E_elastic,"
      "W_boundary,D_slip,D_roll,D_damping,rotation_mean_deg,rotation_band_mean_deg,band_fraction,"
      "band_inclination_deg,band_thickness_d50,rotation_outside_band_mean_deg,rotation_band_std_deg,"
      "rotation_outside_band_std_deg,band_measured";
  if (columns.periodic) s += ",eps1_log,stress_skew";
  if (columns.simpleShear) s += ",gamma,tau";
  if (columns.trueTriaxial) s += ",b";
  s += ",energy_residual";
  for (const auto& name : columns.micro) s += "," + name;
  if (columns.loops) s += ",loop_phase";
  if (columns.undrained) s += ",u";
  if (columns.cyclic) s += ",cycle";
  if (columns.reversing) s += ",load_direction";
  if (columns.stressPath) s += ",s,segment";
  if (columns.cyclicShear) s += ",amplitude";
  if (columns.gravity) s += ",W_gravity";
  s += '\n';
  auto put = [&](long step, double v) {
    if (!std::isfinite(v))
      throw SimulationError(fmt::format("non-finite value in the time series at step {}", step));
    s += fmt::format(",{:.10g}", v);
  };
  for (const auto& r : records) {
    const double values[] = {r.time, r.eps1, r.epsV, r.sigma1, r.sigma2, r.sigma3, r.q, r.p, r.e,
                             r.phiDeg, r.coordination, r.unbalanced, r.eps2, r.eps3,
                             r.inertialNumber, r.sigma1Contact, r.sigma2Contact, r.sigma3Contact,
                             r.kinetic, r.elastic, r.workBoundary, r.dissipSlip, r.dissipRoll,
                             r.dissipDamping};
    s += fmt::format("{}", r.step);
    for (double v : values) put(r.step, v);
    // The rotation means, the band fraction and the band's plane: an empty field where not measured
    // (lab/kinematics.hpp, lab/shear_band.hpp).
    for (double v : {r.rotationMeanDeg, r.rotationBandMeanDeg, r.bandFraction, r.bandInclinationDeg,
                     r.bandThicknessD50, r.rotationOutsideMeanDeg, r.rotationBandStdDeg, r.rotationOutsideStdDeg})
      s += std::isfinite(v) ? fmt::format(",{:.10g}", v) : std::string(",");
    s += r.bandMeasured != 0.0 ? ",1" : ",0";
    if (columns.periodic) {
      put(r.step, r.eps1Log);
      put(r.step, r.stressSkew);
    }
    if (columns.simpleShear) {
      put(r.step, r.gamma);
      put(r.step, r.tau);
    }
    auto nullable = [&](double v) {
      if (std::isnan(v)) s += ",";
      else put(r.step, v);
    };
    if (columns.trueTriaxial) nullable(r.b);
    nullable(r.energyResidual);
    for (std::size_t k = 0; k < columns.micro.size(); ++k) nullable(r.micro.at(k));
    if (columns.loops) s += fmt::format(",{}", r.loopPhase);
    if (columns.undrained) put(r.step, r.u);
    if (columns.cyclic) put(r.step, r.cycle);
    if (columns.reversing) s += fmt::format(",{}", r.loadDirection);
    if (columns.stressPath) {
      put(r.step, r.pathS);
      s += fmt::format(",{}", r.pathSegment);
    }
    if (columns.cyclicShear) s += fmt::format(",{}", r.pathSegment);
    if (columns.gravity) put(r.step, r.workGravity);
    s += '\n';
  }
  return s;
}

}  // namespace grainlab::io
