#pragma once
// Particle size distributions (docs/laboratory.md §1): a sieve curve (percent passing by mass), a range
// uniform by number, or a list of diameters.
#include <string>
#include <vector>

#include "lab/random.hpp"
#include "lab/run_config.hpp"

namespace grainlab::lab {

// Draws n diameters [m]. For a sieve curve the mass fraction in each interval is uniform in d
// (piecewise-linear passing curve), so the number density there is proportional to d^-3; it is
// sampled exactly by inverting its cumulative distribution.
std::vector<double> sampleDiameters(const GradingConfig& grading, int n, Rng& rng);

// (A list grading's diameters are read with the config: io::readDiameterList, io/list_files.hpp.)

// Characteristic diameters of a set of spheres, by mass (as a sieve analysis would give).
struct GradingStats {
  double d10, d30, d50, d60;  // [m]
  double cu;                  // coefficient of uniformity d60/d10
  double cc;                  // coefficient of curvature d30^2/(d10 d60)
  double dMin, dMax;
};
GradingStats gradingStats(std::vector<double> diameters);

// Diameter at a given percent passing by mass.
double percentPassingDiameter(const std::vector<double>& sortedDiameters, double percent);

}  // namespace grainlab::lab
