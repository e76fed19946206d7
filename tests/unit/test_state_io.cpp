// Checkpoint state (core/state_io.hpp, Simulation::validateState): a saved and reloaded laboratory
// continues bit for bit; a truncated or inconsistent state is an error, never a crash; and adding a
// field to a checkpointed struct without teaching the writer fails to compile here.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstring>
#include <new>
#include <type_traits>
#include <functional>
#include <optional>
#include <sstream>

#include "core/errors.hpp"
#include "core/state_io.hpp"
#include "lab/protocols.hpp"

using namespace grainlab;

namespace {

// Size of a struct holding these members in this order (each at its alignment, the whole rounded
// up to the largest alignment): what sizeof gives when the listed members are all there is.
template <class... Members>
constexpr std::size_t layoutSize() {
  std::size_t offset = 0, align = 1;
  ((offset = (offset + alignof(Members) - 1) / alignof(Members) * alignof(Members) + sizeof(Members),
    align = std::max(align, alignof(Members))),
   ...);
  return (offset + align - 1) / align * align;
}

// The members of Laboratory's private ShearState, in order (lab/protocols.hpp).
struct ShearStateMembers {
  bool started;
  double h0, v0;
  Vec3 l0;
  long rampSteps, startStep;
  double nextRecord, nextSnapshot, nextCheckpoint;
  Vec3 stressSum;
  double shearStressSum;
  std::array<double, 6> wallStressSum;
  long stressSamples;
  double elastic0, kinetic0;
  lab::ShearResult result;
  int loopNext, loopPhase;
  double loopQ;
  long loopEndStep;
  long loopRestStart;
  bool forceRecord;
  double slowdown;
  double pressureFactor;
  double windowStrain;
  Vec3 windowLengths, previousWindowLengths;
  long bandWindows;
  bool bandFound;
  lab::ShearBand band;
};

}  // namespace

// The structs whose saveState/loadState list their fields by hand. A failure here means a field was
// added (or removed): write and read it in saveState/loadState (or derive it on load, as invMass
// is), then update the list below. Trivially copyable structs (Wall, Record, ...) are written whole
// and need no list; the checkpoint's layout tag (io/checkpoint_file.cpp) changes with their size.
static_assert(stateio::fieldCount<Particles>() == 19,
              "Particles changed: update Particles::saveState/loadState and this count (16 saved + invMass, "
              "invInertia, equivalentRadius derived)");
static_assert(stateio::fieldCount<contact::ContactHistory>() == 5, "ContactHistory changed: update state_io.hpp");
static_assert(sizeof(BroadPhase) ==
                  layoutSize<double, long, std::vector<Vec3>, std::array<double, 6>, Mat3, SpatialGrid, bool, Vec3,
                             double, SpatialGrid::Cell, std::vector<SpatialGrid::Cell>,
                             std::vector<std::vector<PairKey>>>(),
              "BroadPhase changed: update BroadPhase::saveState/loadState and this list (the grid and the fields "
              "of a build under way, which never outlives a step, are scratch)");
static_assert(sizeof(ContactList<SphereSphere>) ==
                  layoutSize<std::vector<std::uint32_t>, std::vector<std::uint32_t>, std::vector<std::uint32_t>,
                             std::vector<contact::ContactHistory>, std::vector<Vec3>, std::vector<Vec3>,
                             std::vector<Vec3>, std::vector<std::uint32_t>, std::vector<std::uint32_t>, bool>(),
              "ContactList changed: update ContactList::saveState/loadState and this list (the CSR is derived)");
static_assert(sizeof(ContactStore) ==
                  layoutSize<ContactList<SphereSphere>, ContactList<SpherePlane>, ContactList<EllipsoidEllipsoid>,
                             ContactList<SphereEllipsoid>, ContactList<EllipsoidPlane>>(),
              "ContactStore changed: its kinds are saved through forEach; update this list");
