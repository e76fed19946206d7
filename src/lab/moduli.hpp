#pragma once
// Moduli as a laboratory reports them (docs/moduli.md): the small-strain E0 and nu0 of a dedicated
// probe after consolidation, the secant E50 to half the peak deviator, and the unload–reload
// modulus Eur of each loop. Pure functions of measured increments or curves, so that they can be
// tested on synthetic data with known answers; the probe itself is Laboratory::probeModuli().
#include <optional>
#include <string>
#include <vector>

namespace grainlab::lab {

struct ElasticConstants {
  double young = 0.0;    // [Pa]
  double poisson = 0.0;  // [-]
};

// E and nu of an isotropic linear-elastic sample from one axisymmetric increment (compression
// positive): d_eps1 = (d_s1 - 2 nu d_s3)/E and d_eps3 = (d_s3 - nu (d_s1 + d_s3))/E, solved for
// 1/E and nu/E. With d_s3 = 0 (the lateral stress held exactly) it is E = d_s1/d_eps1 and
// nu = -d_eps3/d_eps1; the general form removes what the lateral servo leaves of d_s3. Null when
// the system is singular, E comes out non-positive or nu outside (-1, 1/2) (not an isotropic elastic
// solid: the sample rearranged).
std::optional<ElasticConstants> elasticFromIncrement(double dSigma1, double dSigma3, double dEps1, double dEps3);

// What the probe measured, for the summary.
struct ModulusProbe {
  double strain = 0.0;  // imposed axial strain increment (test.probe_strain)
  double dSigma1 = 0.0, dSigma3 = 0.0, dEps1 = 0.0, dEps3 = 0.0;  // measured increments
  long steps = 0;
  bool settled = false;  // both states met the probe's equilibrium tolerances
  std::optional<ElasticConstants> elastic;  // null when not measured
  std::string method;
};

// Secant modulus from the first record to the point where q first reaches q_peak/2 (linear
// interpolation between records), as laboratory reports give E50. Null when q never rises above its
// starting value or no record reaches q_peak/2 after the first.
std::optional<double> secantE50(const std::vector<double>& eps1, const std::vector<double>& q);

// One unload–reload loop of a triaxial test. `phase` per record: 0 monotonic loading, 1 unloading,
// 2 reloading (the first record of a phase is taken at the reversal, at the turning point and, for
// the 0 after a reload, where the reload regains the reversal strain).
struct UnloadReloadLoop {
  double eps1Reversal = 0.0, qReversal = 0.0;  // where the unload began
  double qLoaded = 0.0;                         // q when the platens stopped (before a rest)
  // test.loop_rest: (qLoaded - qReversal)/qLoaded, the deviator relaxed at constant strain before
  // the unload; null without a rest.
  std::optional<double> restRelaxation;
  double eps1Turn = 0.0, qTurn = 0.0;          // where the reload began
  double eps1End = 0.0, qEnd = 0.0;            // where the reload regained the reversal strain
  // Eur: secant of the reload branch, (qEnd - qTurn)/(eps1End - eps1Turn); null when the reload
  // did not move the platens (eps1End <= eps1Turn) or the loop is incomplete.
  std::optional<double> eur;
};
std::vector<UnloadReloadLoop> unloadReloadLoops(const std::vector<double>& eps1, const std::vector<double>& q,
                                                 const std::vector<int>& phase);

}  // namespace grainlab::lab
