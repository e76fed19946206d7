// Micro-benchmark of the ellipsoid kernels against the sphere kernels (not a test: timings only).
// Each kernel runs over a batch of 4096 precomputed pair configurations; a batch is timed many
// times and the fastest repetition is reported (the least disturbed by other jobs on a shared
// machine), in ns per evaluation. Warm-started ellipsoid solves alternate between two states of
// every pair one DEM step apart (relative motion 1e-6 of the size, rotation 1e-6 rad), each
// starting from the lambda the other returned, as the engine's contact history would.
//
//     build/ellipsoid_kernel_bench [--batches N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include "core/rigid_rotation.hpp"
#include "geometry/ellipsoid_contacts.hpp"
#include "geometry/ellipsoid_shape.hpp"
#include "geometry/sphere_contacts.hpp"

using namespace grainlab;
using namespace grainlab::geometry;

namespace {

constexpr int kPairs = 4096;
volatile double gSink = 0.0;  // results feed it so that no kernel call is optimised away

Quat randomRotation(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double u1 = u(rng), u2 = 2.0 * kPi * u(rng), u3 = 2.0 * kPi * u(rng);
  const double s1 = std::sqrt(1.0 - u1), s2 = std::sqrt(u1);
  return Quat(s2 * std::cos(u3), s1 * std::sin(u2), s1 * std::cos(u2), s2 * std::sin(u3));
}
Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

// Fastest of `reps` timings of fn() over the batch, ns per item.
template <class Fn>
double timeBatch(Fn&& fn, int reps) {
  double best = 1e300;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::nano>(t1 - t0).count() / kPairs);
  }
  return best;
}

struct PairState {
  Vec3 r;          // x_B - x_A
  Quat qa, qb;     // orientations
  Sym3 xa, xb;     // shape matrices
};

}  // namespace

