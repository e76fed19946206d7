// The stress servo of a wall (src/core/servo_settings.hpp, Simulation::updateWalls) against the
// discrete response its design implies.
//
// Per step the wall moves inward by g u + (g / Ns) sum_{j <= n} u_j, where u = (sigma_t - sigma) A /
// K is the displacement that would cancel the stress error if only the wall's contacts (summed
// normal stiffness K) deformed, g the gain and Ns the integral time in steps. If the wall pushes on
// a linear spring of stiffness K' (a rigid support behind the contacts: K' = K; springs in series
// behind them: K' < K), the error in displacement eps_n = (sigma_t - sigma_n) A / K' obeys, with
// g' = g K'/K,
//   eps_1     = (1 - g' - g'/Ns) eps_0,
//   eps_{n+2} = (2 - g' - g'/Ns) eps_{n+1} - (1 - g') eps_n,
// whose characteristic roots lambda_{1,2} solve lambda^2 - (2 - g' - g'/Ns) lambda + (1 - g') = 0.
// For g = 0.8, Ns = 100: lambda_2 = 0.202 (the proportional part removes most of the error within
// a few steps) and lambda_1 = 0.98997: the integral term overshoots by about 1 % and the overshoot
// decays with a time constant of -1/ln(lambda_1) = 99.2 steps, about Ns.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <vector>

#include "core/servo_settings.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

namespace {

struct PiResponse {
  double lambda1, lambda2, c1, c2;
  PiResponse(double gain, double integralSteps, double eps0) {
    const double b = 2.0 - gain - gain / integralSteps, c = 1.0 - gain;
    const double root = std::sqrt(b * b - 4.0 * c);
    lambda1 = 0.5 * (b + root);
    lambda2 = 0.5 * (b - root);
    const double eps1 = (1.0 - gain - gain / integralSteps) * eps0;
    c1 = (eps1 - lambda2 * eps0) / (lambda1 - lambda2);
    c2 = eps0 - c1;
  }
  double at(long n) const { return c1 * std::pow(lambda1, n) + c2 * std::pow(lambda2, n); }
};

}  // namespace

// A sphere held fixed (infinite mass: the rigid support) under the servo-controlled top wall: the
// only spring is the wall contact, K' = K = 2 Ec R. Every step of the response is the closed form.
TEST(WallServo, SingleSpringFollowsTheDiscretePiResponse) {
  omp_set_num_threads(1);
  const double L = 0.01, R = 1e-3, target = 100e3, dt = 1e-5;
  Simulation sim = scenes::emptyScene(L);
  sim.particles.addSphere(Vec3::Zero(), R, 2600.0);
  sim.particles.setMass(0, 1e300, 1e300);
  const double area = (2 * L) * (2 * L);
  const double kn = 2.0 * 30e9 * R;          // sphere against a wall [docs/physics.md §4.1]
  const double targetOverlap = target * area / kn;  // 6.67e-7 m
  Wall& top = sim.box.upper(2);
  top.position = R - 0.5 * targetOverlap;    // starts at half the target overlap
  top.control = WallControl::Stress;
  top.targetStress = target;
  sim.initialise();
  sim.dt = dt;
  ServoSettings& servo = sim.servo;
  servo.gain = 0.8;                          // the shipped defaults, set here so that the hand
  servo.integralSteps = 100.0;               // numbers below stay valid if the defaults change
  // The servo's speeds stay far below its cap here (0.8 x 3.3e-7 m per 1e-5 s = 0.027 m/s), so the
  // response is the linear one.
  const PiResponse expected(servo.gain, servo.integralSteps, 0.5 * targetOverlap);
  EXPECT_NEAR(expected.lambda1, 0.98997, 1e-5);
  EXPECT_NEAR(-1.0 / std::log(expected.lambda1), 99.2, 0.05);
  for (long n = 0; n <= 2000; ++n) {
    sim.step();  // measures sigma_n at the wall position of step n, then moves the wall
    const double eps = (target - top.normalForce / area) * area / kn;
    ASSERT_NEAR(eps, expected.at(n), 1e-6 * targetOverlap) << "step " << n;
  }
  EXPECT_NEAR(top.normalForce / area / target, 1.0, 1e-7);
  // The other walls are fixed and carry nothing.
  EXPECT_EQ(sim.box.lower(2).position, -L);
  EXPECT_EQ(sim.box.lower(2).normalForce, 0.0);
}

