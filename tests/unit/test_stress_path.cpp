// The stress-path protocol (lab/protocol/stress_path.cpp) on the frictionless face-centred cubic
// lattice of test_boundary_control.cpp, whose elastic constants follow from the lattice alone
// (C11 = 2 kn/a, C12 = kn/a along a cubic axis, a the lattice constant):
//   - a strain-controlled path (axial strain, no lateral strain, then back) must track the table's
//     strains exactly (the drive is dead-beat) and give K0 = C12/C11 = 1/2 and d sigma_z/d eps =
//     C11, and return to the start stresses;
//   - a stress-controlled path (axial stress up by d sigma, lateral stresses held) must end at the
//     uniaxial-stress strains of the cubic crystal: eps_z = d sigma / E, E = (C11 - C12)(C11 + 2
//     C12)/(C11 + C12) = 4/3 kn/a, and eps_x = -nu eps_z with nu = C12/(C11 + C12) = 1/3.
// And the reader of path files: every defect an InputError naming the line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "io/list_files.hpp"
#include "core/errors.hpp"
#include "lab/boundary_control.hpp"
#include "lab/protocol/shear_protocol.hpp"
#include "lab/stress_path.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

namespace {

struct Lattice {
  Simulation sim;
  double a = 0.0, kn = 1e6;
};
Lattice fcc(int n, double overlap) {
  Lattice l;
  const double d = 2e-3;
  l.a = d * std::sqrt(2.0) * (1.0 - overlap);
  Simulation& sim = l.sim;
  sim = scenes::emptyScene(1.0, 0.0);
  sim.model.beta = 0.0;
  sim.model.constantKn = l.kn;
  sim.localDamping = 0.3;
  sim.boundary = Boundary::Periodic;
  sim.cell.setBox(Vec3::Constant(n * l.a));
  const Vec3 basis[4] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const Vec3& s : basis) sim.particles.addSphere((Vec3(i, j, k) + s + Vec3::Constant(0.25)) * l.a, 0.5 * d, 2600.0);
  sim.initialise();
  sim.dt = 0.3 * sim.criticalTimeStep();
  return l;
}

lab::PathPoint point(double s, std::array<double, 3> v, std::array<lab::PathControl, 3> c) {
  lab::PathPoint p;
  p.s = s;
  p.value = v;
  p.control = c;
  return p;
}

constexpr lab::PathControl St = lab::PathControl::Stress, Sn = lab::PathControl::Strain;

// Runs the protocol to its end at `rate` (no ramp), calling `each` after every step.
template <class Each>
long runPath(Simulation& sim, lab::BoundaryControl& b, lab::ShearProtocol& p, double rate, Each each) {
  p.configure(b);
  long steps = 0;
  while (!p.finished(b)) {
    p.drive(b, rate, 1.0);
    sim.step();
    p.afterStep(b);
    each();
    if (++steps > 1'000'000) ADD_FAILURE() << "the path did not end";
  }
  return steps;
}

}  // namespace

