// The [W] sphere law over Highway vectors (see contact_simd.hpp). Compiled once per target by
// foreach_target.h; every expression quotes the scalar one it mirrors, in Eigen's evaluation order
// (docs/architecture.md, "Floating point").
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/kernels/contact_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/kernels/contact_simd.hpp"
#include "core/kernels/integrate_simd.hpp"

HWY_BEFORE_NAMESPACE();
namespace grainlab::kernels::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void SphereLawTileImpl(const SphereLawConstants& kc, SphereLawTile& t, std::size_t count) {
  const hn::ScalableTag<double> d;
  using V = hn::Vec<decltype(d)>;
  const std::size_t lanes = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), half = hn::Set(d, 0.5), two = hn::Set(d, 2.0);
  const V twoYoung = hn::Set(d, 2.0 * kc.young), poisson = hn::Set(d, kc.poisson), beta = hn::Set(d, kc.beta);
  const V etaHalf = hn::Set(d, kc.eta * 0.5), tanF = hn::Set(d, kc.tanFriction), dt = hn::Set(d, kc.dt);
  const V tiny = hn::Set(d, 1e-12);
  const Mat3& L = kc.velocityGradient;
  const V l00 = hn::Set(d, L(0, 0)), l01 = hn::Set(d, L(0, 1)), l02 = hn::Set(d, L(0, 2));
  const V l10 = hn::Set(d, L(1, 0)), l11 = hn::Set(d, L(1, 1)), l12 = hn::Set(d, L(1, 2));
  const V l20 = hn::Set(d, L(2, 0)), l21 = hn::Set(d, L(2, 1)), l22 = hn::Set(d, L(2, 2));
  struct V3 {
    V x, y, z;
  };
  auto load3 = [&](const double (*a)[SphereLawTile::kSize], std::size_t i) {
    return V3{hn::Load(d, a[0] + i), hn::Load(d, a[1] + i), hn::Load(d, a[2] + i)};
  };
  auto store3 = [&](const V3& v, double (*a)[SphereLawTile::kSize], std::size_t i) {
    hn::Store(v.x, d, a[0] + i);
    hn::Store(v.y, d, a[1] + i);
    hn::Store(v.z, d, a[2] + i);
  };
  auto add = [](const V3& a, const V3& b) { return V3{hn::Add(a.x, b.x), hn::Add(a.y, b.y), hn::Add(a.z, b.z)}; };
  auto sub = [](const V3& a, const V3& b) { return V3{hn::Sub(a.x, b.x), hn::Sub(a.y, b.y), hn::Sub(a.z, b.z)}; };
  auto scale = [](V s, const V3& a) { return V3{hn::Mul(s, a.x), hn::Mul(s, a.y), hn::Mul(s, a.z)}; };
  // Eigen: a.dot(b) = (a0 b0 + a1 b1) + a2 b2; a.cross(b) = (a1 b2 - a2 b1, a2 b0 - a0 b2, a0 b1 - a1 b0)
  auto dot = [](const V3& a, const V3& b) {
    return hn::Add(hn::Add(hn::Mul(a.x, b.x), hn::Mul(a.y, b.y)), hn::Mul(a.z, b.z));
  };
  auto cross = [](const V3& a, const V3& b) {
    return V3{hn::Sub(hn::Mul(a.y, b.z), hn::Mul(a.z, b.y)), hn::Sub(hn::Mul(a.z, b.x), hn::Mul(a.x, b.z)),
              hn::Sub(hn::Mul(a.x, b.y), hn::Mul(a.y, b.x))};
  };
  auto select = [](auto mask, const V3& a, const V3& b) {
    return V3{hn::IfThenElse(mask, a.x, b.x), hn::IfThenElse(mask, a.y, b.y), hn::IfThenElse(mask, a.z, b.z)};
  };
  // FrameRotation::operator*: ((w w - u.u) v + (2 u.v) u + (2 w) u x v) / |q|^2 (times invNorm2)
  auto rotate = [&](V w, const V3& u, V invNorm2, const V3& v) {
    const V c1 = hn::Sub(hn::Mul(w, w), dot(u, u));
    const V c2 = hn::Mul(two, dot(u, v));
    const V c3 = hn::Mul(two, w);
    const V3 x = cross(u, v);
    return V3{hn::Mul(hn::Add(hn::Add(hn::Mul(c1, v.x), hn::Mul(c2, u.x)), hn::Mul(c3, x.x)), invNorm2),
              hn::Mul(hn::Add(hn::Add(hn::Mul(c1, v.y), hn::Mul(c2, u.y)), hn::Mul(c3, x.y)), invNorm2),
              hn::Mul(hn::Add(hn::Add(hn::Mul(c1, v.z), hn::Mul(c2, u.z)), hn::Mul(c3, x.z)), invNorm2)};
  };
  // tangentialCoulomb's and momentElasticPlastic's limit: trial scaled to `limit` where
  // |trial|^2 > limit^2 (0 if |trial| = 0), dissipation ((|trial| - limit) limit) / k (0 if k = 0)
  struct Limited {
    V3 value;
    V dissipation;
  };
  auto limitTo = [&](const V3& trial, V limit, V k) {
    const V mag2 = dot(trial, trial);
    const auto over = hn::Gt(mag2, hn::Mul(limit, limit));
    const V mag = hn::Sqrt(mag2);
    const V3 scaled = select(hn::Gt(mag, zero), scale(hn::Div(limit, mag), trial), V3{zero, zero, zero});
    const V lost = hn::IfThenElse(hn::Gt(k, zero), hn::Div(hn::Mul(hn::Sub(mag, limit), limit), k), zero);
    return Limited{select(over, scaled, trial), hn::IfThenElse(over, lost, zero)};
  };
  // Note the scalar `trial * (limit / mag)` is Vec3 * scalar: each component times (limit / mag).

  for (std::size_t i = 0; i < count; i += lanes) {
    const V3 branch = load3(t.branch, i);
    const V rA = hn::Load(d, t.radiusA + i), rB = hn::Load(d, t.radiusB + i);
    // geometry::sphereSphere: dist = sqrt(branch.squaredNorm()), N = branch (1 / dist),
    // U = rA + rB - dist, branchA = (rA - 0.5 U) N, branchB = branchA - branch
    const V dist = hn::Sqrt(dot(branch, branch));
    const V3 normal = scale(hn::Div(one, dist), branch);
    const V overlap = hn::Sub(hn::Add(rA, rB), dist);
    const V3 branchA = scale(hn::Sub(rA, hn::Mul(half, overlap)), normal);
    const V3 branchB = sub(branchA, branch);
    // a contact that forms: prevNormal = N
    const auto fresh = hn::Gt(hn::Load(d, t.fresh + i), zero);
    const V3 prevNormal = select(fresh, normal, load3(t.prevNormal, i));
    // pairParams (linear, Kozicki–Donzé, [W] limit): Kn = 2 Ec rA rB / (rA + rB), Ks = nu Kn,
    // Kr = beta Ks rA rB, arm = eta 0.5 (rA + rB), all left to right
    const V kn = hn::Div(hn::Mul(hn::Mul(twoYoung, rA), rB), hn::Add(rA, rB));
    const V ks = hn::Mul(poisson, kn);
    V kr, arm;
    if (kc.linearRolling) {
      // [R]: R = (rA rB)/(rA + rB), Kr = (Ks R) R, arm = mu_r(combined) R
      const V rBar = hn::Div(hn::Mul(rA, rB), hn::Add(rA, rB));
      kr = hn::Mul(hn::Mul(ks, rBar), rBar);
      const V muA = hn::Load(d, t.muA + i), muB = hn::Load(d, t.muB + i);
      V mu;
      switch (kc.combine) {
        case contact::CombineRule::Min: mu = hn::IfThenElse(hn::Lt(muB, muA), muB, muA); break;  // std::min
        case contact::CombineRule::Mean: mu = hn::Mul(half, hn::Add(muA, muB)); break;
        case contact::CombineRule::Harmonic: {
          const V sum = hn::Add(muA, muB);
          mu = hn::IfThenElse(hn::Gt(sum, zero), hn::Div(hn::Mul(hn::Mul(two, muA), muB), sum), zero);
          break;
        }
      }
      arm = hn::Mul(mu, rBar);
    } else {
      kr = hn::Mul(hn::Mul(hn::Mul(beta, ks), rA), rB);
      arm = hn::Mul(etaHalf, hn::Add(rA, rB));
    }
    // pairKinematics: vrel = (vb + wb x branchB) - (va + wa x branchA), spin = wb - wa,
    // meanSpinNormal = 0.5 ((wa + wb) . N)
    const V3 va = load3(t.va, i), vb = load3(t.vb, i), wa = load3(t.wa, i), wb = load3(t.wb, i);
    V3 vrel = sub(add(vb, cross(wb, branchB)), add(va, cross(wa, branchA)));
    if (kc.periodic) {
      // += L l, Eigen's row order: rows 0 and 1 (L0 l0 + L1 l1) + L2 l2, row 2 L0 l0 + (L1 l1 + L2 l2)
      const V3 flow{hn::Add(hn::Add(hn::Mul(l00, branch.x), hn::Mul(l01, branch.y)), hn::Mul(l02, branch.z)),
                    hn::Add(hn::Add(hn::Mul(l10, branch.x), hn::Mul(l11, branch.y)), hn::Mul(l12, branch.z)),
                    hn::Add(hn::Mul(l20, branch.x), hn::Add(hn::Mul(l21, branch.y), hn::Mul(l22, branch.z)))};
      vrel = add(vrel, flow);
    }
    const V3 spin = sub(wb, wa);
    const V meanSpinNormal = hn::Mul(half, dot(add(wa, wb), normal));
    // applyLaw: Fn = (U > 0 ? Kn U : 0) N, fn = Kn U
    const V fn = hn::Mul(kn, overlap);
    const V3 normalForce = scale(hn::IfThenElse(hn::Gt(overlap, zero), fn, zero), normal);
    // applyShearAndMoment: twist = meanSpinNormal dt, vt = vrel - N (N . vrel)
    const V twist = hn::Mul(meanSpinNormal, dt);
    const V3 vt = sub(vrel, scale(dot(normal, vrel), normal));
    // contactFrameRotation(prevNormal, N, twist): tw = 1 + n0 . n, tu = n0 x n (tw <= 1e-12: 1, 0),
    // half = (0.5 twist) N, w = tw - half . tu, u = (tu + tw half) + half x tu, 1/(w w + u . u)
    V tw = hn::Add(one, dot(prevNormal, normal));
    V3 tu = cross(prevNormal, normal);
    const auto reversed = hn::Le(tw, tiny);
    tw = hn::IfThenElse(reversed, one, tw);
    tu = select(reversed, V3{zero, zero, zero}, tu);
    const V3 halfTwist = scale(hn::Mul(half, twist), normal);
    const V fw = hn::Sub(tw, dot(halfTwist, tu));
    const V3 fu = add(add(tu, scale(tw, halfTwist)), cross(halfTwist, tu));
    const V invNorm2 = hn::Div(one, hn::Add(hn::Mul(fw, fw), dot(fu, fu)));
    // tangentialCoulomb(frame * Fs, Ks, vt dt, N, fn, tan phi): trial = carried - Ks (vt dt),
    // trial -= N (N . trial), limit fn tan phi
    const V3 carried = rotate(fw, fu, invNorm2, load3(t.shear, i));
    V3 trial = sub(carried, scale(ks, scale(dt, vt)));
    trial = sub(trial, scale(dot(normal, trial), normal));
    const Limited shear = limitTo(trial, hn::Mul(fn, tanF), ks);
    // momentElasticPlastic(frame * M, Kr, spin dt, arm fn): trial = carried + Kr dTheta
    V3 dTheta = scale(dt, spin);
    V3 carriedMoment = rotate(fw, fu, invNorm2, load3(t.moment, i));
    if (kc.linearRolling) {
      // bending only: bendingPart(x, N) = x - N (N . x), of the increment and of the carried moment
      dTheta = sub(dTheta, scale(dot(normal, dTheta), normal));
      carriedMoment = sub(carriedMoment, scale(dot(normal, carriedMoment), normal));
    }
    const Limited moment = limitTo(add(carriedMoment, scale(kr, dTheta)), hn::Mul(arm, fn), kr);
    // force = Fn + Fs; storePair: torqueA = branchA x (-F) + M, torqueB = branchB x F - M
    const V3 force = add(normalForce, shear.value);
    const V3 minusForce{hn::Neg(force.x), hn::Neg(force.y), hn::Neg(force.z)};
    store3(force, t.force, i);
    store3(add(cross(branchA, minusForce), moment.value), t.torqueA, i);
    store3(sub(cross(branchB, force), moment.value), t.torqueB, i);
    store3(shear.value, t.shear, i);
    store3(moment.value, t.moment, i);
    store3(normal, t.prevNormal, i);
    hn::Store(shear.dissipation, d, t.slip + i);
    hn::Store(moment.dissipation, d, t.roll + i);
  }
}

}  // namespace grainlab::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace grainlab::kernels {

HWY_EXPORT(SphereLawTileImpl);

bool sphereLawVectorised(const contact::SphereContactModel& m) {
  const bool moments = (m.rolling == contact::RollingLaw::KozickiDonze && !m.yadeMomentLimit && m.beta > 0.0) ||
                       m.rolling == contact::RollingLaw::Linear;
  return simdEnabled() && !m.hertz() && moments && m.constantKn <= 0.0 && m.poisson > 0.0 && m.young > 0.0;
}

void sphereLawTile(const SphereLawConstants& k, SphereLawTile& t, std::size_t count) {
  HWY_DYNAMIC_DISPATCH(SphereLawTileImpl)(k, t, count);
}

}  // namespace grainlab::kernels
#endif  // HWY_ONCE
