#pragma once
// The full description of a laboratory run. Every field has a default; io/config.cpp fills it from
// TOML and validates it, and writes it back out with every default resolved. Units SI, angles deg.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/servo_settings.hpp"
#include "lab/sphericity.hpp"
#include "lab/stress_path.hpp"
#include "lab/test_type.hpp"

namespace grainlab::lab {

// Practical bounds of a grain diameter [m] (gradings, list files, packings): a grain below a
// micrometre or above 10 m is no test of this engine (its masses, stiffnesses and time steps leave
// the range a run resolves); refused with these bounds stated.
inline constexpr double kMinDiameter = 1e-6;
inline constexpr double kMaxDiameter = 10.0;

// Most shear strain amplitudes of a cyclic simple shear test (their results live in the
// protocol's fixed-size, checkpointed state).
inline constexpr int kMaxShearAmplitudes = 16;

struct GradingConfig {
  // "curve" (percent passing by mass), "uniform" (by number), "list"; "packing": the grading of
  // sample.packing, as config.resolved.toml records a run from a packing file
  std::string type = "curve";
  std::vector<double> diameters{2.0e-3, 8.0e-3};  // [m] (curve)
  std::vector<double> passing{0.0, 100.0};        // [%] by mass (curve)
  double dMin = 2.0e-3;                           // [m] (uniform)
  double dMax = 8.0e-3;                           // [m] (uniform)
  std::string file;                               // (list) one diameter [m] per line/row
  std::vector<double> list;                       // (list) the file's diameters [m], read with the config

