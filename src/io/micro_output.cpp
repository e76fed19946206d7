#include "io/micro_output.hpp"

#include <fmt/format.h>

#include <cmath>

#include "io/vtu_piece.hpp"

namespace grainlab::io {

using nlohmann::json;

namespace {

constexpr double kFourPi = 4.0 * kPi;

// Appends ",value" (",": a null) to a CSV row.
void appendField(std::string& row, const std::optional<double>& v) {
  row += ',';
  if (v && std::isfinite(*v)) row += fmt::format("{:.10g}", *v);
}

std::optional<double> finiteOrNull(double v) { return std::isfinite(v) ? std::optional<double>(v) : std::nullopt; }

// E(n) of the fitted fabric: (1 + a^r:nn (+ A^r::nnnn))/4π.
std::optional<double> fittedDensity(const lab::MicroAnalysis& m, const Vec3& n) {
  if (!m.ar) return std::nullopt;
  double e = 1.0 + n.dot(m.ar->tensor * n);
  if (m.ar4) e += lab::contract4(*m.ar4, n);
  return e / kFourPi;
}

// f̄ⁿ(n) of the fit: f0 (1 + aⁿ:nn (+ Aⁿ::nnnn)).
std::optional<double> fittedNormalForce(const lab::MicroAnalysis& m, const Vec3& n) {
  if (!m.an || !m.f0) return std::nullopt;
  double g = 1.0 + n.dot(m.an->tensor * n);
  if (m.an4) g += lab::contract4(*m.an4, n);
  return *m.f0 * g;
}

std::optional<double> measuredDensity(const lab::MicroAnalysis& m, const lab::OrientationClasses& oc, std::size_t k) {
  const std::size_t nc = m.coordination.particleContacts;
  if (nc == 0) return std::nullopt;
  return static_cast<double>(m.classes.count[k]) / (2.0 * static_cast<double>(nc) * oc.area(k));
}

json matrix(const Mat3& a) {
  return json::array({{a(0, 0), a(0, 1), a(0, 2)}, {a(1, 0), a(1, 1), a(1, 2)}, {a(2, 0), a(2, 1), a(2, 2)}});
}
json optionalMatrix(const std::optional<Mat3>& a) { return a ? matrix(*a) : json(nullptr); }
json optionalNumber(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }
json anisotropy(const std::optional<lab::Anisotropy>& a) {
  if (!a) return nullptr;
  return {{"tensor", matrix(a->tensor)},
          {"magnitude", a->magnitude},
          {"principal", {a->principal[0], a->principal[1], a->principal[2]}}};
}
json tensor4(const std::optional<lab::Tensor4>& t) {
  if (!t) return nullptr;
  return {{"components", std::vector<double>(t->begin(), t->end())}, {"norm", lab::norm4(*t)}};
}
std::optional<double> meanStress(const std::optional<Mat3>& s) {
  return s ? std::optional<double>(s->trace() / 3.0) : std::nullopt;
}
std::optional<double> meanStress(const Mat3& s) { return s.trace() / 3.0; }

}  // namespace

std::string orientationClassesCsv(const lab::OrientationClasses& oc, const lab::MicroAnalysis& m) {
  std::string s =
      "class,nx,ny,nz,area,count,density,density_fit,fn_mean,fn_fit,ft_x,ft_y,ft_z,ln_mean,lt_x,lt_y,lt_z,"
      "c0x,c0y,c0z,c1x,c1y,c1z,c2x,c2y,c2z,c3x,c3y,c3z\n";
  const auto& ca = m.classes;
  for (std::size_t k = 0; k < oc.size(); ++k) {
    const Vec3& n = oc.centre(k);
    s += fmt::format("{},{:.10g},{:.10g},{:.10g},{:.10g},{}", k, n[0], n[1], n[2], oc.area(k), ca.count[k]);
    appendField(s, measuredDensity(m, oc, k));
    appendField(s, fittedDensity(m, n));
    appendField(s, finiteOrNull(ca.meanNormalForce[k]));
    appendField(s, fittedNormalForce(m, n));
    for (int i = 0; i < 3; ++i) appendField(s, finiteOrNull(ca.meanTangentialForce[k][i]));
    appendField(s, finiteOrNull(ca.meanBranchNormal[k]));
    for (int i = 0; i < 3; ++i) appendField(s, finiteOrNull(ca.meanBranchTangential[k][i]));
    for (const Vec3& c : oc.corners(k)) s += fmt::format(",{:.10g},{:.10g},{:.10g}", c[0], c[1], c[2]);
    s += '\n';
  }
  return s;
}

std::string orientationClassesVtu(const lab::OrientationClasses& oc, const lab::MicroAnalysis& m) {
  const double nan = std::nan("");
  auto value = [&](const std::optional<double>& v) { return v ? *v : nan; };
  std::vector<Vec3> points, normals, tangential;
  std::vector<double> count, area, density, densityFit, fn, fnFit, ln;
  VtuPiece v;
  for (std::size_t k = 0; k < oc.size(); ++k) {
    const auto corners = oc.corners(k);
    const auto first = static_cast<std::int64_t>(points.size());
    points.insert(points.end(), corners.begin(), corners.end());
    v.cell({first, first + 1, first + 2, first + 3}, VtuPiece::kQuad);
    const Vec3& n = oc.centre(k);
    normals.push_back(n);
    count.push_back(static_cast<double>(m.classes.count[k]));
    area.push_back(oc.area(k));
    density.push_back(value(measuredDensity(m, oc, k)));
    densityFit.push_back(value(fittedDensity(m, n)));
    fn.push_back(m.classes.meanNormalForce[k]);
    fnFit.push_back(value(fittedNormalForce(m, n)));
    tangential.push_back(m.classes.meanTangentialForce[k]);
    ln.push_back(m.classes.meanBranchNormal[k]);
  }
  v.points(points);
  v.cellScalar("count", count);
  v.cellScalar("area", area);
  v.cellScalar("density", density);
  v.cellScalar("density_fit", densityFit);
  v.cellScalar("mean_normal_force", fn);
  v.cellScalar("fit_normal_force", fnFit);
  v.cellVector("mean_tangential_force", tangential);
  v.cellScalar("mean_branch_length", ln);
  v.cellVector("normal", normals);
  return v.text();
}

std::string microAnalysisCsv(const std::vector<AnalysedSnapshot>& rows, const lab::MicroColumnSet& set) {
  std::string s =
      "index,step,eps1,Z,particles,contacts,wall_contacts,rattlers,empty_classes,q_over_p,q_over_p_contacts,"
      "q_over_p_particle_contacts,p,p_contacts,p_particle_contacts,p_sff,sff_error_measured";
  for (const auto& name : lab::microColumnNames(set)) {
    s += ',';
    s += name;
  }
  s += '\n';
  for (const auto& [info, m] : rows) {
    const auto& c = m.coordination;
    s += fmt::format("{},{},{:.10g},{:.10g},{},{},{},{},{}", info.index, info.step, info.eps1, c.Z, c.particles,
                     c.particleContacts, c.wallContacts, c.rattlers, m.emptyClasses);
    for (const auto& v : {m.qOverPMeasured, m.qOverPContacts, m.qOverPParticleContacts, meanStress(m.stressMeasured),
                          meanStress(m.stressAllContacts), meanStress(m.stressParticleContacts),
                          meanStress(m.stressSff), m.sffErrorMeasured})
      appendField(s, v);
    for (const auto& v : lab::microRowValues(m, set)) appendField(s, v);
    s += '\n';
  }
  return s;
}

json microAnalysisJson(const AnalysedSnapshot& s) {
  const lab::MicroAnalysis& m = s.analysis;
  const auto& c = m.coordination;
  return {
      {"index", s.info.index},
      {"step", s.info.step},
      {"eps1", s.info.eps1},
      {"volume", s.info.volume},
      {"particles", c.particles},
      {"contacts", c.particleContacts},
      {"wall_contacts", c.wallContacts},
      {"Z", c.Z},
      {"Z_mech", optionalNumber(c.Zmech)},
      {"rattlers", c.rattlers},
      {"rattler_fraction", c.rattlerFraction},
      {"contact_histogram", c.histogram},
      {"fabric", matrix(m.fabric)},
      {"a_r", anisotropy(m.ar)},
      {"a_n", anisotropy(m.an)},
      {"a_t", anisotropy(m.at)},
      {"a_v", anisotropy(m.av)},
      {"a_tau", anisotropy(m.atau)},
      {"a_E", anisotropy(m.aE)},
      {"a_r4", tensor4(m.ar4)},
      {"a_n4", tensor4(m.an4)},
      {"f0", optionalNumber(m.f0)},
      {"l0", optionalNumber(m.l0)},
      {"empty_classes", m.emptyClasses},
      {"non_spherical", m.nonSpherical},
      {"stress_measured", optionalMatrix(m.stressMeasured)},
      {"stress_contacts", matrix(m.stressAllContacts)},
      {"stress_particle_contacts", matrix(m.stressParticleContacts)},
      {"stress_sff", optionalMatrix(m.stressSff)},
      {"stress_sff_linear", optionalMatrix(m.stressSffLinear)},
      {"q_over_p", optionalNumber(m.qOverPMeasured)},
      {"q_over_p_contacts", optionalNumber(m.qOverPContacts)},
      {"q_over_p_particle_contacts", optionalNumber(m.qOverPParticleContacts)},
      {"q_over_p_sff", optionalNumber(m.qOverPSff)},
      {"q_over_p_sff_linear", optionalNumber(m.qOverPSffLinear)},
      {"sff_error", optionalNumber(m.sffError)},
      {"sff_error_measured", optionalNumber(m.sffErrorMeasured)},
  };
}

}  // namespace grainlab::io