// A wall without contacts approaches at the speed cap.
TEST(WallServo, WallWithoutContactsApproachesAtTheCap) {
  omp_set_num_threads(1);
  Simulation sim = scenes::emptyScene(0.01);
  sim.particles.addSphere(Vec3::Zero(), 1e-3, 2600.0);
  Wall& top = sim.box.upper(2);
  top.control = WallControl::Stress;
  top.targetStress = 100e3;
  sim.initialise();
  sim.dt = 1e-5;
  for (int n = 0; n < 10; ++n) sim.step();
  EXPECT_NEAR(top.position, 0.01 - 10 * sim.servo.maxSpeed * 1e-5, 1e-15);
  EXPECT_EQ(top.velocity, -sim.servo.maxSpeed);
}

// A real sphere between the fixed bottom wall and the servo-controlled top wall: two equal wall
// springs in series behind the top wall's contact, K' = K/2, so g' = g/2. The sphere is damped and
// its own period (about 9 steps at half the critical step) is short beside the servo's integral
// time, so the slow mode follows the quasi-static law: the error decays as lambda_1(g/2, Ns)^n.
TEST(WallServo, RealSphereReachesTargetWithTheIntegralTimeConstant) {
  omp_set_num_threads(1);
  const double L = 0.01, R = 1e-3, target = 100e3;
  Simulation sim = scenes::emptyScene(L);
  sim.localDamping = 0.3;
  sim.particles.addSphere(Vec3::Zero(), R, 2600.0);
  const double area = (2 * L) * (2 * L);
  const double kn = 2.0 * 30e9 * R;
  const double targetOverlap = target * area / kn;  // of each wall contact at the target
  // Both contacts at half their final overlap: the sphere starts in equilibrium at sigma_t / 2.
  sim.box.lower(2).position = -R + 0.5 * targetOverlap;
  Wall& top = sim.box.upper(2);
  top.position = R - 0.5 * targetOverlap;
  top.control = WallControl::Stress;
  top.targetStress = target;
  sim.initialise();
  sim.dt = 0.5 * sim.criticalTimeStep();
  sim.servo.gain = 0.8;
  sim.servo.integralSteps = 100.0;
  std::vector<double> error;
  for (long n = 0; n < 3000; ++n) {
    sim.step();
    error.push_back(target - top.normalForce / area);
  }
  EXPECT_LT(std::abs(error.back()) / target, 1e-6);
  // Least-squares slope of ln|error| over steps 300..1200, where the fast modes (the servo's
  // lambda_2 = 0.61 and the damped sphere) have died out.
  double sn = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (long n = 300; n <= 1200; ++n) {
    ASSERT_LT(error[n], 0.0) << "the slow mode is an overshoot, step " << n;
    const double y = std::log(-error[n]);
    sn += 1;
    sx += n;
    sy += y;
    sxx += double(n) * n;
    sxy += n * y;
  }
  const double slope = (sn * sxy - sx * sy) / (sn * sxx - sx * sx);
  const PiResponse expected(0.5 * sim.servo.gain, sim.servo.integralSteps, 1.0);
  EXPECT_NEAR(expected.lambda1, 0.98984, 1e-5);
  // Measured: the fit equals lambda_1 to 7 digits; 1e-5 still tells g' = g/2 (0.98984) from a servo
  // that saw the series springs as one (g' = g: 0.98997).
  EXPECT_NEAR(std::exp(slope), expected.lambda1, 1e-5);
}