static_assert(stateio::fieldCount<PeriodicCell>() == 16, "PeriodicCell changed: update Simulation::saveCell/loadCell");
static_assert(stateio::fieldCount<lab::GrainRecords>() == 5, "GrainRecords changed: update its saveState/loadState");
static_assert(sizeof(Simulation) ==
                  layoutSize<Particles, Boundary, WallBox, PeriodicCell, Membrane, ContactStore, BroadPhase,
                             contact::SphereContactModel, ServoSettings, EnergyLedger, Vec3, double, double, double,
                             long, double, std::vector<Vec3>, bool, std::vector<geometry::Sym3>, ChunkedSums, ChunkedSums, ChunkedSums,
                             ChunkedSums, ChunkedSums, ChunkedSums, std::array<bool, 5>, StageFlag,
                             std::exception_ptr>(),
              "Simulation changed: update Simulation::saveState/loadState and this list (shape matrices, the "
              "step's chunk sums and error state are scratch)");
static_assert(sizeof(lab::Laboratory) ==
                  layoutSize<lab::RunConfig, lab::ProgressFn, lab::SnapshotFn, double, lab::CheckpointFn, double,
                             std::unique_ptr<lab::ShearProtocol>, std::unique_ptr<lab::BoundaryControl>,
                             ShearStateMembers, Simulation, lab::GrainRecords, lab::GrainRecords,
                             lab::GrainRecords, lab::MicroAnalyzer,
                             lab::MicroColumnSet, double, std::vector<lab::GrowthStage>,
                             std::optional<lab::DepositionReport>, std::vector<std::vector<double>>,
                             std::optional<lab::UnderCompactionReport>>(),
              "Laboratory changed: update Laboratory::saveState/loadState and this list");
static_assert(std::is_trivially_copyable_v<Wall> && std::is_trivially_copyable_v<lab::Record> &&
              std::is_trivially_copyable_v<contact::SphereContactModel>);

// The writer refuses what it cannot write exactly: Eigen types are not bytewise (written by
// components), nor is a struct holding a vector (its heap pointer would be written).
static_assert(!stateio::Bytewise<Vec3> && !stateio::Bytewise<Quat> && !stateio::Bytewise<lab::ShearResult>);
static_assert(!stateio::Bytewise<bool> && !stateio::Bytewise<double*>);
static_assert(stateio::Bytewise<Wall> && stateio::Bytewise<lab::Record> && stateio::Bytewise<lab::ProtocolState>);

namespace {

lab::RunConfig smallConfig() {
  lab::RunConfig c;
  c.sample.nParticles = 40;
  c.sample.grading.type = "uniform";
  c.sample.grading.dMin = 4e-3;
  c.sample.grading.dMax = 6e-3;
  c.sample.prepFrictionDeg = 0.0;
  c.sample.seed = 5;
  c.test.finalAxialStrain = 0.003;
  c.test.axialStrainRate = 1.0;
  return c;
}

std::string saved(const lab::Laboratory& lab) {
  std::ostringstream out(std::ios::binary);
  lab.saveState(out);
  return out.str();
}

// A laboratory a little way into shearing, and its state then.
struct Sheared {
  lab::Laboratory lab{smallConfig()};
  std::string state;
  Sheared() {
    // One thread: every test binary under ctest builds this again, and OpenMP threads on a busy
    // 2-core machine slow down many times over.
    omp_set_num_threads(1);
    lab.prepare();
    lab.beginShear();
    for (int i = 0; i < 300; ++i) lab.simulation().step();
    state = saved(lab);
  }
};

Sheared& sheared() {
  static Sheared s;
  return s;
}

}  // namespace