  // The grading of a run from sample.packing: its grains are the packing's.
  static GradingConfig ofPacking() {
    GradingConfig g;
    g.type = "packing";
    g.diameters.clear();
    g.passing.clear();
    return g;
  }
};

// Grain shape ([O], docs/physics.md §2): spheres, or triaxial ellipsoids a >= b >= c of the same volume
// as the sphere drawn from the grading (equivalent radius), grown from it at the end of preparation.
struct ShapeConfig {
  std::string type = "sphere";      // "sphere" | "ellipsoid"
  double elongation = 1.0;          // b/a (<= 1); [O]'s elr
  double flatness = 1.0;            // c/b (<= 1); [O]'s flr; 1 for prolate spheroids
  std::string orientation = "random";  // long axes "random" or all "aligned-x" (inherent anisotropy)
  double fraction = 1.0;            // share of the grains (by number) that are ellipsoids; the rest stay spheres
  double eccentricityStep = 0.01;   // growth in steps of this eccentricity (a - b)/(a + b), relaxed after each
};

struct SampleConfig {
  int nParticles = 2000;
  bool nParticlesGiven = false;  // given in the config (with sample.packing it must match the packing)
  GradingConfig grading;
  double density = 2600.0;   // [kg/m^3]
  double e0 = 0.60;          // target initial void ratio
  std::uint64_t seed = 1;
  // Friction during compaction [deg]; lower gives a denser sample. Unset: searched to meet e0.
  std::optional<double> prepFrictionDeg;
  double e0Tolerance = 0.01;
  double initialVoidRatio = 2.0;  // of the loose random placement before compaction
  std::string packing;            // start from this packing file instead of preparing a sample
  // With a packing: the friction [deg] while the packing is brought to test.confining_pressure
  // (then friction is restored and the sample re-equilibrated); nullopt: contact.friction_deg
  // throughout. [O]'s gradual frictionless unloading to the lower pressures is 0.
  std::optional<double> packingFrictionDeg;
  double prepStiffnessFactor = 0.01;  // contact stiffness during compaction, as a fraction of Ec
  double prepDamping = 0.3;           // local damping during compaction
  long prepRampSteps = 20000;         // steps of the geometric ramp from the soft to the full Ec
  // "compaction": the boundary's servo compacts the loose sample with the preparation friction
  // (searched to meet e0 when prep_friction_deg is "auto"); "growth": frictionless radius growth with
  // the boundary held still up to the confining pressure (the densest state; e0 is a result).
  // "lattice" ([O] §5.1): equal spheres of diameter d50 on a simple cubic lattice (n_particles a
  // cube), compressed isotropically without friction (coordination 6).
  // "loose-moment-free": as "compaction" (the same e0 search on the preparation friction), but with
  // no contact moments during compaction (rolling stiffness 0); the moments are switched on at the
  // full-stiffness equilibrium. Spheres that cannot resist rolling cannot stand in the tenuous arches
  // that contact moments allow, so a loose target is met by a connected skeleton (docs/moduli.md).
  std::string method = "compaction";
  double growthRate = 2e-5;           // relative radius growth per step (method "growth")
  double latticeJitter = 0.0;         // lattice: random offsets of the compressed lattice, fraction of d
  // "deposition": the grains, placed at random in a tall column (a cloud at initial_void_ratio), fall
  // under gravity onto the floor of a box with fixed walls and settle; then the top platen and the
  // side walls take over and consolidate to the confining pressure (docs/lab.md, preparation).
  // drop_height [m]: free fall of the cloud's lowest grains above the floor.
  double dropHeight = 0.0;
  // "under-compaction" (Ladd 1978's moist tamping, layer by layer; docs/laboratory.md §1.8): the
  // grains in `layers` equal shares, each rained as a cloud onto the bed under gravity and tamped by
  // the top platen to a height at which the sample built so far has its layers' target densities:
  // layer j (1 = the bottom) at a dry density (1 - U_j) times that of e0, U_j = under_compaction
  // (L - j)/(L - 1), so that the lower layers, compacted again by every tamping above them, end up
  // as dense as the upper ones. Then the platen and the side walls take over, as after deposition.
  int layers = 5;
  double underCompaction = 0.05;
  // Gravity [m/s^2], every protocol (walls only): none unless given; "deposition" and
  // "under-compaction" default to (0, 0, -9.81) and need it along -z.
  std::optional<std::array<double, 3>> gravity;
  ShapeConfig shape;
};

struct SphericityConfig {
  std::string file;          // CSV: column `sphericity`, or `bin_low,bin_high,frequency`
  SphericityDistribution distribution;  // the file's contents, read with the config
  double c = 0.1963;         // mu_r = c psi^k ([R])
  double k = 0.0;            // required, no default
  std::string combine = "min";  // "min" | "mean" | "harmonic"
};

struct ContactConfig {
  // "kozicki" [W] | "rolling-linear" [R] (linear springs) | "hertz-mindlin" (docs/physics.md §4.6)
  std::string model = "kozicki";
  double young = 30.0e9;        // Ec [Pa] (linear laws)
  double poisson = 0.3;         // nu_c = Ks/Kn [-]; hertz-mindlin: Poisson's ratio of the grain material
  // hertz-mindlin only: the grain material's shear modulus G [Pa] (quartz about 29 GPa), the rolling
  // slot ("none", "kozicki" or "rolling-linear") and the normal coefficient of restitution (1: no
  // dashpot).
  double shearModulus = 29.0e9;
  std::string rolling = "none";
  double restitution = 1.0;
  bool hertz() const { return model == "hertz-mindlin"; }
  // The rolling slot in use: the linear models name theirs, Hertz–Mindlin takes contact.rolling.
  const std::string& rollingSlot() const { return hertz() ? rolling : model; }
  // The Young's modulus the engine's model carries: Ec, or E = 2 G (1 + nu) of the grain material.
  double modelYoung() const { return hertz() ? 2.0 * shearModulus * (1.0 + poisson) : young; }
  double frictionDeg = 30.0;    // mu [deg]
  double beta = 0.15;           // rolling stiffness coefficient [-]
  double eta = 1.0;             // moment limit coefficient [-]
  double wallFrictionDeg = 0.0; // 0: smooth walls, as in [W]
  // "mean-radius": [W]'s |M| <= eta (RA+RB)/2 |Fn|; "yade": YADE's eta min(RA,RB) |Fn| on bending and
  // twisting separately (for comparisons with YADE).
  std::string momentLimit = "mean-radius";
  // A constant normal stiffness Kn [N/m] for every contact (walls too), Ks = poisson Kn, as [O]
  // used; unset: Kn from Ec and the (equivalent) radii.
  std::optional<double> kn;
  // rolling-linear only: a uniform rolling friction, or per-grain values from sphericity.
  double rollingFriction = 0.1;
  std::optional<SphericityConfig> sphericity;
};

struct TestConfig {
  // test.type: one of kTestTypes (lab/test_type.hpp)
  TestType type = TestType::Triaxial;
  // test.drainage (triaxial, simple-shear, cyclic-triaxial): undrained = constant volume, the
  // change of total lateral stress the constraint produces read as the excess pore pressure u.
  Drainage drainage = Drainage::Drained;
  std::string boundary = "walls";     // "walls" | "periodic" | "membrane"
  double confiningPressure = 100.0e3; // [Pa]; the mean stress of constant-p and true-triaxial, the
                                      // normal stress of simple-shear
  // test.boundary = "membrane" (core/membrane.hpp, docs/physics.md §8.3): height/diameter of the
  // cylinder, the sleeve's Young modulus [Pa] and thickness [m] (its hoop stiffness E_m t), and the
  // side of the membrane's bins in d50.
  double aspectRatio = 2.0;
  double membraneYoung = 1.4e6;
  double membraneThickness = 0.3e-3;
  double membraneBinD50 = 1.0;
  // Friction of the platens (the z walls) [deg]; nullopt: contact.wall_friction_deg, as every wall.
  std::optional<double> platenFrictionDeg;
  std::optional<double> axialStrainRate = 0.5;  // [1/s]; nullopt = "auto"
  double finalAxialStrain = 0.20;     // [-]
  double b = 0.5;                     // true-triaxial: (sigma2 - sigma3)/(sigma1 - sigma3)
  std::optional<double> shearStrainRate;  // simple-shear [1/s]; nullopt = "auto"
  double finalShearStrain = 0.5;      // simple-shear: final gamma [-]
  // Window of the steady-state (critical-state) criterion (lab/macro.hpp) in the test's strain;
  // nullopt = "auto": a quarter of the final strain, at least 0.05 (lab::autoCsWindow).
  std::optional<double> csWindow;
  // Small-strain probe after consolidation (lab/moduli.hpp): axial strain increment with the
  // lateral stress held; 0: no probe (E0, nu0 null).
  double probeStrain = 1e-6;
  // Triaxial: axial strains at which the platens reverse for an unload-reload loop (strictly
  // increasing, in (0, final_axial_strain)); each unload ends at unloadToQFraction of the deviator
  // at reversal, and the reload returns to the reversal strain.
  std::vector<double> unloadReloadAt;
  double unloadToQFraction = 0.5;
  // Before each unload the platens stand still until the sample is at rest (unbalanced-force ratio
  // below Laboratory::kProbeUnbalanced), so that Eur is measured from a relaxed state and the
  // relaxation of q at constant strain is reported (docs/moduli.md).
  bool loopRest = false;
  // Platens slow down while the unbalanced-force ratio exceeds this (speed x threshold/ratio, at
  // least kMinPlatenSlowdown), so that the lateral servos can follow a collapse; 0: off.
  double platenSlowdownUnbalanced = 0.0;
  // The loading rate follows the mean effective stress, rate(p') = rate(p0) sqrt(p'/p0) (never
  // above it, never below Laboratory::kMinPressureRateFactor of it), so that the inertial number
  // stays at its value at p0 when p' falls (undrained flow of a loose sample).
  bool rateFollowsPressure = false;
  // Speed cap of the boundary servos while the test runs [m/s] (cell: 2 x this / cell length as a
  // rate). By default above solver.servoMaxSpeed, which governs the preparation (walls that approach a loose
  // cloud without contacts move at the cap there): in a test the lateral walls only reach the cap
  // when a force-chain column collapses and the sample contracts faster than 0.5 m/s lets them
  // follow (docs/moduli.md, "Lateral stress in column collapses").
  double servoMaxSpeed = 2.0;
  // Oedometer: axial stress at which loading turns to unloading, and where unloading ends [Pa].
  double maxAxialStress = 1.0e6;
  double unloadAxialStress = 100.0e3;
  // Cyclic triaxial: cyclic stress ratio q_cyc/(2 p0), the number of cycles at most, and the
  // liquefaction criteria (excess pore-pressure ratio ru = 1 - p'/p0 and double-amplitude axial strain).
  double csr = 0.2;
  long nCycles = 20;
  double ruLimit = 0.95;
  // Undrained tests: the back pressure of the pore water [Pa, gauge]; nullopt: no cavitation limit
  // (the water takes any tension). With it the water cavitates where its absolute pressure falls to
  // its vapour pressure, at u = cavitationPressure() (docs/laboratory.md, "Cavitation").
  std::optional<double> backPressure;
  // The excess pore pressure at which the water cavitates [Pa, negative]: -(back pressure +
  // atmospheric pressure - vapour pressure of water at 20 degC); nullopt without test.back_pressure.
  static constexpr double kAtmosphericPressure = 101325.0;
  static constexpr double kVapourPressure = 2339.0;
  std::optional<double> cavitationPressure() const {
    if (!backPressure) return std::nullopt;
    return -(*backPressure + kAtmosphericPressure - kVapourPressure);
  }
  double liquefactionDaStrain = 0.05;
  // Stress path (test.path): its points, and the file they were read from ("" when given inline).
  std::vector<PathPoint> path;
  std::string pathSource;
  // Cyclic simple shear: the shear strain amplitudes, increasing (at most kMaxShearAmplitudes),
  // each cycled this many times.
  std::vector<double> shearStrainAmplitudes{1e-5, 1e-4, 1e-3};
  long cyclesPerAmplitude = 2;

