#pragma once
// Macro-parameters of a drained triaxial test from its recorded curves (PHYSICS.md §7.3).
// Pure functions of the curves, so they can be tested on synthetic data with known answers.
#include <optional>
#include <vector>

namespace grainlab::lab {

struct TriaxialCurves {
  std::vector<double> eps1;    // axial strain [-], compression positive
  std::vector<double> epsV;    // volumetric strain [-], contraction positive
  std::vector<double> sigma1;  // [Pa]
  std::vector<double> sigma3;  // mean lateral stress [Pa]
  std::vector<double> voidRatio;
  std::vector<double> shearStress;  // simple shear: tau [Pa] (sigma1 is then the normal stress)
};

// Windows used, stated here and in the README:
//  - residual / critical state: the last 20 % of the final axial strain, eps1 >= 0.8 eps1_final;
//  - dilatancy rate: local least-squares slope r = d(eps_v)/d(eps1) over a centred window of
//    +-dilatancyHalfWindow axial strain (default 0.005); windows with r >= 1 (sudden collapse,
//    where sin psi = -r/(2 - r) leaves [-1, 1]) are skipped;
//  - E50: the secant to half the peak q (lab/moduli.hpp); the small-strain E0 and nu0 come from
//    a dedicated probe (Laboratory::probeModuli), not from these curves;
//  - simple shear's G: least-squares slope of tau on gamma over gamma <= elasticWindow (0.1 %), at
//    least the first 3 records.
struct MacroSettings {
  double residualFraction = 0.2;
  double dilatancyHalfWindow = 0.005;
  double elasticWindow = 0.001;
};

struct MacroParameters {
  double phiPeakDeg = 0.0;
  double eps1AtPeak = 0.0;
  double qPeak = 0.0;
  double phiResDeg = 0.0;
  double residualFrom = 0.0;  // eps1 where the residual window starts
  std::optional<double> psiMaxDeg;  // null when no window could be evaluated
  double eps1AtPsiMax = 0.0;
  std::optional<double> e50;        // [Pa]; null when not measurable (lab/moduli.hpp)
  double csStressRatio = 0.0;  // q/p over the residual window (simple shear: tau/sigma_n)
  double csVoidRatio = 0.0;
  double shearModulus = 0.0;  // simple shear: least-squares slope of tau on gamma in the elastic window [Pa]
};

// phi = asin((sigma1 - sigma3)/(sigma1 + sigma3)) [deg]
double mobilisedFrictionDeg(double sigma1, double sigma3);
// psi = asin(-r/(2 - r)) with r = d(eps_v)/d(eps1) [deg]; positive in dilation.
double dilatancyAngleDeg(double rate);
// Least-squares slope of y on x over indices [begin, end).
double slope(const std::vector<double>& x, const std::vector<double>& y, std::size_t begin, std::size_t end);

MacroParameters computeMacro(const TriaxialCurves& c, const MacroSettings& s = {});
// Simple shear at constant normal stress: `eps1` holds gamma, `sigma1` the normal stress, and
// `shearStress` tau. phi = atan(tau / sigma_n); psi = atan(-d eps_v / d gamma) (positive in
// dilation); G the slope of tau on gamma over gamma <= elasticWindow; windows as for computeMacro.
// E50 stays null (not measured by this test).
MacroParameters computeSimpleShearMacro(const TriaxialCurves& c, const MacroSettings& s = {});

}  // namespace grainlab::lab