int main(int argc, char** argv) {
  int reps = 400;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--batches") == 0) reps = std::atoi(argv[i + 1]);
  }
  if (reps < 1) {
    std::fprintf(stderr, "--batches: %d is not a positive number of timed batches\n", reps);
    return 2;
  }
  std::mt19937_64 rng(2024);
  // [O]'s prolate spheroids (elr = 0.7, equivalent radius 1 mm) and triaxial grains 1 : 0.75 : 0.5.
  const Vec3 spheroid = semiAxesFromOuadfel(1e-3, 0.7, 1.0);
  const Vec3 triaxial = Vec3(1.0, 0.75, 0.5) * 1.3e-3;
  std::uniform_real_distribution<double> logEps(-4.0, -2.0), radius(0.8e-3, 1.2e-3);
  std::vector<PairState> now(kPairs), next(kPairs), apart(kPairs);
  std::vector<Vec3> axesA(kPairs), axesB(kPairs);
  std::vector<double> sphereA(kPairs), sphereB(kPairs);
  std::vector<Vec3> sphereBranch(kPairs);
  std::vector<double> lambda(kPairs, 0.0), lambdaSE(kPairs, 0.0), lambdaGen(kPairs, 0.0);
  for (int i = 0; i < kPairs; ++i) {
    axesA[i] = i % 2 ? spheroid : triaxial;
    axesB[i] = i % 3 ? spheroid : triaxial;
    PairState& s = now[i];
    s.qa = randomRotation(rng);
    s.qb = randomRotation(rng);
    s.xa = shapeMatrix(axesA[i], s.qa);
    s.xb = shapeMatrix(axesB[i], s.qb);
    const Vec3 u = randomUnit(rng);
    const double touch = 1.0 / std::sqrt(contactFunction(u, s.xa, s.xb).contactFunction);
    s.r = u * touch * (1.0 - std::pow(10.0, logEps(rng)));
    PairState& t = next[i];
    t = s;
    t.r += 1e-6 * touch * randomUnit(rng);
    t.qb = rotation::rotationQuaternion(1e-6 * randomUnit(rng)) * s.qb;
    t.xb = shapeMatrix(axesB[i], t.qb);
    apart[i] = s;
    apart[i].r = u * touch * 1.05;  // within the bounding spheres' reach, not touching
    sphereA[i] = radius(rng);
    sphereB[i] = radius(rng);
    sphereBranch[i] = randomUnit(rng) * (sphereA[i] + sphereB[i]) * (1.0 - std::pow(10.0, logEps(rng)));
  }
  for (int i = 0; i < kPairs; ++i) lambda[i] = ellipsoidEllipsoid(now[i].r, now[i].xa, now[i].xb, 0.0, 0.0).lambda;

  const double tSphere = timeBatch([&] {
    double acc = 0;
    for (int i = 0; i < kPairs; ++i) {
      const Vec3& b = sphereBranch[i];
      const double d2 = b.squaredNorm();
      if (d2 >= (sphereA[i] + sphereB[i]) * (sphereA[i] + sphereB[i])) continue;
      const ContactGeometry g = sphereSphere(b, d2, sphereA[i], sphereB[i]);
      acc += g.overlap + g.branchA.x() + g.normal.y();
    }
    gSink = gSink + acc;
  }, reps);

  int flip = 0;
  auto warm = [&](bool withShapes) {
    return timeBatch([&] {
      const std::vector<PairState>& states = (++flip & 1) ? next : now;
      double acc = 0;
      for (int i = 0; i < kPairs; ++i) {
        const PairState& s = states[i];
        EllipsoidContact c;
        if (withShapes) {
          c = ellipsoidEllipsoid(s.r, shapeMatrix(axesA[i], s.qa), shapeMatrix(axesB[i], s.qb), lambda[i], 0.0);
        } else {
          c = ellipsoidEllipsoid(s.r, s.xa, s.xb, lambda[i], 0.0);
        }
        lambda[i] = c.lambda;
        acc += c.geometry.overlap + c.geometry.branchA.x() + c.geometry.normal.y();
      }
      gSink = gSink + acc;
    }, reps);
  };
  const double tWarm = warm(false);
  const double tWarmShapes = warm(true);
  long evaluations = 0;
  for (int i = 0; i < kPairs; ++i) {
    const PairState& s = (i & 1) ? next[i] : now[i];
    const EllipsoidContact c = ellipsoidEllipsoid(s.r, s.xa, s.xb, lambda[i], 0.0);
    evaluations += c.iterations;
    lambda[i] = c.lambda;
  }
  const double tCold = timeBatch([&] {
    double acc = 0;
    for (int i = 0; i < kPairs; ++i) {
      const EllipsoidContact c = ellipsoidEllipsoid(now[i].r, now[i].xa, now[i].xb, 0.0, 0.0);
      acc += c.geometry.overlap + c.geometry.branchA.x();
    }
    gSink = gSink + acc;
  }, reps);
  const double tApart = timeBatch([&] {
    double acc = 0;
    for (int i = 0; i < kPairs; ++i) {
      const EllipsoidContact c = ellipsoidEllipsoid(apart[i].r, apart[i].xa, apart[i].xb, lambda[i], 0.0);
      acc += c.contactFunction;
    }
    gSink = gSink + acc;
  }, reps);
  const double tFilter = timeBatch([&] {
    int n = 0;
    for (int i = 0; i < kPairs; ++i) n += separatedAlongCentreLine(apart[i].r, apart[i].xa, apart[i].xb);
    gSink = gSink + n;
  }, reps);

  // Sphere (radius = B's equivalent radius) against ellipsoid B: general solve with X_A = r^2 I
  // vs the specialised one in B's frame.
  std::vector<Vec3> seBranch(kPairs);
  std::vector<double> seRadius(kPairs);
  for (int i = 0; i < kPairs; ++i) {
    seRadius[i] = equivalentRadius(axesB[i]);
    const Sym3 xs = Sym3::identity(seRadius[i] * seRadius[i]);
    const Vec3 u = randomUnit(rng);
    seBranch[i] = u * (1.0 / std::sqrt(contactFunction(u, xs, now[i].xb).contactFunction)) * (1 - 1e-3);
    lambdaSE[i] = sphereEllipsoid(seBranch[i], seRadius[i], axesB[i], now[i].qb, 0.0, 0.0).lambda;
    lambdaGen[i] = lambdaSE[i];
  }
  const double tSeGeneral = timeBatch([&] {
    double acc = 0;
    for (int i = 0; i < kPairs; ++i) {
      const EllipsoidContact c = ellipsoidEllipsoid(seBranch[i], Sym3::identity(seRadius[i] * seRadius[i]), now[i].xb,
                                                    lambdaGen[i], 0.0);
      lambdaGen[i] = c.lambda;
      acc += c.geometry.overlap + c.geometry.branchA.x();
    }
    gSink = gSink + acc;
  }, reps);
  const double tSeSpecial = timeBatch([&] {
    double acc = 0;
    for (int i = 0; i < kPairs; ++i) {
      const EllipsoidContact c = sphereEllipsoid(seBranch[i], seRadius[i], axesB[i], now[i].qb, lambdaSE[i], 0.0);
      lambdaSE[i] = c.lambda;
      acc += c.geometry.overlap + c.geometry.branchA.x();
    }
    gSink = gSink + acc;
  }, reps);

  const Vec3 m = Vec3::UnitZ();
  const double tPlane = timeBatch([&] {
    double acc = 0;
    for (int i = 0; i < kPairs; ++i) {
      const EllipsoidPlaneContact c = ellipsoidPlane(now[i].r, now[i].xa, Vec3::Zero(), m);
      acc += c.geometry.overlap + c.geometry.branchB.x();
    }
    gSink = gSink + acc;
  }, reps);
  const double tSpherePlane = timeBatch([&] {
    double acc = 0;
    for (int i = 0; i < kPairs; ++i) {
      const ContactGeometry g = spherePlane(now[i].r, sphereA[i], Vec3::Zero(), m);
      acc += g.overlap + g.branchB.x();
    }
    gSink = gSink + acc;
  }, reps);
  const double tShape = timeBatch([&] {
    double acc = 0;
    for (int i = 0; i < kPairs; ++i) acc += shapeMatrix(axesA[i], now[i].qa).xy;
    gSink = gSink + acc;
  }, reps);

  // Rotation updates with |w| dt ~ 1e-4 and a torque kick of 1 % of L per step.
  std::vector<Quat> q(kPairs);
  std::vector<Vec3> w(kPairs), torque(kPairs), inertia(kPairs);
  for (int i = 0; i < kPairs; ++i) {
    q[i] = now[i].qa;
    w[i] = randomUnit(rng) * 1e-4;
    inertia[i] = ellipsoidPrincipalInertia(axesA[i], 1.0);
    torque[i] = 0.01 * inertia[i].x() * 1e-4 * randomUnit(rng);
  }
  long passes = 0;
  const double tRotation = timeBatch([&] {
    for (int i = 0; i < kPairs; ++i) {
      const rotation::LeapfrogRotation s =
          rotation::leapfrogRotation(q[i], w[i], inertia[i], torque[i], 1.0, 1.0, rotation::Damping::Local, 0.3);
      q[i] = s.step.orientation;
      w[i] = s.step.angularVelocity;
      passes += s.step.iterations;
    }
  }, reps);
  const double passesPerStep = double(passes) / (double(reps) * kPairs);
  // The same with L stored per particle (no rebuild, one-pass tolerance).
  std::vector<Vec3> momentum(kPairs);
  for (int i = 0; i < kPairs; ++i) momentum[i] = rotation::midStepAngularMomentum(q[i], w[i], inertia[i], 1.0);
  long storedPasses = 0;
  const double tRotationStored = timeBatch([&] {
    for (int i = 0; i < kPairs; ++i) {
      const rotation::LeapfrogRotation s = rotation::leapfrogRotationWithMomentum(
          q[i], w[i], momentum[i], inertia[i], torque[i], 1.0, rotation::Damping::Local, 0.3);
      q[i] = s.step.orientation;
      w[i] = s.step.angularVelocity;
      momentum[i] = s.angularMomentum;
      storedPasses += s.step.iterations;
    }
  }, reps);
  const double storedPassesPerStep = double(storedPasses) / (double(reps) * kPairs);
  // The engine's sphere update (simulation.cpp): damped kick, first-order quaternion, series
  // renormalisation.
  const double tSphereRotation = timeBatch([&] {
    for (int i = 0; i < kPairs; ++i) {
      const Vec3 td = rotation::localDamping(torque[i], w[i], 0.3);
      w[i] += (torque[i] + td) * (1.0 / inertia[i].x());
      const Vec3 half = 0.5 * w[i];
      q[i] = rotation::renormalised(Quat(1.0, half.x(), half.y(), half.z()) * q[i]);
    }
  }, reps);

  std::printf("ellipsoid kernel benchmark: %d pairs per batch, fastest of %d batches, ns per evaluation\n", kPairs, reps);
  std::printf("  sphere-sphere (sphereSphere + distance test)          %7.1f\n", tSphere);
  std::printf("  ellipsoid-ellipsoid, warm, shape matrices cached      %7.1f  (%.2f evaluations of S per solve)\n",
              tWarm, double(evaluations) / kPairs);
  std::printf("  ellipsoid-ellipsoid, warm, shape matrices per contact %7.1f\n", tWarmShapes);
  std::printf("  ellipsoid-ellipsoid, cold start                       %7.1f\n", tCold);
  std::printf("  ellipsoid-ellipsoid, apart candidate (early exit)     %7.1f\n", tApart);
  std::printf("  separatedAlongCentreLine filter                       %7.1f\n", tFilter);
  std::printf("  sphere-ellipsoid, general solve (X_A = r^2 I)         %7.1f\n", tSeGeneral);
  std::printf("  sphere-ellipsoid, specialised (ellipsoid frame)       %7.1f\n", tSeSpecial);
  std::printf("  ellipsoid-plane                                       %7.1f  (sphere-plane %.1f)\n", tPlane, tSpherePlane);
  std::printf("  shape matrix (per particle and step)                  %7.1f\n", tShape);
  std::printf("  rotation step, ellipsoid, L rebuilt (%.2f passes)     %7.1f  (engine's sphere update %.1f)\n",
              passesPerStep, tRotation, tSphereRotation);
  std::printf("  rotation step, ellipsoid, L stored (%.2f passes)      %7.1f\n", storedPassesPerStep, tRotationStored);
  std::printf("  ratio ellipsoid/sphere contact geometry (warm, cached) %6.1fx\n", tWarm / tSphere);
  // Per particle and step at the lattice scene's density (3 touching pairs per particle): the
  // contact geometry of those pairs, ~2.5 apart candidates within the bounding spheres (1.8
  // candidates per touching pair in the brute-force test of random sets), 10 % of which pass
  // the centre-line filter to an early-exit solve, one shape matrix and the rotation step; the
  // contact law and the rest of the step cost what they cost for spheres.
  const double contacts = 3.0 * (tWarm - tSphere) + 2.5 * (tFilter + 0.1 * tApart) + tShape;
  std::printf("extra cost per particle-step over spheres (3 touching pairs, 2.5 apart candidates):\n"
              "  %.0f ns with L rebuilt, %.0f ns with L stored\n",
              contacts + tRotation - tSphereRotation, contacts + tRotationStored - tSphereRotation);
  return 0;
}
