// The sphere integrator over Highway vectors (see integrate_simd.hpp). Highway compiles this file
// once per target (foreach_target.h re-includes it); HWY_EXPORT / HWY_DYNAMIC_DISPATCH pick the
// target at run time.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/kernels/integrate_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/kernels/integrate_simd.hpp"

// The kernel reads the particle arrays as flat arrays of doubles.
static_assert(sizeof(grainlab::Vec3) == 3 * sizeof(double), "Vec3 must be three packed doubles");
static_assert(sizeof(grainlab::Quat) == 4 * sizeof(double), "Quat must be four packed doubles (x, y, z, w)");

HWY_BEFORE_NAMESPACE();
namespace grainlab::kernels::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Processes whole vectors of particles from `begin`; returns where it stopped (the caller does the
// rest with the scalar kernel). Each line below is the scalar kernel's expression, operation for
// operation in Eigen's order (integrate.hpp; the comments quote it).
template <bool Periodic>
std::size_t SpheresT(const IntegratorView& p, std::size_t begin, std::size_t end, const IntegratorStep& s,
                     ParticleWork* work, const StepChecks& c, ChecksResult& result) {
  const hn::ScalableTag<double> d;
  using V = hn::Vec<decltype(d)>;
  const std::size_t lanes = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), minusOne = hn::Set(d, -1.0), half = hn::Set(d, 0.5);
  const V h = hn::Set(d, s.h), halfH = hn::Set(d, 0.5 * s.h), minusAlpha = hn::Set(d, -s.localDamping);
  const V g0 = hn::Set(d, s.gravity[0]), g1 = hn::Set(d, s.gravity[1]), g2 = hn::Set(d, s.gravity[2]);
  // A 3 x 3 matrix broadcast to every lane, and its product with a vector of lanes in Eigen's
  // order: rows 0 and 1 in one SSE2 register, (M0 x0 + M1 x1) + M2 x2; row 2 by its scalar
  // unroller, M0 x0 + (M1 x1 + M2 x2).
  struct Matrix {
    V e[3][3];
  };
  auto broadcast = [&](const Mat3& M) {
    Matrix r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r.e[i][j] = hn::Set(d, M(i, j));
    return r;
  };
  auto times = [](const Matrix& M, V x0, V x1, V x2, V& r0, V& r1, V& r2) {
    r0 = hn::Add(hn::Add(hn::Mul(M.e[0][0], x0), hn::Mul(M.e[0][1], x1)), hn::Mul(M.e[0][2], x2));
    r1 = hn::Add(hn::Add(hn::Mul(M.e[1][0], x0), hn::Mul(M.e[1][1], x1)), hn::Mul(M.e[1][2], x2));
    r2 = hn::Add(hn::Mul(M.e[2][0], x0), hn::Add(hn::Mul(M.e[2][1], x1), hn::Mul(M.e[2][2], x2)));
  };
  Matrix flow{}, deformation{};
  if constexpr (Periodic) flow = broadcast(s.flowStep), deformation = broadcast(c.deformation);
  // The checks (StepChecks): the build's deformation F (periodic), the box (walls).
  const bool measure = c.positionsAtBuild != nullptr;
  const double* const xBuild = measure ? c.positionsAtBuild->data() : nullptr;
  V lo0, lo1, lo2, up0, up1, up2;
  if constexpr (!Periodic) {
    lo0 = hn::Set(d, c.lower[0]), lo1 = hn::Set(d, c.lower[1]), lo2 = hn::Set(d, c.lower[2]);
    up0 = hn::Set(d, c.upper[0]), up1 = hn::Set(d, c.upper[1]), up2 = hn::Set(d, c.upper[2]);
  }
  V maxDisp2 = zero;
  // Eigen's sign(): +1, -1, or 0 where the value is 0.
  auto sign = [&](V a) { return hn::IfThenElse(hn::Gt(a, zero), one, hn::IfThenElse(hn::Lt(a, zero), minusOne, zero)); };
  // dampedKick with local damping, per component: the damping load fd = ((-alpha) |f|) sign(v),
  // and v + (f + fd) (h / m) (a spin: the torque and h / I).
  auto kick = [&](V vel, V load, V hOverMass, V& damping) {
    damping = hn::Mul(hn::Mul(minusAlpha, hn::Abs(load)), sign(vel));
    return hn::Add(vel, hn::Mul(hn::Add(load, damping), hOverMass));
  };
  // Eigen's 3-vector dot product: (a0 b0 + a1 b1) + a2 b2.
  auto dot = [](V a0, V a1, V a2, V b0, V b1, V b2) {
    return hn::Add(hn::Add(hn::Mul(a0, b0), hn::Mul(a1, b1)), hn::Mul(a2, b2));
  };
  double* const x = p.position->data();
  double* const v = p.velocity->data();
  double* const w = p.angularVelocity->data();
  double* const q = p.orientation->coeffs().data();  // x, y, z, w per particle
  const double* const force = p.force->data();
  const double* const torque = p.torque->data();
  HWY_ALIGN double damping[hn::MaxLanes(d)];
  HWY_ALIGN double gravityWork[hn::MaxLanes(d)];
  std::size_t i = begin;
  for (; i + lanes <= end; i += lanes) {
    V x0, x1, x2, v0, v1, v2, w0, w1, w2, f0, f1, f2, t0, t1, t2;
    hn::LoadInterleaved3(d, x + 3 * i, x0, x1, x2);
    hn::LoadInterleaved3(d, v + 3 * i, v0, v1, v2);
    hn::LoadInterleaved3(d, w + 3 * i, w0, w1, w2);
    hn::LoadInterleaved3(d, force + 3 * i, f0, f1, f2);
    hn::LoadInterleaved3(d, torque + 3 * i, t0, t1, t2);
    const V m = hn::LoadU(d, p.mass + i), invM = hn::LoadU(d, p.invMass + i);
    const V invI = hn::LoadU(d, p.invInertia + i);
    // f = force + m g
    f0 = hn::Add(f0, hn::Mul(m, g0));
    f1 = hn::Add(f1, hn::Mul(m, g1));
    f2 = hn::Add(f2, hn::Mul(m, g2));
    // the damped kicks of the velocity (force, h / m) and of the spin (torque, h / I)
    const V hm = hn::Mul(h, invM), hi = hn::Mul(h, invI);
    V fd0, fd1, fd2, td0, td1, td2;
    const V vn0 = kick(v0, f0, hm, fd0), vn1 = kick(v1, f1, hm, fd1), vn2 = kick(v2, f2, hm, fd2);
    const V wn0 = kick(w0, t0, hi, td0), wn1 = kick(w1, t1, hi, td1), wn2 = kick(w2, t2, hi, td2);
    // q <- Quat(1, (0.5 h) w) * q, renormalised, where |w|^2 > 0 (Eigen's SSE quaternion product)
    const auto spinning = hn::Gt(hn::Add(hn::Add(hn::Mul(wn0, wn0), hn::Mul(wn1, wn1)), hn::Mul(wn2, wn2)), zero);
    if (!hn::AllFalse(d, spinning)) {
      V bx, by, bz, bw;
      hn::LoadInterleaved4(d, q + 4 * i, bx, by, bz, bw);
      const V ax = hn::Mul(halfH, wn0), ay = hn::Mul(halfH, wn1), az = hn::Mul(halfH, wn2), aw = one;
      const V rx = hn::Sub(hn::Add(hn::Mul(aw, bx), hn::Mul(ay, bz)), hn::Sub(hn::Mul(az, by), hn::Mul(ax, bw)));
      const V ry = hn::Add(hn::Add(hn::Mul(aw, by), hn::Mul(ay, bw)), hn::Sub(hn::Mul(az, bx), hn::Mul(ax, bz)));
      const V rz = hn::Add(hn::Sub(hn::Mul(aw, bz), hn::Mul(ay, bx)), hn::Add(hn::Mul(az, bw), hn::Mul(ax, by)));
      const V rw = hn::Sub(hn::Sub(hn::Mul(aw, bw), hn::Mul(ay, by)), hn::Add(hn::Mul(az, bz), hn::Mul(ax, bx)));
      // eps = |qn|^2 - 1 with Eigen's two-lane sum (x^2 + z^2) + (y^2 + w^2)
      const V eps = hn::Sub(hn::Add(hn::Add(hn::Mul(rx, rx), hn::Mul(rz, rz)), hn::Add(hn::Mul(ry, ry), hn::Mul(rw, rw))), one);
      const V series = hn::Add(hn::Sub(one, hn::Mul(half, eps)), hn::Mul(hn::Mul(hn::Set(d, 0.375), eps), eps));
      const V root = hn::Div(one, hn::Sqrt(hn::Add(one, eps)));
      const V scale = hn::IfThenElse(hn::Lt(hn::Abs(eps), hn::Set(d, 1e-6)), series, root);
      bx = hn::IfThenElse(spinning, hn::Mul(rx, scale), bx);
      by = hn::IfThenElse(spinning, hn::Mul(ry, scale), by);
      bz = hn::IfThenElse(spinning, hn::Mul(rz, scale), bz);
      bw = hn::IfThenElse(spinning, hn::Mul(rw, scale), bw);
      hn::StoreInterleaved4(bx, by, bz, bw, d, q + 4 * i);
    }
    // damping work: h (fd . (0.5 (vOld + v)) + td . (0.5 (wOld + w)))
    const V dv = dot(fd0, fd1, fd2, hn::Mul(half, hn::Add(v0, vn0)), hn::Mul(half, hn::Add(v1, vn1)),
                     hn::Mul(half, hn::Add(v2, vn2)));
    const V dw = dot(td0, td1, td2, hn::Mul(half, hn::Add(w0, wn0)), hn::Mul(half, hn::Add(w1, wn1)),
                     hn::Mul(half, hn::Add(w2, wn2)));
    hn::Store(hn::Mul(h, hn::Add(dv, dw)), d, damping);
    // x += v h (periodic: x += v h + M x, the product with the old x)
    if constexpr (Periodic) {
      V mx0, mx1, mx2;
      times(flow, x0, x1, x2, mx0, mx1, mx2);
      x0 = hn::Add(x0, hn::Add(hn::Mul(vn0, h), mx0));
      x1 = hn::Add(x1, hn::Add(hn::Mul(vn1, h), mx1));
      x2 = hn::Add(x2, hn::Add(hn::Mul(vn2, h), mx2));
    } else {
      x0 = hn::Add(x0, hn::Mul(vn0, h));
      x1 = hn::Add(x1, hn::Mul(vn1, h));
      x2 = hn::Add(x2, hn::Mul(vn2, h));
    }
    hn::StoreInterleaved3(x0, x1, x2, d, x + 3 * i);
    hn::StoreInterleaved3(vn0, vn1, vn2, d, v + 3 * i);
    hn::StoreInterleaved3(wn0, wn1, wn2, d, w + 3 * i);
    // gravity's work: (m (g . v)) h
    if (s.gravityOn) hn::Store(hn::Mul(hn::Mul(m, dot(g0, g1, g2, vn0, vn1, vn2)), h), d, gravityWork);
    for (std::size_t k = 0; k < lanes; ++k) {
      work[i - begin + k].damping = damping[k];
      work[i - begin + k].gravity = s.gravityOn ? gravityWork[k] : 0.0;
    }
    // checks: |x - x_build|^2 (cell: |x - F x_build|^2), then finite state and (walls) inside the box: x - lo > -r and hi - x > -r
    if (measure) {
      V b0, b1, b2;
      hn::LoadInterleaved3(d, xBuild + 3 * i, b0, b1, b2);
      if constexpr (Periodic) {
        V fb0, fb1, fb2;
        times(deformation, b0, b1, b2, fb0, fb1, fb2);
        b0 = fb0, b1 = fb1, b2 = fb2;
      }
      const V d0 = hn::Sub(x0, b0), d1 = hn::Sub(x1, b1), d2 = hn::Sub(x2, b2);
      maxDisp2 = hn::Max(maxDisp2, dot(d0, d1, d2, d0, d1, d2));
    }
    auto ok = hn::And(hn::And(hn::And(hn::IsFinite(x0), hn::IsFinite(x1)), hn::And(hn::IsFinite(x2), hn::IsFinite(vn0))),
                      hn::And(hn::And(hn::IsFinite(vn1), hn::IsFinite(vn2)),
                              hn::And(hn::IsFinite(wn0), hn::And(hn::IsFinite(wn1), hn::IsFinite(wn2)))));
    if constexpr (!Periodic) {
      const V negR = hn::Neg(hn::LoadU(d, c.radius + i));
      ok = hn::And(ok, hn::And(hn::And(hn::Gt(hn::Sub(x0, lo0), negR), hn::Gt(hn::Sub(x1, lo1), negR)),
                               hn::And(hn::Gt(hn::Sub(x2, lo2), negR), hn::Gt(hn::Sub(up0, x0), negR))));
      ok = hn::And(ok, hn::And(hn::Gt(hn::Sub(up1, x1), negR), hn::Gt(hn::Sub(up2, x2), negR)));
    }
    const auto bad = hn::Not(ok);
    if (!hn::AllFalse(d, bad) && result.firstBad == ChecksResult::kNoParticle)
      result.firstBad = i + static_cast<std::size_t>(hn::FindFirstTrue(d, bad));
  }
  // The largest lane (max is exact whatever the order).
  HWY_ALIGN double lanesMax[hn::MaxLanes(d)];
  hn::Store(maxDisp2, d, lanesMax);
  for (std::size_t k = 0; k < lanes; ++k) result.maxDisplacement2 = std::max(result.maxDisplacement2, lanesMax[k]);
  return i;
}

