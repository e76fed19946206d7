#pragma once
// The one contact driver, instantiated per pair kind (and boundary): for every candidate of a kind's
// list it asks the kind's narrow phase for the geometry, applies the contact law (slots of
// contact/models.hpp) with the pair's parameters and the contact's history, and writes the result
// slots. Geometry x parameters x history -> force (YADE's Ig2 / Ip2 / Law2). No virtual call or
// switch per contact: the kind is a template argument.
//
// Parameters (the Ip2 step) are computed from the two bodies when a contact is evaluated rather than
// stored per contact: for spheres they are a handful of multiplications and one division, cheaper
// than reading 48 stored bytes per contact per step, and they follow a stiffness change (the
// preparation's stiffness ramp) without a pass over the contacts (bench/NOTES.md has the measurement).
#include <type_traits>

#include "contact/models.hpp"
#include "core/contact_list.hpp"
#include "core/kernels/contact_simd.hpp"
#include "core/parallel.hpp"
#include "core/particles.hpp"
#include "core/periodic_cell.hpp"
#include "core/walls.hpp"
#include "geometry/ellipsoid_contacts.hpp"
#include "geometry/sphere_contacts.hpp"

namespace grainlab {

// What a kernel reads besides its own list.
struct ContactContext {
  const Particles& particles;
  const contact::SphereContactModel& model;
  const WallBox& box;
  const PeriodicCell& cell;
  double dt;
  // Shape matrices X = Q diag(a^2, b^2, c^2) Q^T of the step, per particle (ellipsoids only).
  const std::vector<geometry::Sym3>* shapeMatrices = nullptr;
};

// Terms summed per chunk of contacts (deterministic, see parallel.hpp).
enum ContactSum : int {
  kSlip = 0,
  kRoll,
  kViscous,  // Hertz–Mindlin's normal dashpots
  // Periodic cell only: Love–Weber stress terms f_i l_j (9) and the servo's affine stiffnesses
  // (3 normal: xx, yy, zz; 3 shear: yz, xz, xy).
  kStress0,
  kStiffness0 = kStress0 + 9,
  kShearStiffness0 = kStiffness0 + 3,
  kContactSums = kShearStiffness0 + 3,
};

namespace detail {

// Kinematics of a particle pair at the contact point (every particle–particle kind).
template <bool Periodic>
GRAINLAB_ALWAYS_INLINE contact::ContactKinematics pairKinematics(const ContactContext& ctx, std::uint32_t a,
                                                                 std::uint32_t b, const geometry::ContactGeometry& g,
                                                                 const Vec3& branch) {
  const auto& v = ctx.particles.velocity;
  const auto& w = ctx.particles.angularVelocity;
  contact::ContactKinematics k;
  k.normal = g.normal;
  k.overlap = g.overlap;
  k.relativeVelocity = (v[b] + w[b].cross(g.branchB)) - (v[a] + w[a].cross(g.branchA));
  // In a periodic cell the bodies' velocities are fluctuations about the homogeneous flow, whose
  // relative velocity across the branch (image shift included) is L l (docs/physics.md §3, §8.2).
  if constexpr (Periodic) k.relativeVelocity += ctx.cell.velocityGradient * branch;
  k.relativeSpin = w[b] - w[a];
  k.meanSpinNormal = 0.5 * (w[a] + w[b]).dot(g.normal);
  k.dt = ctx.dt;
  return k;
}

// Kinematics of a particle (body B) against a wall (body A).
GRAINLAB_ALWAYS_INLINE contact::ContactKinematics wallKinematics(const ContactContext& ctx, std::uint32_t i,
                                                                 const Wall& wall, const geometry::ContactGeometry& g) {
  const auto& v = ctx.particles.velocity;
  const auto& w = ctx.particles.angularVelocity;
  Vec3 wallVelocity = Vec3::Zero();
  wallVelocity[wall.axis] = wall.velocity;
  contact::ContactKinematics k;
  k.normal = g.normal;
  k.overlap = g.overlap;
  k.relativeVelocity = v[i] + w[i].cross(g.branchB) - wallVelocity;
  k.relativeSpin = w[i];
  k.meanSpinNormal = 0.5 * w[i].dot(g.normal);
  k.dt = ctx.dt;
  return k;
}

template <class List>
GRAINLAB_ALWAYS_INLINE void storePair(List& list, std::size_t c, const geometry::ContactGeometry& g,
                                      const contact::ContactResponse& res) {
  list.force[c] = res.force;
  list.torqueA[c] = g.branchA.cross(-res.force) + res.moment;
  list.torqueB[c] = g.branchB.cross(res.force) - res.moment;
}

template <class List>
GRAINLAB_ALWAYS_INLINE void storeWall(List& list, std::size_t c, const geometry::ContactGeometry& g,
                                      const contact::ContactResponse& res) {
  list.force[c] = res.force;
  list.torqueA[c] = g.branchB.cross(res.force) - res.moment;
}

template <bool Periodic, class List>
GRAINLAB_ALWAYS_INLINE Vec3 pairBranch(const ContactContext& ctx, const List& list, std::size_t c) {
  const auto& x = ctx.particles.position;
  if constexpr (Periodic) return x[list.b[c]] + ctx.cell.shiftVector(list.shift[c]) - x[list.a[c]];
  else return x[list.b[c]] - x[list.a[c]];
}

// The plane of a wall through the particle's projection on it.
GRAINLAB_ALWAYS_INLINE Vec3 wallPoint(const Wall& wall, const Vec3& x) {
  Vec3 p = x;
  p[wall.axis] = wall.position;
  return p;
}

// What every body pair of one kind shares: the kinematics at the contact point, the Ip2 parameters
// from the two bodies' radii (the sphere radius, or an ellipsoid's volume-equivalent radius) and
// the stored force and moment.
template <class Kind, bool Periodic, bool EquivalentRadius>
struct PairKernelBase {
  using List = ContactList<Kind>;
  GRAINLAB_ALWAYS_INLINE static contact::ContactKinematics kinematics(const ContactContext& ctx, const List& list,
                                                                      std::size_t c, const geometry::ContactGeometry& g,
                                                                      const Vec3& branch) {
    return pairKinematics<Periodic>(ctx, list.a[c], list.b[c], g, branch);
  }
  GRAINLAB_ALWAYS_INLINE static contact::PairParams params(const ContactContext& ctx, const List& list, std::size_t c) {
    const auto& r = EquivalentRadius ? ctx.particles.equivalentRadius : ctx.particles.radius;
    const auto& mu = ctx.particles.rollingFriction;
    const std::uint32_t a = list.a[c], b = list.b[c];
    contact::PairParams p = ctx.model.pairParams(r[a], r[b], mu[a], mu[b]);
    if (ctx.model.restitutionBeta != 0.0) {
      const auto& m = ctx.particles.mass;
      p.damping = ctx.model.dampingFactor(m[a] * m[b] / (m[a] + m[b]));
    }
    return p;
  }
  GRAINLAB_ALWAYS_INLINE static void store(List& list, std::size_t c, const geometry::ContactGeometry& g,
                                           const contact::ContactResponse& res) {
    storePair(list, c, g, res);
  }
};

// The same for a body (list.a) against a wall (list.b).
template <class Kind, bool EquivalentRadius>
struct WallKernelBase {
  using List = ContactList<Kind>;
  GRAINLAB_ALWAYS_INLINE static contact::ContactKinematics kinematics(const ContactContext& ctx, const List& list,
                                                                      std::size_t c, const geometry::ContactGeometry& g,
                                                                      const Vec3&) {
    return wallKinematics(ctx, list.a[c], ctx.box.walls[list.b[c]], g);
  }
  GRAINLAB_ALWAYS_INLINE static contact::PairParams params(const ContactContext& ctx, const List& list, std::size_t c) {
    const std::uint32_t i = list.a[c];
    const double r = EquivalentRadius ? ctx.particles.equivalentRadius[i] : ctx.particles.radius[i];
    contact::PairParams p = ctx.model.wallParams(r, ctx.box.walls[list.b[c]].tanFriction, ctx.particles.rollingFriction[i]);
    if (ctx.model.restitutionBeta != 0.0) p.damping = ctx.model.dampingFactor(ctx.particles.mass[i]);
    return p;
  }
  GRAINLAB_ALWAYS_INLINE static void store(List& list, std::size_t c, const geometry::ContactGeometry& g,
                                           const contact::ContactResponse& res) {
    storeWall(list, c, g, res);
  }
};

// An ellipsoid solve's outcome: keeps lambda and the potential length for the next step's warm start.
GRAINLAB_ALWAYS_INLINE bool acceptEllipsoidContact(const geometry::EllipsoidContact& e, contact::EllipsoidHistory& h,
                                                   geometry::ContactGeometry& g) {
  if (!e.touching) return false;
  h.lambda = e.lambda;
  h.potentialLength = e.potentialLength;
  g = e.geometry;
  return true;
}

// The narrow phase of one contact of a kind: fills the geometry (and the branch vector of a pair)
// and returns false when the bodies are apart.
template <class Kind, bool Periodic>
struct KindKernel;

template <bool Periodic>
struct KindKernel<SphereSphere, Periodic> : PairKernelBase<SphereSphere, Periodic, false> {
  using List = ContactList<SphereSphere>;
  GRAINLAB_ALWAYS_INLINE static bool evaluate(const ContactContext& ctx, const List& list, std::size_t c,
                                              contact::ContactHistory&, geometry::ContactGeometry& g, Vec3& branch) {
    const auto& rad = ctx.particles.radius;
    const std::uint32_t a = list.a[c], b = list.b[c];
    branch = pairBranch<Periodic>(ctx, list, c);
    const double dist2 = branch.squaredNorm();
    const double reach = rad[a] + rad[b];
    if (dist2 >= reach * reach) return false;
    g = geometry::sphereSphere(branch, dist2, rad[a], rad[b]);
    return true;
  }
};

// The wall is body A, the sphere body B (the plane's normal points into the sphere's side).
template <bool Periodic>
struct KindKernel<SpherePlane, Periodic> : WallKernelBase<SpherePlane, false> {
  using List = ContactList<SpherePlane>;
  GRAINLAB_ALWAYS_INLINE static bool evaluate(const ContactContext& ctx, const List& list, std::size_t c,
                                              contact::ContactHistory&, geometry::ContactGeometry& g, Vec3&) {
    const std::uint32_t i = list.a[c];
    const Wall& wall = ctx.box.walls[list.b[c]];
    const Vec3& x = ctx.particles.position[i];
    g = geometry::spherePlane(x, ctx.particles.radius[i], wallPoint(wall, x), wall.inwardNormal());
    return g.overlap > 0.0;
  }
};

// Ellipsoid pairs: bounding spheres, then the line-of-centres filter, then the Perram–Wertheim
// solve warm-started from the lambda of the last step, with the potential length frozen when the
// contact forms (docs/ellipsoids.md).
template <bool Periodic>
struct KindKernel<EllipsoidEllipsoid, Periodic> : PairKernelBase<EllipsoidEllipsoid, Periodic, true> {
  using List = ContactList<EllipsoidEllipsoid>;
  GRAINLAB_ALWAYS_INLINE static bool evaluate(const ContactContext& ctx, const List& list, std::size_t c,
                                              contact::EllipsoidHistory& h, geometry::ContactGeometry& g,
                                              Vec3& branch) {
    const std::uint32_t a = list.a[c], b = list.b[c];
    const auto& rad = ctx.particles.radius;
    branch = pairBranch<Periodic>(ctx, list, c);
    if (!geometry::boundingSpheresOverlap(branch, rad[a], rad[b])) return false;
    const auto& xs = *ctx.shapeMatrices;
    if (geometry::separatedAlongCentreLine(branch, xs[a], xs[b])) return false;
    return acceptEllipsoidContact(
        geometry::ellipsoidEllipsoid(branch, xs[a], xs[b], h.lambda, h.touching ? h.potentialLength : 0.0), h, g);
  }
};

// A sphere (body a) and an ellipsoid (body b), solved in the ellipsoid's frame.
template <bool Periodic>
struct KindKernel<SphereEllipsoid, Periodic> : PairKernelBase<SphereEllipsoid, Periodic, true> {
  using List = ContactList<SphereEllipsoid>;
  GRAINLAB_ALWAYS_INLINE static bool evaluate(const ContactContext& ctx, const List& list, std::size_t c,
                                              contact::EllipsoidHistory& h, geometry::ContactGeometry& g,
                                              Vec3& branch) {
    const std::uint32_t a = list.a[c], b = list.b[c];
    const Particles& P = ctx.particles;
    branch = pairBranch<Periodic>(ctx, list, c);
    if (!geometry::boundingSpheresOverlap(branch, P.radius[a], P.radius[b])) return false;
    return acceptEllipsoidContact(geometry::sphereEllipsoid(branch, P.radius[a], P.semiAxes[b], P.orientation[b],
                                                            h.lambda, h.touching ? h.potentialLength : 0.0),
                                  h, g);
  }
};

// An ellipsoid (body B) against a wall (body A): the closed-form support point.
template <bool Periodic>
struct KindKernel<EllipsoidPlane, Periodic> : WallKernelBase<EllipsoidPlane, true> {
  using List = ContactList<EllipsoidPlane>;
  GRAINLAB_ALWAYS_INLINE static bool evaluate(const ContactContext& ctx, const List& list, std::size_t c,
                                              contact::ContactHistory&, geometry::ContactGeometry& g, Vec3&) {
    const std::uint32_t i = list.a[c];
    const Wall& wall = ctx.box.walls[list.b[c]];
    const Vec3& x = ctx.particles.position[i];
    const geometry::EllipsoidPlaneContact e =
        geometry::ellipsoidPlane(x, (*ctx.shapeMatrices)[i], wallPoint(wall, x), wall.inwardNormal());
    g = e.geometry;
    return e.touching;
  }
};

// A candidate found apart: a contact that was touching opens, and what its shear and moment
// springs still hold is released with the history (the model keeps no memory of it), so it is
// booked as dissipated, slip and rolling (added to slip and roll: the energy balance stays
// closed); its history and result slots are cleared. Returns false when there was nothing to do (a
// pair that was apart and still is keeps its zero slots, so it is skipped without a write).
template <class Kernel, class List>
GRAINLAB_ALWAYS_INLINE bool releaseApart(const ContactContext& ctx, List& list, std::size_t c, bool writeAll,
                                         double& slip, double& roll) {
  using Kind = typename List::KindType;
  typename Kind::History& h = list.history[c];
  if (!h.touching && !writeAll) return false;
  if (h.touching) {
    contact::PairParams p = Kernel::params(ctx, list, c);
    contact::SphereContactModel::resolve(p, h.overlap);  // Hertz–Mindlin: the springs' last stiffness
    if (p.ks > 0.0) slip += 0.5 * h.shearForce.squaredNorm() / p.ks;
    if (p.kr > 0.0) roll += 0.5 * h.moment.squaredNorm() / p.kr;
  }
  h = typename Kind::History{};  // (an ellipsoid pair's lambda restarts cold: its solve is cheap)
  list.force[c].setZero();
  list.torqueA[c].setZero();
  if constexpr (!Kind::kPlane) list.torqueB[c].setZero();
  return true;
}

// A touching pair's terms of the cell's Love–Weber stress (f l^T) and of the servo's affine
// stiffnesses, added to the chunk's sums.
GRAINLAB_ALWAYS_INLINE void addCellTerms(Mat3& stress, Vec3& stiffness, Vec3& shearStiffness, const Vec3& force,
                                         const Vec3& branch, const Vec3& normal, double kn, double ks) {
  stress += force * branch.transpose();
  const Vec3 n2 = normal.cwiseProduct(normal);
  const double l2 = branch.squaredNorm();
  stiffness += l2 * n2.cwiseProduct(kn * n2 + ks * (Vec3::Ones() - n2));
  // Pure shear e in the (i, j) plane: l2 (2 kn ni^2 nj^2 + ks ((ni^2 + nj^2)/2 - 2 ni^2 nj^2)).
  for (int k = 0; k < 3; ++k) {
    const int i = k == 0 ? 1 : 0, j = k == 2 ? 1 : 2;
    const double ninj = n2[i] * n2[j];
    shearStiffness[k] += l2 * (2.0 * kn * ninj + ks * (0.5 * (n2[i] + n2[j]) - 2.0 * ninj));
  }
}

// Sphere pairs with the [W] law, vectorised (core/kernels/contact_simd.hpp):
// per chunk, the apart test and the release of opened contacts here, the touching contacts
// gathered into tiles for the vector kernel and scattered back. Each contact's dissipation is kept
// and the chunk's sums are added in contact order afterwards, as the scalar loop adds them: the
// same bits.
template <bool Periodic>
void evaluateSphereTiles(ContactList<SphereSphere>& list, const ContactContext& ctx, ChunkedSums& sums,
                         bool writeAll) {
  using Kernel = KindKernel<SphereSphere, Periodic>;
  using Tile = kernels::SphereLawTile;
  kernels::SphereLawConstants constants{ctx.model.young, ctx.model.poisson,     ctx.model.beta,
                                        ctx.model.eta,   ctx.model.tanFriction, ctx.dt};
  constants.periodic = Periodic;
  constants.linearRolling = ctx.model.rolling == contact::RollingLaw::Linear;
  constants.combine = ctx.model.combine;
  if constexpr (Periodic) constants.velocityGradient = ctx.cell.velocityGradient;
  const Particles& P = ctx.particles;
#pragma omp for schedule(dynamic, 1) nowait
  for (std::size_t chunk = 0; chunk < sums.chunks(); ++chunk) {
    const std::size_t first = sums.begin(chunk), last = sums.end(chunk);
    double slipOf[ChunkedSums::kChunk], rollOf[ChunkedSums::kChunk];
    Mat3 stress = Mat3::Zero();
    Vec3 stiffness = Vec3::Zero(), shearStiffness = Vec3::Zero();
    Tile tile;
    std::uint32_t slot[Tile::kSize];
    std::size_t n = 0;
    auto flush = [&] {
      // Pad to whole vectors with lane 0 (computed, not used).
      const std::size_t padded = (n + 7) / 8 * 8;
      for (std::size_t j = n; j < padded; ++j) {
        for (int k = 0; k < 3; ++k) {
          tile.branch[k][j] = tile.branch[k][0];
          tile.va[k][j] = tile.va[k][0], tile.vb[k][j] = tile.vb[k][0];
          tile.wa[k][j] = tile.wa[k][0], tile.wb[k][j] = tile.wb[k][0];
          tile.shear[k][j] = tile.shear[k][0], tile.moment[k][j] = tile.moment[k][0];
          tile.prevNormal[k][j] = tile.prevNormal[k][0];
        }
        tile.radiusA[j] = tile.radiusA[0], tile.radiusB[j] = tile.radiusB[0], tile.fresh[j] = tile.fresh[0];
        tile.muA[j] = tile.muA[0], tile.muB[j] = tile.muB[0];
      }
      kernels::sphereLawTile(constants, tile, padded);
      for (std::size_t j = 0; j < n; ++j) {
        const std::uint32_t c = slot[j];
        contact::ContactHistory& h = list.history[c];
        list.force[c] = Vec3(tile.force[0][j], tile.force[1][j], tile.force[2][j]);
        list.torqueA[c] = Vec3(tile.torqueA[0][j], tile.torqueA[1][j], tile.torqueA[2][j]);
        list.torqueB[c] = Vec3(tile.torqueB[0][j], tile.torqueB[1][j], tile.torqueB[2][j]);
        h.shearForce = Vec3(tile.shear[0][j], tile.shear[1][j], tile.shear[2][j]);
        h.moment = Vec3(tile.moment[0][j], tile.moment[1][j], tile.moment[2][j]);
        h.prevNormal = Vec3(tile.prevNormal[0][j], tile.prevNormal[1][j], tile.prevNormal[2][j]);
        slipOf[c - first] = tile.slip[j];
        rollOf[c - first] = tile.roll[j];
        if constexpr (Periodic) {
          // in contact order, as the scalar loop adds them
          const contact::PairParams p = Kernel::params(ctx, list, c);
          addCellTerms(stress, stiffness, shearStiffness, list.force[c],
                       Vec3(tile.branch[0][j], tile.branch[1][j], tile.branch[2][j]), h.prevNormal, p.kn, p.ks);
        }
      }
      n = 0;
    };
    for (std::size_t c = first; c < last; ++c) {
      slipOf[c - first] = 0.0;
      rollOf[c - first] = 0.0;
      contact::ContactHistory& h = list.history[c];
      const std::uint32_t a = list.a[c], b = list.b[c];
      const Vec3 branch = pairBranch<Periodic>(ctx, list, c);
      const double dist2 = branch.squaredNorm();
      const double reach = P.radius[a] + P.radius[b];
      if (dist2 >= reach * reach) {
        releaseApart<Kernel>(ctx, list, c, writeAll, slipOf[c - first], rollOf[c - first]);
        continue;
      }
      tile.fresh[n] = h.touching ? 0.0 : 1.0;
      h.touching = true;
      for (int k = 0; k < 3; ++k) {
        tile.branch[k][n] = branch[k];
        tile.va[k][n] = P.velocity[a][k], tile.vb[k][n] = P.velocity[b][k];
        tile.wa[k][n] = P.angularVelocity[a][k], tile.wb[k][n] = P.angularVelocity[b][k];
        tile.shear[k][n] = h.shearForce[k], tile.moment[k][n] = h.moment[k], tile.prevNormal[k][n] = h.prevNormal[k];
      }
      tile.radiusA[n] = P.radius[a], tile.radiusB[n] = P.radius[b];
      tile.muA[n] = P.rollingFriction[a], tile.muB[n] = P.rollingFriction[b];
      slot[n++] = static_cast<std::uint32_t>(c);
      if (n == Tile::kSize) flush();
    }
    if (n > 0) flush();
    double slip = 0.0, roll = 0.0;
    for (std::size_t c = first; c < last; ++c) {
      slip += slipOf[c - first];
      roll += rollOf[c - first];
    }
    sums.at(chunk, kSlip) = slip;
    sums.at(chunk, kRoll) = roll;
    sums.at(chunk, kViscous) = 0.0;
    if constexpr (Periodic) {
      for (int i = 0; i < 9; ++i) sums.at(chunk, kStress0 + i) = stress(i % 3, i / 3);
      for (int i = 0; i < 3; ++i) sums.at(chunk, kStiffness0 + i) = stiffness[i];
      for (int i = 0; i < 3; ++i) sums.at(chunk, kShearStiffness0 + i) = shearStiffness[i];
    }
  }
}

}  // namespace detail

// Evaluates every contact of `list`; call from every thread of an OpenMP parallel region (the loop
// is a work-shared `omp for` without a barrier at its end). `sums` holds kContactSums terms per chunk
// when Periodic, else kSlip, kRoll and kViscous.
template <class Kind, bool Periodic>
void evaluateContacts(ContactList<Kind>& list, const ContactContext& ctx, ChunkedSums& sums, bool writeAll) {
  using Kernel = detail::KindKernel<Kind, Periodic>;
  if constexpr (std::is_same_v<Kind, SphereSphere>) {
    // The same branch on every thread (the model does not change during a step).
    if (kernels::sphereLawVectorised(ctx.model)) return detail::evaluateSphereTiles<Periodic>(list, ctx, sums, writeAll);
  }
  // Chunks are scheduled dynamically: only touching pairs run the contact law.
#pragma omp for schedule(dynamic, 1) nowait
  for (std::size_t chunk = 0; chunk < sums.chunks(); ++chunk) {
    double slip = 0.0, roll = 0.0, viscous = 0.0;
    Mat3 stress = Mat3::Zero();
    Vec3 stiffness = Vec3::Zero(), shearStiffness = Vec3::Zero();
    for (std::size_t c = sums.begin(chunk); c < sums.end(chunk); ++c) {
      typename Kind::History& h = list.history[c];
      geometry::ContactGeometry g;
      Vec3 branch;
      if (!Kernel::evaluate(ctx, list, c, h, g, branch)) {
        detail::releaseApart<Kernel>(ctx, list, c, writeAll, slip, roll);
        continue;
      }
      if (!h.touching) {
        h.touching = true;
        h.prevNormal = g.normal;
      }
      contact::PairParams p = Kernel::params(ctx, list, c);
      contact::ContactResponse res;
      if (p.hertz > 0.0) {
        contact::SphereContactModel::resolve(p, g.overlap);
        contact::ContactKinematics k = Kernel::kinematics(ctx, list, c, g, branch);
        k.prevNormal = h.prevNormal;
        double dashpot;
        res = contact::applyHertzMindlin(p, k, h, dashpot);
        viscous += dashpot;
      } else if (p.tanFriction <= 0.0 && p.kr <= 0.0) {
        // Frictionless and without a moment spring (a smooth wall, a growth stage at mu = 0): the
        // normal spring alone, without the kinematics the tangential and moment slots need.
        res = contact::applyNormalLaw(p, g.normal, g.overlap, h);
      } else {
        contact::ContactKinematics k = Kernel::kinematics(ctx, list, c, g, branch);
        k.prevNormal = h.prevNormal;
        res = contact::applyLaw(p, k, h);
      }
      Kernel::store(list, c, g, res);
      slip += res.slipDissipation;
      roll += res.rollDissipation;
      if constexpr (Periodic && !Kind::kPlane)
        detail::addCellTerms(stress, stiffness, shearStiffness, res.force, branch, g.normal, p.kn, p.ks);
    }
    sums.at(chunk, kSlip) = slip;
    sums.at(chunk, kRoll) = roll;
    sums.at(chunk, kViscous) = viscous;
    if constexpr (Periodic) {
      for (int i = 0; i < 9; ++i) sums.at(chunk, kStress0 + i) = stress(i % 3, i / 3);
      for (int i = 0; i < 3; ++i) sums.at(chunk, kStiffness0 + i) = stiffness[i];
      for (int i = 0; i < 3; ++i) sums.at(chunk, kShearStiffness0 + i) = shearStiffness[i];
    }
  }
}

}  // namespace grainlab