TEST(StressPath, StrainControlledPathTracksTheTableAndGivesK0) {
  Lattice l = fcc(3, 1e-3);
  auto b = lab::BoundaryControl::of(l.sim);
  l.sim.step();
  b->beginTest();
  const Vec3 s0 = b->stress();
  lab::RunConfig c;
  c.test.type = lab::TestType::StressPath;
  c.test.confiningPressure = s0[0];
  const double e = 2e-4;
  c.test.path = {point(e, {0.0, 0.0, e}, {Sn, Sn, Sn}), point(2 * e, {0.0, 0.0, 0.0}, {Sn, Sn, Sn})};
  auto p = lab::ShearProtocol::make(c);
  const double rate = e / (2000 * l.sim.dt);
  Vec3 atTurn = Vec3::Zero();
  double strainAtTurn = 0.0;
  double worstTracking = 0.0;
  runPath(l.sim, *b, *p, rate, [&] {
    const double s = p->progress(*b);
    const double expected = s <= e ? s : 2 * e - s;
    worstTracking = std::max(worstTracking, std::abs(b->strain()[2] - expected));
    if (s <= e + 0.5 * rate * l.sim.dt && s > e - 0.5 * rate * l.sim.dt) {
      atTurn = b->stress();
      strainAtTurn = b->strain()[2];
    }
  });
  EXPECT_LT(worstTracking, 1e-12);
  EXPECT_NEAR(strainAtTurn, e, 1e-12);
  EXPECT_EQ(b->strain()[0], 0.0);
  const Vec3 ds = atTurn - s0;
  // Loaded at a finite rate with damping: the stresses lag the strain slightly (0.5 % allowed).
  EXPECT_NEAR(ds[0] / ds[2], 0.5, 0.005);
  EXPECT_NEAR(ds[2] / e, 2.0 * l.kn / l.a, 0.01 * 2.0 * l.kn / l.a);
  EXPECT_NEAR(b->strain()[2], 0.0, 1e-12);
  for (int i = 0; i < 4000; ++i) {
    p->drive(*b, rate, 1.0);  // after the end: the strains held
    l.sim.step();
  }
  EXPECT_NEAR(b->strain()[2], 0.0, 1e-12);
  EXPECT_NEAR(b->stress()[2], s0[2], 1e-3 * s0[2]);  // elastic: back to the start
  EXPECT_FALSE(p->state.pathFailed);
}

TEST(StressPath, StressControlledPathGivesTheUniaxialStressStrains) {
  Lattice l = fcc(3, 1e-3);
  auto b = lab::BoundaryControl::of(l.sim);
  l.sim.step();
  b->beginTest();
  const Vec3 s0 = b->stress();
  const double dSigma = 0.2 * s0[2];
  lab::RunConfig c;
  c.test.type = lab::TestType::StressPath;
  c.test.confiningPressure = s0[0];
  c.test.path = {point(1e-4, {s0[0], s0[1], s0[2] + dSigma}, {St, St, St})};
  auto p = lab::ShearProtocol::make(c);
  runPath(l.sim, *b, *p, 1e-4 / (4000 * l.sim.dt), [] {});
  // The servos settle on the last targets.
  for (int i = 0; i < 40000; ++i) {
    p->drive(*b, 1.0, 1.0);
    l.sim.step();
  }
  const Vec3 s = b->stress();
  EXPECT_NEAR(s[2] - s0[2], dSigma, 0.01 * dSigma);
  EXPECT_NEAR(s[0], s0[0], 0.01 * dSigma);
  const double young = 4.0 / 3.0 * l.kn / l.a;
  const Vec3 eps = b->strain();
  EXPECT_NEAR(eps[2], dSigma / young, 0.02 * dSigma / young);
  EXPECT_NEAR(eps[0] / eps[2], -1.0 / 3.0, 0.01);
  EXPECT_NEAR(eps[1] / eps[2], -1.0 / 3.0, 0.01);
  EXPECT_LT(p->state.stressDeviationMax, 0.2);
}

// A stress target beyond the sample: the test stops when a strain reaches test.final_axial_strain
// and says so (pathFailed), rather than running on.
TEST(StressPath, AStressTheSampleCannotCarryStopsTheTest) {
  Lattice l = fcc(2, 1e-3);
  auto b = lab::BoundaryControl::of(l.sim);
  l.sim.step();
  b->beginTest();
  const Vec3 s0 = b->stress();
  lab::RunConfig c;
  c.test.type = lab::TestType::StressPath;
  c.test.confiningPressure = s0[0];
  c.test.finalAxialStrain = 1e-3;
  // Lateral stresses to zero: the frictionless lattice flies apart.
  c.test.path = {point(1e-2, {0.0, 0.0, s0[2]}, {St, St, St})};
  auto p = lab::ShearProtocol::make(c);
  runPath(l.sim, *b, *p, 1e-2 / (2000 * l.sim.dt), [] {});
  EXPECT_TRUE(p->state.pathFailed);
  EXPECT_LT(p->state.path, 1e-2);
}

