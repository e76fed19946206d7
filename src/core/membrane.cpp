#include "core/membrane.hpp"

#include <algorithm>
#include <cmath>

namespace grainlab {

double Membrane::equivalentRadius() const { return height > 0.0 ? std::sqrt(volume / (kPi * height)) : 0.0; }

std::size_t Membrane::binOf(const Vec3& x) const {
  const double dTheta = 2.0 * kPi / around, dz = height / along;
  const int a = std::clamp(static_cast<int>(std::floor((std::atan2(x[1] - axisY, x[0] - axisX) + kPi) / dTheta)), 0,
                           around - 1);
  const int k = std::clamp(static_cast<int>(std::floor((x[2] - bottom) / dz)), 0, along - 1);
  return static_cast<std::size_t>(k) * static_cast<std::size_t>(around) + static_cast<std::size_t>(a);
}

bool Membrane::contains(const Vec3& x) const {
  if (around <= 0 || along <= 0 || !(height > 0.0) || x[2] < bottom || x[2] > bottom + height) return false;
  const double dx = x[0] - axisX, dy = x[1] - axisY;
  const std::size_t b = binOf(x);
  if (b >= binRho.size()) return false;
  double rho = binRho[b];
  if (binGrain[b] < 0) {  // the mean of the filled bins, as measure() takes it
    double sum = 0.0;
    int n = 0;
    for (std::size_t c = 0; c < binRho.size(); ++c)
      if (binGrain[c] >= 0) sum += binRho[c], ++n;
    rho = n > 0 ? sum / n : 0.0;
  }
  return std::hypot(dx, dy) <= rho;
}

void Membrane::measure(const Particles& particles, double zLow, double zHigh) {
  const std::size_t bins = static_cast<std::size_t>(around) * static_cast<std::size_t>(along);
  binRho.assign(bins, 0.0);
  binGrain.assign(bins, -1);
  height = zHigh - zLow;
  bottom = zLow;
  if (around <= 0 || along <= 0 || !(height > 0.0)) {
    volume = area = 0.0;
    filledBins = 0;
    return;
  }
  const double dTheta = 2.0 * kPi / around, dz = height / along;
  const auto& x = particles.position;
  const auto& r = particles.radius;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double dx = x[i][0] - axisX, dy = x[i][1] - axisY;
    const double rho = std::hypot(dx, dy) + r[i];
    const std::size_t b = binOf(x[i]);
    if (rho > binRho[b]) {  // strict: the lowest index wins a tie, whatever the order of equal rho
      binRho[b] = rho;
      binGrain[b] = static_cast<std::int64_t>(i);
    }
  }
  filledBins = 0;
  double sum = 0.0;
  for (std::size_t b = 0; b < bins; ++b)
    if (binGrain[b] >= 0) {
      ++filledBins;
      sum += binRho[b];
    }
  const double mean = filledBins > 0 ? sum / filledBins : 0.0;
  volume = area = 0.0;
  for (std::size_t b = 0; b < bins; ++b) {
    const double rho = binGrain[b] >= 0 ? binRho[b] : mean;
    volume += 0.5 * dTheta * rho * rho * dz;
    area += dTheta * rho * dz;
  }
  // The rigid cylinder presses on its own area; the volume is the envelope's in either mode, so
  // that the void ratio does not jump when the membrane takes over.
  if (rigid) area = 2.0 * kPi * radius * height;
}

void Membrane::servo(double modulus) {
  if (control != MembraneControl::ConstantVolume || !(referenceVolume > 0.0) || !(modulus > 0.0)) return;
  const double strain = (volume - referenceVolume) / referenceVolume;  // > 0: swollen, press harder
  const double k = volumeGain * modulus;
  basePressure = std::max(0.0, basePressure + volumeIntegral * k * strain);
  pressure = std::max(0.0, basePressure + k * strain);
}