  // The largest boundary stress the test asks for before the sample's own deviator (the confining
  // pressure, the oedometer's turning stress, a stress path's targets) [Pa]; Hertz–Mindlin's
  // reference overlap for the time step follows it (contact::hertzReferenceOverlap).
  double largestStress() const {
    double s = confiningPressure;
    if (type == TestType::Oedometer) s = std::max(s, maxAxialStress);
    for (const PathPoint& p : path)
      for (int a = 0; a < 3; ++a)
        if (p.control[a] == PathControl::Stress) s = std::max(s, std::abs(p.value[a]));
    return s;
  }
};

struct SolverConfig {
  double damping = 0.3;        // Cundall local damping alpha [-]
  double viscousDamping = 0.0; // [O]'s viscous damping alpha [1/s]; > 0 replaces the local damping
  double dtFactor = 0.5;       // fraction of the critical time step
  std::optional<double> dt;    // explicit time step [s]; refused above critical unless forced
  bool forceDt = false;
  int threads = 2;
  double unbalancedTolerance = 0.01;  // quasi-static threshold for the unbalanced-force ratio
  double stressTolerance = 0.01;      // relative, for isotropic equilibrium
  double servoGain = ServoSettings{}.gain;
  double servoIntegralSteps = ServoSettings{}.integralSteps;
  double servoMaxSpeed = ServoSettings{}.maxSpeed;  // [m/s]
  double skinFraction = 0.2;   // Verlet skin as a fraction of the smallest radius
  long maxSteps = 50'000'000;  // safety limit per phase
};

struct OutputConfig {
  std::string dir = "runs/example";
  double recordEveryStrain = 0.001;
  bool plots = true;
  bool savePacking = true;  // packing.txt of the prepared sample, reusable as sample.packing
  double vtkEveryStrain = 0.01;  // ParaView snapshots during shearing; 0 = none
  bool microSnapshots = true;    // contact-network snapshots (micro/) with the VTK ones, analysed at the end
  double checkpointEvery = 0.01;  // checkpoints during shearing, in axial strain; 0 = none
  double bandFactor = 2.0;  // a grain is in the shear band when its local eq >= this x the box's
  // The shear band is measured from the strain increment over windows of this much of the test's
  // driving strain (axial, or shear strain), one window closing at the first record past it.
  double bandStrainWindow = 0.01;
};

struct RunConfig {
  // Keys given that were ignored (preparation keys beside sample.packing), one message each; not
  // part of the resolved config.
  std::vector<std::string> warnings;
  SampleConfig sample;
  ContactConfig contact;
  TestConfig test;
  SolverConfig solver;
  OutputConfig output;
};

}  // namespace grainlab::lab