TEST(StateIo, ReloadedLaboratoryContinuesBitForBit) {
  Sheared& s = sheared();
  lab::Laboratory copy(smallConfig());
  stateio::MemoryInput in(s.state);
  copy.loadState(in);
  EXPECT_EQ(in.bytesLeft(), 0u);
  copy.simulation().validateState();
  EXPECT_EQ(saved(copy), s.state);  // everything read is written back identically

  lab::Laboratory original(smallConfig());
  stateio::MemoryInput again(s.state);
  original.loadState(again);
  const lab::ShearResult a = original.continueShear();
  const lab::ShearResult b = copy.continueShear();
  ASSERT_EQ(a.records.size(), b.records.size());
  ASSERT_GT(a.records.size(), 2u);
  EXPECT_EQ(std::memcmp(a.records.data(), b.records.data(), a.records.size() * sizeof(lab::Record)), 0);
  const Particles& pa = original.simulation().particles;
  const Particles& pb = copy.simulation().particles;
  for (std::size_t i = 0; i < pa.size(); ++i) {
    EXPECT_EQ(pa.position[i], pb.position[i]);
    EXPECT_EQ(pa.orientation[i].coeffs(), pb.orientation[i].coeffs());
  }
}

// The shear band's windows (output.band_strain_window) are part of the state: a laboratory loaded
// from a checkpoint taken after several windows closed writes the same bytes back, closes its next
// windows at the same records and measures the same strain increment.
TEST(StateIo, BandWindowsSurviveACheckpoint) {
  lab::RunConfig c = smallConfig();
  c.output.bandStrainWindow = 2e-4;
  lab::Laboratory whole(c);
  std::string state;
  whole.onCheckpoint([&state](const lab::Laboratory& l) { if (state.empty() && l.bandWindows() >= 3) state = saved(l); },
                     1e-4);
  whole.prepare();
  const lab::ShearResult a = whole.shear();
  ASSERT_FALSE(state.empty());
  lab::Laboratory resumed(c);
  stateio::MemoryInput in(state);
  resumed.loadState(in);
  EXPECT_GE(resumed.bandWindows(), 3);
  EXPECT_EQ(saved(resumed), state);
  const lab::ShearResult b = resumed.continueShear();
  ASSERT_EQ(a.records.size(), b.records.size());
  long windows = 0;
  for (std::size_t i = 0; i < a.records.size(); ++i) {
    EXPECT_EQ(a.records[i].bandMeasured, b.records[i].bandMeasured) << i;
    windows += a.records[i].bandMeasured != 0.0;
  }
  EXPECT_GE(windows, 10);
  EXPECT_EQ(whole.bandWindows(), resumed.bandWindows());
  EXPECT_EQ(whole.incrementKinematics().localShearStrain, resumed.incrementKinematics().localShearStrain);
}

TEST(StateIo, EveryTruncationIsAnErrorNeverACrash) {
  const std::string& state = sheared().state;
  // Every cut in the first 4 kB (the headers of the arrays), then a spread over the rest.
  std::vector<std::size_t> cuts;
  for (std::size_t n = 0; n < std::min<std::size_t>(4096, state.size()); ++n) cuts.push_back(n);
  for (std::size_t n = 4096; n < state.size(); n += state.size() / 97 + 1) cuts.push_back(n);
  // One laboratory for every cut (constructing one per cut took 16 s of the 17): a refused load
  // must leave it able to refuse the next one the same way.
  lab::Laboratory lab(smallConfig());
  for (std::size_t n : cuts) {
    stateio::MemoryInput in(std::string_view(state).substr(0, n));
    EXPECT_THROW(lab.loadState(in), stateio::StateError) << "cut at " << n << " of " << state.size();
  }
}

TEST(StateIo, ACountBeyondTheBytesLeftIsRefusedBeforeAllocating) {
  std::string state = sheared().state;
  // The first value is the count of particle positions: make it 2^62 (1.5e20 bytes of Vec3).
  const std::uint64_t huge = std::uint64_t{1} << 62;
  std::memcpy(state.data(), &huge, sizeof(huge));
  lab::Laboratory lab(smallConfig());
  stateio::MemoryInput in(state);
  try {
    lab.loadState(in);
    FAIL() << "accepted";
  } catch (const stateio::StateError& e) {
    EXPECT_NE(std::string(e.what()).find("count exceeds the bytes left"), std::string::npos) << e.what();
  }
}

