#pragma once
// The laboratory tests (docs/laboratory.md): one enumeration, parsed once from test.type (io/config.cpp), with
// what the rest of the laboratory needs to know about each test in one table.
#include <array>
#include <optional>
#include <string_view>

namespace grainlab::lab {

enum class TestType : std::uint8_t {
  Isotropic,      // consolidation only
  Triaxial,       // axial strain rate, lateral stress held (drained) or constant volume (undrained)
  ConstantP,      // axial strain rate, lateral stress following (3p - sigma1)/2
  TrueTriaxial,   // axial strain rate, p and b held
  SimpleShear,    // periodic cell: shear strain rate, normal stress held, no lateral strain
  Oedometer,      // axial loading and unloading with no lateral strain
  CyclicTriaxial, // deviator cycles of amplitude 2 csr p0 about the isotropic state
  StressPath,     // a table of stress or strain targets per axis (test.path, lab/stress_path.hpp)
  CyclicSimpleShear,  // periodic cell: gamma cycles at a list of amplitudes, G and damping per amplitude
};

// What the shearing part of a test is driven by: the axial strain (platens or H_zz) or the shear
// strain gamma = H_xz/H_zz of the cell.
enum class DrivingStrain : std::uint8_t { None, Axial, Shear };

struct TestTypeInfo {
  TestType type;
  std::string_view name;   // test.type in configs and summaries
  std::string_view phase;  // progress phase of its shearing
  DrivingStrain strain;
  bool periodicOnly;       // needs test.boundary = "periodic"
  bool drainage;           // test.drainage = "undrained" applies
  // Its report is a monotonic curve's (peak, residual, dilatancy, E50, critical state); the other
  // shearing tests report their own macro-values (lab/test_report.hpp, lab/run_report.hpp).
  bool monotonic;
};

inline constexpr std::array<TestTypeInfo, 9> kTestTypes{{
    {TestType::Isotropic, "isotropic", "isotropic consolidation", DrivingStrain::None, false, false, false},
    {TestType::Triaxial, "triaxial", "triaxial shearing", DrivingStrain::Axial, false, true, true},
    {TestType::ConstantP, "constant-p", "constant-p", DrivingStrain::Axial, false, false, true},
    {TestType::TrueTriaxial, "true-triaxial", "true-triaxial", DrivingStrain::Axial, false, false, true},
    {TestType::SimpleShear, "simple-shear", "simple-shear", DrivingStrain::Shear, true, true, true},
    {TestType::Oedometer, "oedometer", "oedometer", DrivingStrain::Axial, false, false, false},
    {TestType::CyclicTriaxial, "cyclic-triaxial", "cyclic triaxial", DrivingStrain::Axial, false, true, false},
    {TestType::StressPath, "stress-path", "stress path", DrivingStrain::Axial, false, false, false},
    {TestType::CyclicSimpleShear, "cyclic-simple-shear", "cyclic simple shear", DrivingStrain::Shear, true, true, false},
}};

inline const TestTypeInfo& info(TestType t) {
  for (const TestTypeInfo& i : kTestTypes)
    if (i.type == t) return i;
  return kTestTypes[0];  // unreachable: every enumerator is in the table
}
inline std::string_view name(TestType t) { return info(t).name; }
inline std::optional<TestType> parseTestType(std::string_view s) {
  for (const TestTypeInfo& i : kTestTypes)
    if (i.name == s) return i.type;
  return std::nullopt;
}
inline bool shears(TestType t) { return info(t).strain != DrivingStrain::None; }

// test.drainage
enum class Drainage : std::uint8_t { Drained, Undrained };

}  // namespace grainlab::lab
