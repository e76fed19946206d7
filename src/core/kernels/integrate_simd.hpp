#pragma once
// The sphere integrator vectorised over particles (issue 25, part 2): several particles per
// instruction through Google Highway (Debian libhwy-dev), with run-time dispatch, so that one
// portable x86-64 binary uses the widest vectors the CPU has (SSSE3, SSE4, AVX2 or AVX-512, and
// Highway's EMU128, a portable emulation of 128-bit vectors in scalar code).
//
// Every target computes, lane by lane, the same IEEE operations in the same order as the scalar
// kernel kernels::integrateParticle (core/kernels/integrate.hpp) with Eigen's evaluation order:
// the results are bit-identical between the targets and with the scalar kernel (no contraction
// into fused multiply-adds: the project compiles with -ffp-contract=off, docs/architecture.md,
// "Floating point"). tests/unit/test_integrate_simd.cpp checks it on every target this CPU has.
//
// It covers the engine's common case: spheres under local (Cundall) damping, with or without
// gravity, walls or a periodic cell. Ellipsoids and [O]'s viscous damping take the scalar kernel.
#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include "core/kernels/integrate.hpp"

namespace grainlab::kernels {

// Which kernel the integrator uses: the scalar per-particle kernel, or a Highway target.
// "best" (the default) is the widest target this CPU supports.
struct SimdChoice {
  static constexpr const char* kEnvironment = "GRAINLAB_SIMD";
};

// Names a user may give (GRAINLAB_SIMD): "best", "scalar", and the Highway targets compiled in
// and supported by this CPU ("emu128", "ssse3", "sse4", "avx2", "avx512"), best first.
std::vector<std::string> simdTargetNames();
// Selects the kernel by name; std::invalid_argument (naming the value and what is allowed) when
// the name is unknown or the CPU lacks the target. Not thread-safe: call before stepping.
void selectSimdTarget(const std::string& name);
// The kernel in use: "scalar" or the Highway target's name (e.g. "avx2").
std::string simdTarget();
// Whether a vectorised target is selected (false: "scalar").
bool simdEnabled();

// The checks the integrate stage makes on every particle after its step, done by the kernel while
// the particle is in registers: the largest squared displacement since the broad phase's build
// (|x - x_build|^2, in a cell |x - F x_build|^2), and the first particle whose state is not finite
// or (walls) that left the box.
struct StepChecks {
  const Vec3* positionsAtBuild = nullptr;  // nullptr: no build yet (no displacement measured)
  Mat3 deformation = Mat3::Identity();     // periodic: F = H H_build^-1
  const double* radius = nullptr;          // walls: the particles' radii
  Vec3 lower = Vec3::Zero(), upper = Vec3::Zero();  // walls: the box's corners
};
struct ChecksResult {
  double maxDisplacement2 = 0.0;       // the largest |dx|^2 of the range (0 without a build)
  std::size_t firstBad = kNoParticle;  // the lowest index of a bad particle, or kNoParticle
  static constexpr std::size_t kNoParticle = ~std::size_t{0};
};

// Advances particles [begin, end) by one step. Precondition: every one is a sphere and
// s.viscousDamping == 0. work[k] receives particle begin + k's ParticleWork (the caller sums them
// in particle order, as it sums the scalar kernel's). Periodic: the position follows the cell's
// homogeneous flow too (s.flowStep). Returns the checks of `c` over the range.
ChecksResult integrateSpheres(const IntegratorView& p, std::size_t begin, std::size_t end, const IntegratorStep& s,
                              bool periodic, ParticleWork* work, const StepChecks& c = {});

// The same checks for one particle after its step, as the scalar loop makes them (integrate.hpp's
// kernel leaves them to its caller); folded into `r`.
template <bool Periodic>
inline void checkParticle(const IntegratorView& p, std::size_t i, const StepChecks& c, ChecksResult& r) {
  const Vec3& x = p.position[i];
  if (c.positionsAtBuild != nullptr) {
    if constexpr (Periodic) r.maxDisplacement2 = std::max(r.maxDisplacement2, (x - c.deformation * c.positionsAtBuild[i]).squaredNorm());
    else r.maxDisplacement2 = std::max(r.maxDisplacement2, (x - c.positionsAtBuild[i]).squaredNorm());
  }
  const bool finite = x.allFinite() && p.velocity[i].allFinite() && p.angularVelocity[i].allFinite();
  bool inside = true;
  if constexpr (!Periodic) {
    const double rad = c.radius[i];
    inside = ((x - c.lower).array() > -rad).all() && ((c.upper - x).array() > -rad).all();
  }
  if ((!finite || !inside) && i < r.firstBad) r.firstBad = i;
}

}  // namespace grainlab::kernels