TEST(StateIo, AFlagThatIsNeitherZeroNorOneIsRefused) {
  std::ostringstream out(std::ios::binary);
  stateio::put(out, std::uint8_t{2});
  const std::string bytes = out.str();
  stateio::MemoryInput in(bytes);
  bool flag = false;
  EXPECT_THROW(stateio::get(in, flag), stateio::StateError);
}

TEST(StateIo, OnlyAMemoryInputIsAccepted) {
  std::istringstream in(sheared().state);
  std::vector<double> v;
  EXPECT_THROW(stateio::getVector(in, v), std::logic_error);
}

// The padding bytes of the structs the state holds (the contact model, the walls) are not part of
// the state: a state whose padding holds other bytes saves to the same bytes, with zeros there.
TEST(StateIo, PaddingIsWrittenAsZeros) {
  Simulation a;
  a.box.setBounds(Vec3::Constant(-1.0), Vec3::Constant(1.0));
  a.box.walls[3].control = WallControl::Stress;
  a.model.yadeMomentLimit = true;
  a.particles.addSphere(Vec3::Zero(), 0.1, 2600.0);
  a.initialise();
  a.dt = 1e-6;
  Simulation b = a;
  // b's structs: the same fields, their padding filled with 0xAB (as uninitialised memory might be).
  {
    alignas(contact::SphereContactModel) unsigned char bytes[sizeof(contact::SphereContactModel)];
    std::memset(bytes, 0xAB, sizeof bytes);
    auto* m = new (bytes) contact::SphereContactModel;
    m->yadeMomentLimit = true;
    std::memcpy(static_cast<void*>(&b.model), bytes, sizeof bytes);
  }
  for (std::size_t k = 0; k < b.box.walls.size(); ++k) {
    alignas(Wall) unsigned char bytes[sizeof(Wall)];
    std::memset(bytes, 0xAB, sizeof bytes);
    Wall* w = new (bytes) Wall;
    w->axis = a.box.walls[k].axis, w->side = a.box.walls[k].side, w->position = a.box.walls[k].position;
    w->control = a.box.walls[k].control;
    std::memcpy(static_cast<void*>(&b.box.walls[k]), bytes, sizeof bytes);
  }
  ASSERT_NE(std::memcmp(&a.model, &b.model, sizeof a.model), 0) << "the poisoned padding differs in memory";
  std::ostringstream sa, sb;
  a.saveState(sa);
  b.saveState(sb);
  EXPECT_TRUE(sa.str() == sb.str()) << "padding bytes reached the saved state";
  // and what is written reads back into the same fields
  Simulation c;
  const std::string saved = sb.str();
  stateio::MemoryInput in(saved);
  c.loadState(in);
  EXPECT_TRUE(c.model.yadeMomentLimit);
  EXPECT_EQ(c.box.walls[3].control, WallControl::Stress);
  EXPECT_EQ(c.box.walls[5].position, 1.0);
}

TEST(StateIo, VectorsOfEigenTypesAreWrittenByComponents) {
  const std::vector<Vec3> v{Vec3(1.0, -2.5, 3.25), Vec3(0.1, 0.2, 0.3)};
  const std::vector<Quat> q{Quat(0.5, 0.5, -0.5, 0.5)};
  std::ostringstream out(std::ios::binary);
  stateio::putVector(out, v);
  stateio::putVector(out, q);
  const std::string bytes = out.str();
  ASSERT_EQ(bytes.size(), 8 + 2 * 24 + 8 + 32u);
  double third;  // the third double of the first vector: z of v[0]
  std::memcpy(&third, bytes.data() + 8 + 16, sizeof(double));
  EXPECT_EQ(third, 3.25);
  double w;  // a quaternion is written w, x, y, z
  std::memcpy(&w, bytes.data() + 8 + 48 + 8, sizeof(double));
  EXPECT_EQ(w, 0.5);
  stateio::MemoryInput in(bytes);
  std::vector<Vec3> v2;
  std::vector<Quat> q2;
  stateio::getVector(in, v2);
  stateio::getVector(in, q2);
  EXPECT_EQ(v2, v);
  EXPECT_EQ(q2[0].coeffs(), q[0].coeffs());
}

