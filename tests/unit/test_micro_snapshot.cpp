// Micromechanics snapshots: a written network reads back bit for bit (so its analysis is the
// same), and damaged files are refused with the file, the line and the offending value named.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>
#include <unistd.h>

#include "core/errors.hpp"
#include "io/micro_output.hpp"
#include "io/micro_snapshot.hpp"

using namespace grainlab;
using namespace grainlab::lab;
namespace fs = std::filesystem;

namespace {

MicroNetwork smallNetwork(bool ellipsoids) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MicroNetwork net;
  net.volume = 1.234e-3;
  net.measuredStress = Mat3(Vec3(1.1e5, 0.99e5, 2.5e5).asDiagonal());
  for (int i = 0; i < 40; ++i) {
    MicroParticle p;
    p.id = 100 + 3 * i;
    p.centre = Vec3(u(rng), u(rng), u(rng)) * 1e-2;
    p.radius = 1e-3 * (1.5 + u(rng));
    if (ellipsoids && i % 2) {
      p.shape = MicroParticle::Shape::Ellipsoid;
      p.semiAxes = Vec3(2e-3, 1.2e-3, 0.9e-3);
      p.longAxis = Vec3(u(rng), u(rng), u(rng)).normalized();
    }
    p.frictionless = i % 7 == 0;
    net.particles.push_back(p);
  }
  for (int c = 0; c < 120; ++c) {
    MicroContact k;
    k.a = 100 + 3 * (c % 40);
    k.wall = c % 11 == 0;
    k.b = k.wall ? c % 6 : 100 + 3 * ((c * 7 + 1) % 40);
    if (!k.wall && k.b == k.a) k.b = 100 + 3 * ((c % 40 + 1) % 40);
    k.normal = Vec3(u(rng), u(rng), u(rng)).normalized();
    k.force = Vec3(u(rng), u(rng), u(rng)) + 2.0 * k.normal;
    k.branchA = 1e-3 * k.normal;
    k.branchB = k.wall ? Vec3::Zero() : Vec3(-1.1e-3 * k.normal);
    net.contacts.push_back(k);
  }
  return net;
}

class SnapshotFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("grainlab_micro_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    io::MicroSnapshotSeries series(dir_);
    series.write(smallNetwork(false), 1000, 0.0);
    series.write(smallNetwork(true), 2000, 0.01);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string read(const std::string& name) {
    std::ifstream in(dir_ / name, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  void write(const std::string& name, const std::string& text) { std::ofstream(dir_ / name, std::ios::binary) << text; }
  // Replaces the first occurrence of `from` in a file.
  void corrupt(const std::string& name, const std::string& from, const std::string& to) {
    std::string s = read(name);
    const auto at = s.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    s.replace(at, from.size(), to);
    write(name, s);
  }
  // The error message of reading every snapshot (empty when it reads).
  std::string readError() {
    try {
      for (const auto& info : io::readMicroIndex(dir_)) io::readMicroSnapshot(dir_, info);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

}  // namespace

TEST_F(SnapshotFiles, RoundTripIsExact) {
  const auto index = io::readMicroIndex(dir_);
  ASSERT_EQ(index.size(), 2u);
  EXPECT_EQ(index[1].step, 2000);
  EXPECT_EQ(index[1].eps1, 0.01);
  for (int s = 0; s < 2; ++s) {
    const MicroNetwork original = smallNetwork(s == 1);
    const MicroNetwork back = io::readMicroSnapshot(dir_, index[s]);
    EXPECT_EQ(back.volume, original.volume);
    ASSERT_TRUE(back.measuredStress.has_value());
    EXPECT_EQ(*back.measuredStress, *original.measuredStress);
    ASSERT_EQ(back.particles.size(), original.particles.size());
    ASSERT_EQ(back.contacts.size(), original.contacts.size());
    for (std::size_t i = 0; i < back.particles.size(); ++i) {
      const auto &p = back.particles[i], &q = original.particles[i];
      EXPECT_EQ(p.id, q.id);
      EXPECT_EQ(p.centre, q.centre);
      EXPECT_EQ(p.shape, q.shape);
      EXPECT_EQ(p.frictionless, q.frictionless);
      if (p.shape == MicroParticle::Shape::Sphere) EXPECT_EQ(p.radius, q.radius);
      else EXPECT_EQ(p.longAxis, q.longAxis);
    }
    for (std::size_t c = 0; c < back.contacts.size(); ++c) {
      const auto &a = back.contacts[c], &b = original.contacts[c];
      EXPECT_EQ(a.a, b.a);
      EXPECT_EQ(a.b, b.b);
      EXPECT_EQ(a.wall, b.wall);
      EXPECT_EQ(a.normal, b.normal);
      EXPECT_EQ(a.force, b.force);
      EXPECT_EQ(a.branchA, b.branchA);
      if (!a.wall) EXPECT_EQ(a.branchB, b.branchB);
    }
    // Hence the same analysis, bit for bit.
    MicroOptions opt;
    opt.classDivisions = 1;
    const MicroAnalyzer analyzer(opt);
    const MicroAnalysis m1 = analyzer.analyse(original), m2 = analyzer.analyse(back);
    EXPECT_EQ(m1.stressAllContacts, m2.stressAllContacts);
    ASSERT_TRUE(m1.an && m2.an);
    EXPECT_EQ(m1.an->tensor, m2.an->tensor);
    EXPECT_EQ(m1.coordination.Zmech, m2.coordination.Zmech);
  }
}

TEST_F(SnapshotFiles, StressMayBeUnmeasured) {
  write("snapshots.csv", "index,step,eps1,volume,sxx,syy,szz,sxy,sxz,syz\n0,5,0,1e-3,,,,,,\n");
  const auto index = io::readMicroIndex(dir_);
  ASSERT_EQ(index.size(), 1u);
  EXPECT_FALSE(index[0].stress.has_value());
}

TEST_F(SnapshotFiles, CorruptedFilesAreRefusedWithFileAndLine) {
  struct Case {
    const char* file;
    std::string from, to;
    std::string expected;  // part of the message
  };
  const std::vector<Case> cases{
      {"contacts_0001.csv", "a,b,nx", "a,c,nx", "header"},
      {"contacts_0001.csv", "\n100,", "\n100,103,1,2\n100,", "contacts_0001.csv: line 2: expected 14"},
      {"contacts_0001.csv", "\n100,", "\n999,", "contacts_0001.csv: line 2: a = '999': is not a particle id"},
      {"contacts_0001.csv", "\n100,w0,", "\n100,wx,", "b = 'wx'"},
      {"contacts_0001.csv", "\n100,w0,", "\n100,w0,nan", "nx = 'nan"},
      {"contacts_0001.csv", "\n100,w0,", "\n100,w0,7,0,0,1,0,0,0.001,0,0,,,\n100,w0,", "must be a unit vector"},
      {"contacts_0001.csv", "\n100,w0,", "\n100,w0,1,0,0,1,0,0,0.001,0,0,1,,\n100,w0,", "bx = '1': must be empty"},
      {"particles_0000.csv", "\n100,sphere", "\n100,cube", "particles_0000.csv: line 2: shape = 'cube'"},
      {"particles_0000.csv", "\n103,sphere", "\n100,sphere", "id = '100': appears twice"},
      {"particles_0001.csv", ",ellipsoid,", ",ellipsoid,1e300x", "line 3: x = '1e300x"},
      {"particles_0000.csv", ",0\n", ",2\n", "frictionless = '2': must be 0 or 1"},
      {"snapshots.csv", "\n1,2000,", "\n1,-2000,", "snapshots.csv: line 3: step = '-2000'"},
      {"snapshots.csv", "\n1,2000,", "\n0,2000,", "index = '0': appears twice"},
  };
  for (const auto& c : cases) {
    SetUp();
    corrupt(c.file, c.from, c.to);
    const std::string error = readError();
    EXPECT_NE(error.find(c.expected), std::string::npos) << c.file << ": got '" << error << "'";
    EXPECT_NE(error.find(c.file), std::string::npos) << error;
  }
  SetUp();
  fs::remove(dir_ / "contacts_0001.csv");
  EXPECT_NE(readError().find("contacts_0001.csv: does not exist"), std::string::npos);
  SetUp();
  write("particles_0001.csv", "id,shape,x,y,z,a,b,c,ux,uy,uz,frictionless\n" + std::string(10000, '1') + "\n");
  EXPECT_NE(readError().find("line 2: line longer than 4096"), std::string::npos) << readError();
  SetUp();
  write("particles_0000.csv", "id,shape,x,y,z,a,b,c,ux,uy,uz,frictionless\n");
  EXPECT_NE(readError().find("no particles"), std::string::npos);
  SetUp();
  write("snapshots.csv", "index,step,eps1,volume,sxx,syy,szz,sxy,sxz,syz\n0,5,0,1e-3,1,2,,,,\n");
  EXPECT_NE(readError().find("all six components"), std::string::npos);
  SetUp();
  corrupt("snapshots.csv", "\n0,1000,0,", "\n0,1000,0,-");
  EXPECT_NE(readError().find("volume = '-"), std::string::npos) << readError();
}

TEST_F(SnapshotFiles, ClassAverageOutputsHaveOneRowOrCellPerClass) {
  const MicroAnalyzer analyzer;
  const MicroAnalysis m = analyzer.analyse(smallNetwork(false));
  const std::string csv = io::orientationClassesCsv(analyzer.classes(), m);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 384);
  const std::string vtu = io::orientationClassesVtu(analyzer.classes(), m);
  EXPECT_NE(vtu.find("NumberOfPoints=\"1536\" NumberOfCells=\"384\""), std::string::npos);
  EXPECT_NE(vtu.find("Name=\"mean_normal_force\""), std::string::npos);
}
