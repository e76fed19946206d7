#pragma once
// Macro-parameters of a drained triaxial test from its recorded curves (docs/laboratory.md §4).
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
//  - critical (steady) state: over trailing windows of csWindow of the test's strain (eps1, or gamma
//    in simple shear), the least-squares slopes of the stress ratio eta = q/p (tau/sigma_n), of
//    eps_v and of e against the strain must all be small: |d eta/d eps| <= csMaxStressRatioRate,
//    |d eps_v/d eps| <= csMaxVolumetricRate, |d e/d eps| <= csMaxVoidRatioRate, in every window
//    that ends from some strain eps* to the end of the test (at least csMinRecords records each).
//    eps* is where the critical state was reached; its values are the means from eps* to the end
//    (those of the last window when fewer than csMinRecords records follow eps*). A test that does not meet it has no critical state, only its end values (the means
//    over the last window, and the slopes there).
struct MacroSettings {
  double residualFraction = 0.2;
  double dilatancyHalfWindow = 0.005;
  double elasticWindow = 0.001;
  double csWindow = 0.05;
  double csMaxStressRatioRate = 0.5;
  double csMaxVolumetricRate = 0.02;
  double csMaxVoidRatioRate = 0.05;
  std::size_t csMinRecords = 5;
};

// The criterion's window for test.cs_window = "auto": a quarter of the test's final strain (eps1, or
// gamma in simple shear), at least 0.05. A 20 % triaxial test gets 0.05; a simple-shear test to
// gamma = 2 gets 0.5, long enough that the stress-ratio fluctuations of a 1000-2000 grain sample
// (about +-0.1 in tau/sigma_n over gamma ~ 0.05-0.1) do not dominate the slopes.
double autoCsWindow(double finalStrain);

// The steady-state check of MacroSettings over the curves' strain `eps`: means and slopes of the
// last window, and whether (and from where) every trailing window meets the thresholds.
struct SteadyState {
  bool evaluated = false;          // the test reached at least one window of csMinRecords records
  bool reached = false;
  double reachedAt = 0.0;          // eps* (end of the first window of the steady run to the end)
  double stressRatio = 0.0, voidRatio = 0.0, meanStress = 0.0;  // means from eps* to the end
  // The last window: its means and the slopes of eta, eps_v and e against the strain.
  double endStressRatio = 0.0, endVoidRatio = 0.0, endMeanStress = 0.0;
  double endStressRatioRate = 0.0, endVolumetricRate = 0.0, endVoidRatioRate = 0.0;
};
SteadyState steadyState(const std::vector<double>& eps, const std::vector<double>& stressRatio,
                        const std::vector<double>& epsV, const std::vector<double>& voidRatio,
                        const std::vector<double>& meanStress, const MacroSettings& s = {});

struct MacroParameters {
  double phiPeakDeg = 0.0;
  double eps1AtPeak = 0.0;
  double qPeak = 0.0;
  double phiResDeg = 0.0;
  double residualFrom = 0.0;  // eps1 where the residual window starts
  std::optional<double> psiMaxDeg;  // null when no window could be evaluated
  double eps1AtPsiMax = 0.0;
  std::optional<double> e50;        // [Pa]; null when not measurable (lab/moduli.hpp)
  // Means over the residual window (phi_res's): q/p (simple shear: tau/sigma_n) and e. Not a
  // critical state unless `steady` says one was reached.
  double residualStressRatio = 0.0;
  double residualVoidRatio = 0.0;
  // tan psi = D = -d eps_v/d eps1 (simple shear: -d eps_v/d gamma), the other convention's largest
  // angle over the same windows; psiMaxDeg is sin psi = D/(2 + D) for the axial tests.
  std::optional<double> psiMaxTanDeg;
  SteadyState steady;         // the critical-state criterion of MacroSettings
  double shearModulus = 0.0;  // simple shear: least-squares slope of tau on gamma in the elastic window [Pa]
};

// phi = asin((sigma1 - sigma3)/(sigma1 + sigma3)) [deg]
double mobilisedFrictionDeg(double sigma1, double sigma3);
// psi = asin(-r/(2 - r)) with r = d(eps_v)/d(eps1) [deg]; positive in dilation. With D = -r the
// dilatancy rate: sin psi = D/(2 + D), the triaxial definition (principal strain rates of a
// cylinder: d eps_v = d eps1 + 2 d eps3).
double dilatancyAngleDeg(double rate);
// The plane-strain / direct-shear definition tan psi = D = -r [deg].
double dilatancyAngleTanDeg(double rate);
// Least-squares slope of y on x over indices [begin, end).
double slope(const std::vector<double>& x, const std::vector<double>& y, std::size_t begin, std::size_t end);

// Stress–dilatancy data of a test (Rowe's plot): at every record with a centred window of
// +-halfWindow strain holding at least 3 records, the dilatancy rate D = -d eps_v/d eps (least
// squares over the window; eps = eps1, or gamma in simple shear), the stress ratio eta = q/p (simple
// shear: tau/sigma_n) and, for the axial tests, the principal stress ratio R = sigma1/sigma3.
struct StressDilatancy {
  std::vector<double> strain, dilatancy, stressRatio, principalRatio;  // principalRatio empty in simple shear
};
StressDilatancy stressDilatancy(const TriaxialCurves& c, bool simpleShear, double halfWindow = 0.005);

MacroParameters computeMacro(const TriaxialCurves& c, const MacroSettings& s = {});
// Simple shear at constant normal stress: `eps1` holds gamma, `sigma1` the normal stress, and
// `shearStress` tau. phi = atan(tau / sigma_n); psi = atan(-d eps_v / d gamma) (positive in
// dilation); G the slope of tau on gamma over gamma <= elasticWindow; windows as for computeMacro.
// E50 stays null (not measured by this test).
MacroParameters computeSimpleShearMacro(const TriaxialCurves& c, const MacroSettings& s = {});

}  // namespace grainlab::lab