namespace {

// A struct that lists its fields (stateio::Listed), with a nested one, a vector and Eigen values.
struct ListedInner {
  std::vector<double> values;
  long count = 0;
  template <class Self>
  static auto fields(Self& s) {
    return std::tie(s.values, s.count);
  }
};
struct ListedOuter {
  bool flag = false;
  Vec3 position = Vec3::Zero();
  ListedInner inner;
  int phase = 0;
  template <class Self>
  static auto fields(Self& s) {
    return std::tie(s.flag, s.position, s.inner, s.phase);
  }
};
static_assert(stateio::Listed<ListedOuter> && stateio::Listed<ListedInner> && !stateio::Listed<Wall>);

}  // namespace

// One list writes and reads every field, in the listed order and without padding.
TEST(StateIo, ListedStructsAreWrittenFieldByFieldInTheirOrder) {
  ListedOuter a;
  a.flag = true;
  a.position = Vec3(1.5, -2.0, 4.0);
  a.inner.values = {0.25, -8.0};
  a.inner.count = 7;
  a.phase = -3;
  std::ostringstream out(std::ios::binary);
  stateio::put(out, a);
  const std::string bytes = out.str();
  ASSERT_EQ(bytes.size(), 1 + 24 + (8 + 16) + 8 + 4u);
  double y;
  std::memcpy(&y, bytes.data() + 1 + 8, sizeof(double));
  EXPECT_EQ(y, -2.0);
  long count;
  std::memcpy(&count, bytes.data() + 1 + 24 + 24, sizeof(long));
  EXPECT_EQ(count, 7);
  stateio::MemoryInput in(bytes);
  ListedOuter b;
  stateio::get(in, b);
  EXPECT_EQ(in.bytesLeft(), 0u);
  EXPECT_TRUE(b.flag);
  EXPECT_EQ(b.position, a.position);
  EXPECT_EQ(b.inner.values, a.inner.values);
  EXPECT_EQ(b.inner.count, 7);
  EXPECT_EQ(b.phase, -3);
  // A short read is an error, not a half-filled struct taken for a whole one.
  stateio::MemoryInput shortIn(std::string_view(bytes).substr(0, bytes.size() - 2));
  ListedOuter c;
  EXPECT_THROW(stateio::get(shortIn, c), stateio::StateError);
}