namespace {
std::string writeFile(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("grainlab_path_" + name + ".csv");
  std::ofstream(path) << text;
  return path.string();
}
std::string errorOf(const std::string& text) {
  try {
    io::readStressPathFile(writeFile("bad", text), "test.path.file");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(StressPathFile, ReadsPointsInAnyColumnOrder) {
  const auto pts = io::readStressPathFile(
      writeFile("good", "# a path\nzz,zz_control,s,xx,xx_control,yy,yy_control\n0.01,strain,0.01,1e5,stress,1e5,stress\n"
                        "2e5, stress ,0.02,0,strain,0,strain\n"),
      "test.path.file");
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_EQ(pts[0].s, 0.01);
  EXPECT_EQ(pts[0].value[2], 0.01);
  EXPECT_EQ(pts[0].control[2], lab::PathControl::Strain);
  EXPECT_EQ(pts[0].control[0], lab::PathControl::Stress);
  EXPECT_EQ(pts[1].value[2], 2e5);
  EXPECT_EQ(pts[1].control[0], lab::PathControl::Strain);
}

TEST(StressPathFile, EveryDefectNamesTheLineAndWhatIsAllowed) {
  const std::string header = "s,xx,xx_control,yy,yy_control,zz,zz_control\n";
  EXPECT_NE(errorOf("s,xx,yy,zz\n1,2,3,4\n").find("no column 'xx_control'"), std::string::npos);
  EXPECT_NE(errorOf(header).find("no points"), std::string::npos);
  EXPECT_NE(errorOf(header + "0.01,1e5,stress,1e5,stres,1e5,stress\n").find("line 2: yy_control \"stres\""), std::string::npos);
  EXPECT_NE(errorOf(header + "0.01,1e5,stress,nan,stress,1e5,stress\n").find("not a finite number"), std::string::npos);
  EXPECT_NE(errorOf(header + "0.02,1e5,stress,1e5,stress,1e5,stress\n0.01,1e5,stress,1e5,stress,1e5,stress\n")
                .find("line 3: s = 0.01 must be finite, above the previous"),
            std::string::npos);
  EXPECT_NE(errorOf(header + "0.01,-1,stress,1e5,stress,1e5,stress\n").find("no tension"), std::string::npos);
  EXPECT_NE(errorOf(header + "0.01,0.7,strain,1e5,stress,1e5,stress\n").find("must be a strain in [-0.5, 0.5]"),
            std::string::npos);
  EXPECT_NE(errorOf(header + "0.01,1e5,stress\n").find("missing yy"), std::string::npos);
  EXPECT_NE(errorOf(header + "0,1e5,stress,1e5,stress,1e5,stress\n").find("s = 0 must be"), std::string::npos);
}

// Cyclic simple shear (lab/protocol/cyclic_simple_shear.cpp) on the same lattice at constant
// volume: a central-force FCC crystal sheared in xz has the shear modulus C44 = kn/a (the Cauchy
// relation C44 = C12), the same at every small amplitude, and an elastic loop encloses no area
// (damping ratio ~0: only the local damping of the small velocities acts).
TEST(CyclicSimpleShear, ElasticLatticeGivesC44AndNoDamping) {
  Lattice l = fcc(3, 1e-3);
  auto b = lab::BoundaryControl::of(l.sim);
  l.sim.step();
  b->beginTest();
  lab::RunConfig c;
  c.test.type = lab::TestType::CyclicSimpleShear;
  c.test.drainage = lab::Drainage::Undrained;
  c.test.confiningPressure = b->stress()[2];
  c.test.shearStrainAmplitudes = {1e-5, 1e-4};
  c.test.cyclesPerAmplitude = 1;
  auto p = lab::ShearProtocol::make(c);
  runPath(l.sim, *b, *p, 1.0, [] {});
  const lab::ProtocolState& s = p->state;
  ASSERT_EQ(s.amplitudesDone, 2);
  const double c44 = l.kn / l.a;
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(s.measuredAmplitude[i], c.test.shearStrainAmplitudes[i], 0.01 * c.test.shearStrainAmplitudes[i]);
    EXPECT_NEAR(s.secantModulus[i], c44, 0.02 * c44) << i;
    EXPECT_LT(std::abs(s.dampingRatio[i]), 0.01) << i;
  }
  EXPECT_LT(s.volumeDriftMax, 1e-12);
}