std::size_t IntegrateSpheres(const IntegratorView& p, std::size_t begin, std::size_t end, const IntegratorStep& s,
                             bool periodic, ParticleWork* work, const StepChecks& c, ChecksResult& result) {
  return periodic ? SpheresT<true>(p, begin, end, s, work, c, result)
                  : SpheresT<false>(p, begin, end, s, work, c, result);
}

const char* TargetOfThisCode() { return hwy::TargetName(HWY_TARGET); }

}  // namespace grainlab::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <stdexcept>

namespace grainlab::kernels {

HWY_EXPORT(IntegrateSpheres);
HWY_EXPORT(TargetOfThisCode);

namespace {

struct NamedTarget {
  const char* name;
  std::int64_t target;
};
// Best first. Highway calls AVX-512 (F, BW, DQ, VL) "AVX3".
constexpr NamedTarget kTargets[] = {
    {"avx512", HWY_AVX3}, {"avx2", HWY_AVX2}, {"sse4", HWY_SSE4}, {"ssse3", HWY_SSSE3}, {"emu128", HWY_EMU128}};

// The targets compiled in and supported by this CPU, read once before any selection narrows them.
std::int64_t availableTargets() {
  static const std::int64_t available = hwy::SupportedTargets() & HWY_TARGETS;
  return available;
}

bool gScalar = false;

}  // namespace

std::vector<std::string> simdTargetNames() {
  std::vector<std::string> names{"best", "scalar"};
  for (const NamedTarget& t : kTargets)
    if (availableTargets() & t.target) names.emplace_back(t.name);
  return names;
}

void selectSimdTarget(const std::string& name) {
  const std::int64_t available = availableTargets();
  if (name == "best" || name == "scalar") {
    hwy::SetSupportedTargetsForTest(0);
    gScalar = name == "scalar";
    return;
  }
  for (const NamedTarget& t : kTargets) {
    if (name != t.name) continue;
    if (!(available & t.target)) break;
    hwy::SetSupportedTargetsForTest(t.target);
    gScalar = false;
    return;
  }
  std::string allowed;
  for (const std::string& n : simdTargetNames()) allowed += (allowed.empty() ? "" : ", ") + n;
  throw std::invalid_argument("SIMD target \"" + name + "\" is not one this program and CPU have; allowed: " + allowed);
}

std::string simdTarget() {
  if (gScalar) return "scalar";
  std::string name = HWY_DYNAMIC_DISPATCH(TargetOfThisCode)();
  for (char& c : name) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return name == "avx3" ? "avx512" : name;
}

bool simdEnabled() { return !gScalar; }

ChecksResult integrateSpheres(const IntegratorView& p, std::size_t begin, std::size_t end, const IntegratorStep& s,
                              bool periodic, ParticleWork* work, const StepChecks& c) {
  ChecksResult result;
  std::size_t i = begin;
  if (!gScalar) i = HWY_DYNAMIC_DISPATCH(IntegrateSpheres)(p, begin, end, s, periodic, work, c, result);
  // The rest (fewer than one vector) with the scalar kernel: the same bits.
  for (; i < end; ++i) {
    if (periodic) {
      work[i - begin] = integrateParticle<true>(p, i, s);
      checkParticle<true>(p, i, c, result);
    } else {
      work[i - begin] = integrateParticle<false>(p, i, s);
      checkParticle<false>(p, i, c, result);
    }
  }
  return result;
}

}  // namespace grainlab::kernels
#endif  // HWY_ONCE