namespace {

// Loads the sheared state, lets `spoil` change it, and returns validateState's complaint ("" if none).
std::string complaint(const std::function<void(Simulation&)>& spoil) {
  lab::Laboratory lab(smallConfig());
  stateio::MemoryInput in(sheared().state);
  lab.loadState(in);
  spoil(lab.simulation());
  try {
    lab.simulation().validateState();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ValidateState, AcceptsASavedStateAndNamesWhatIsInconsistent) {
  EXPECT_EQ(complaint([](Simulation&) {}), "");
  EXPECT_NE(complaint([](Simulation& s) {
              s.contacts.sphereSphere.b[0] = static_cast<std::uint32_t>(s.particles.size());
            }).find("sphere-sphere contact 0"),
            std::string::npos);
  EXPECT_NE(complaint([](Simulation& s) { s.particles.position[3][1] = std::nan(""); }).find("particle 3"),
            std::string::npos);
  EXPECT_NE(complaint([](Simulation& s) { s.particles.radius.pop_back(); }).find("entries"), std::string::npos);
  EXPECT_NE(complaint([](Simulation& s) { std::swap(s.contacts.sphereSphere.b[0], s.contacts.sphereSphere.b[1]); })
                .find("not sorted"),
            std::string::npos);
  EXPECT_NE(complaint([](Simulation& s) { s.contacts.sphereWall.b.assign(s.contacts.sphereWall.size(), 6); })
                .find("sphere-wall"),
            std::string::npos);
  EXPECT_NE(complaint([](Simulation& s) { s.particles.mass[0] = 0.0; }).find("particle 0"), std::string::npos);
  EXPECT_NE(complaint([](Simulation& s) { s.dt = -1.0; }).find("time step"), std::string::npos);
  EXPECT_NE(complaint([](Simulation& s) { s.box.upper(0).position = 1e6; }).find("far too large"), std::string::npos);
}

// A forged state (checksum recomputed, so only the loader stands between it and the engine): an
// index or size that the loader used before checking it would write out of bounds (issue 28: a
// contact index far beyond the particles crashed resume in buildIncidence). Every spoilt state is
// saved and loaded again: the load must refuse it, and nothing may be derived from it first (under
// AddressSanitizer an out-of-bounds access fails this test even if the error is thrown later).
TEST(ValidateState, AForgedStateIsRefusedBeforeAnythingIsDerivedFromIt) {
  const std::vector<std::pair<std::string, std::function<void(Simulation&)>>> spoils{
      {"pair index far out of range", [](Simulation& s) { s.contacts.sphereSphere.a[0] = 4'000'000'000u; }},
      {"second body far out of range", [](Simulation& s) { s.contacts.sphereSphere.b.back() = 4'000'000'000u; }},
      {"wall index out of range", [](Simulation& s) { s.contacts.sphereWall.b[0] = 1'000'000u; }},
      {"wall contact's particle out of range", [](Simulation& s) { s.contacts.sphereWall.a[0] = 3'000'000'000u; }},
      {"fewer shapes than particles", [](Simulation& s) { s.particles.shape.resize(3); }},
      {"fewer masses than particles", [](Simulation& s) { s.particles.mass.resize(1); }},
      {"history shorter than the pairs", [](Simulation& s) { s.contacts.sphereSphere.history.pop_back(); }},
      {"unknown shape", [](Simulation& s) { s.particles.shape[2] = static_cast<Shape>(7); }},
      {"unknown wall control", [](Simulation& s) { s.box.walls[1].control = static_cast<WallControl>(9); }},
      {"non-finite Young modulus", [](Simulation& s) { s.model.young = std::nan(""); }},
      {"negative step count", [](Simulation& s) { s.stepCount = -5; }},
      {"non-finite force", [](Simulation& s) { s.particles.force[0][2] = INFINITY; }},
  };
  ASSERT_GT(sheared().lab.simulation().contacts.sphereWall.size(), 0u);
  for (const auto& [what, spoil] : spoils) {
    lab::Laboratory source(smallConfig());
    stateio::MemoryInput in(sheared().state);
    source.loadState(in);
    spoil(source.simulation());
    const std::string forged = saved(source);
    lab::Laboratory target(smallConfig());
    stateio::MemoryInput forgedIn(forged);
    EXPECT_ANY_THROW(target.loadState(forgedIn)) << what;
  }
}

// --- the checkpoint container (io/checkpoint_file.hpp) ---------------------------------------------

#include <xxhash.h>

#include "io/checkpoint_file.hpp"

namespace {

const nlohmann::json kRecord{{"summary", {{"e0", 0.61}}}, {"vtk_labels", {0.0, 0.01}}, {"wall_seconds", 1.5}};

// Rewrites a header field of an encoded checkpoint and recomputes its checksum, as a deliberate
// forgery (or another program) would.
std::string withField(std::string bytes, std::size_t offset, const void* value, std::size_t size) {
  std::memcpy(bytes.data() + offset, value, size);
  const std::uint64_t sum = XXH64(bytes.data(), bytes.size() - 8, 0);
  std::memcpy(bytes.data() + bytes.size() - 8, &sum, 8);
  return bytes;
}

std::string withVersion(const std::string& bytes, const std::string& version) {
  char field[32] = {};
  std::memcpy(field, version.data(), version.size());
  return withField(bytes, 32, field, sizeof(field));
}

std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(CheckpointFile, RoundTrip) {
  const lab::RunConfig config = smallConfig();
  const std::string state = "engine state \x01\x02\x03";
  const io::Checkpoint c = io::decodeCheckpoint(io::encodeCheckpoint(config, kRecord, state), "state.bin");
  EXPECT_EQ(c.state, state);
  EXPECT_EQ(c.record, kRecord);
  EXPECT_EQ(c.programVersion, GRAINLAB_VERSION);
  EXPECT_NO_THROW(io::checkCheckpointBelongs(c, "state.bin", config, false));
}

TEST(CheckpointFile, EveryBitFlipAndEveryTruncationIsRefused) {
  const std::string good = io::encodeCheckpoint(smallConfig(), kRecord, std::string(200, '\x5a'));
  for (std::size_t byte = 0; byte < good.size(); ++byte)
    for (int bit = 0; bit < 8; ++bit) {
      std::string bad = good;
      bad[byte] = static_cast<char>(bad[byte] ^ (1 << bit));
      const std::string why = refusal([&] { io::decodeCheckpoint(bad, "dir/state.bin"); });
      ASSERT_NE(why.find("dir/state.bin"), std::string::npos) << "flip of bit " << bit << " of byte " << byte;
    }
  for (std::size_t n = 0; n < good.size(); ++n)
    ASSERT_NE(refusal([&] { io::decodeCheckpoint(good.substr(0, n), "state.bin"); }), "") << "cut at " << n;
}

TEST(CheckpointFile, VersionLayoutAndConfigMustMatch) {
  const lab::RunConfig config = smallConfig();
  const std::string good = io::encodeCheckpoint(config, kRecord, "x");
  auto belongs = [&](const std::string& bytes, const lab::RunConfig& c, bool allowOlder) {
    return refusal([&] { io::checkCheckpointBelongs(io::decodeCheckpoint(bytes, "s.bin"), "s.bin", c, allowOlder); });
  };
  EXPECT_EQ(belongs(good, config, false), "");
  // Another program version: refused; an older one is accepted on request, a newer one never.
  const std::string older = withVersion(good, "0.0.9"), newer = withVersion(good, "99.0.0");
  EXPECT_NE(belongs(older, config, false).find("written by grainlab 0.0.9"), std::string::npos);
  EXPECT_EQ(belongs(older, config, true), "");
  EXPECT_NE(belongs(newer, config, true).find("written by grainlab 99.0.0"), std::string::npos);
  // Another engine state layout (a build whose checkpointed structs differ).
  const std::uint64_t otherLayout = io::stateLayoutTag() ^ 1;
  EXPECT_NE(belongs(withField(good, 16, &otherLayout, 8), config, true).find("state layout"), std::string::npos);
  // Another config; the results folder's name is not part of it (a folder may be moved).
  lab::RunConfig other = config;
  other.contact.frictionDeg = 31.0;
  EXPECT_NE(belongs(good, other, false).find("another config"), std::string::npos);
  lab::RunConfig moved = config;
  moved.output.dir = "elsewhere/run";
  EXPECT_EQ(belongs(good, moved, false), "");
  // A known format but a record that is not what a run writes.
  const std::string noRecord = io::encodeCheckpoint(config, nlohmann::json{{"summary", 1}}, "x");
  EXPECT_NE(refusal([&] { io::decodeCheckpoint(noRecord, "s.bin"); }).find("run record"), std::string::npos);
}

TEST(CheckpointFile, VersionOrder) {
  EXPECT_LT(io::compareVersions("0.9.1", "0.10.0"), 0);
  EXPECT_GT(io::compareVersions("1.0", "0.99.99"), 0);
  EXPECT_EQ(io::compareVersions("0.1.0", "0.1.0"), 0);
  EXPECT_EQ(io::compareVersions("0.1", "0.1.0"), 0);
}