void Membrane::applyPressure(const Particles& particles) {
  grain.clear();
  force.clear();
  radialForce = hoopPressure = 0.0;
  if (filledBins == 0) return;
  const double dTheta = 2.0 * kPi / around, dz = height / along;
  double filledArea = 0.0;
  for (std::size_t b = 0; b < binGrain.size(); ++b)
    if (binGrain[b] >= 0) filledArea += dTheta * binRho[b] * dz;
  const double share = area / filledArea;  // the holes' load goes to the filled bins
  // Per grain its bin and weight, per bin the sum of the weights (a second pass, as in measure()).
  const auto& x = particles.position;
  const auto& r = particles.radius;
  std::vector<double> weightSum(binGrain.size(), 0.0);
  struct Loaded {
    std::uint32_t i;
    std::uint32_t bin;
    double w;
  };
  std::vector<Loaded> loaded;
  loaded.reserve(static_cast<std::size_t>(filledBins) * 2);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double dx = x[i][0] - axisX, dy = x[i][1] - axisY;
    const double rho = std::hypot(dx, dy) + r[i];
    const std::size_t b = binOf(x[i]);
    const double depth = binRho[b] - rho;
    const double w = shell > 0.0 ? 1.0 - depth / shell : (binGrain[b] == static_cast<std::int64_t>(i) ? 1.0 : 0.0);
    if (!(w > 0.0) || !(std::hypot(dx, dy) > 0.0)) continue;  // too deep, or on the axis (no radial direction)
    weightSum[b] += w;
    loaded.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(b), w});
  }
  // The sleeve's hoop tension E_m t eps_theta is uniform around a circumference: per row of bins,
  // from the row's mean radius, pressing with tension / radius (tension only: a squeezed sleeve
  // buckles).
  std::vector<double> hoop(static_cast<std::size_t>(along), 0.0);
  if (referenceRadius > 0.0 && stiffness > 0.0)
    for (int k = 0; k < along; ++k) {
      double sum = 0.0;
      int n = 0;
      for (int a = 0; a < around; ++a) {
        const std::size_t b = static_cast<std::size_t>(k) * static_cast<std::size_t>(around) + static_cast<std::size_t>(a);
        if (binGrain[b] >= 0) sum += binRho[b], ++n;
      }
      if (n == 0) continue;
      const double row = sum / n;
      hoop[static_cast<std::size_t>(k)] = stiffness * std::max(0.0, row - referenceRadius) / (referenceRadius * row);
    }
  double hoopLoad = 0.0;
  for (std::size_t b = 0; b < binGrain.size(); ++b) {
    if (binGrain[b] < 0 || !(weightSum[b] > 0.0)) continue;
    const double patch = dTheta * binRho[b] * dz * share;
    const double h = hoop[b / static_cast<std::size_t>(around)];
    radialForce += (pressure + h) * patch;
    hoopLoad += h * patch;
  }
  for (const Loaded& l : loaded) {
    const double rho = binRho[l.bin];
    const double h = hoop[l.bin / static_cast<std::size_t>(around)];
    const double f = (pressure + h) * dTheta * rho * dz * share * l.w / weightSum[l.bin];
    const double dx = x[l.i][0] - axisX, dy = x[l.i][1] - axisY;
    const double rr = std::hypot(dx, dy);
    grain.push_back(l.i);
    force.push_back(Vec3(-f * dx / rr, -f * dy / rr, 0.0));
  }
  hoopPressure = area > 0.0 ? hoopLoad / area : 0.0;
}

void Membrane::servoCylinder(double dt, double gain, double integralSteps, double maxSpeed) {
  // The wall servo (Simulation::controlWalls) for the cylinder: the stress error over the contacts'
  // stiffness is the inward displacement that would cancel it.
  if (control != MembraneControl::Pressure || !(area > 0.0)) return;
  const double error = pressure - radialStress();  // > 0: close in
  double inward = maxSpeed;
  if (contactStiffness > 0.0) {
    const double u = error * area / contactStiffness;
    if (integralSteps > 0.0) servoIntegral = std::clamp(servoIntegral + gain * u / (integralSteps * dt), -maxSpeed, maxSpeed);
    inward = gain * u / dt + servoIntegral;
  } else {
    servoIntegral = 0.0;
  }
  radius -= std::clamp(inward, -maxSpeed, maxSpeed) * dt;
}

}  // namespace grainlab
