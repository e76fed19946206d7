#pragma once
// The list files a config names, read and checked when the config is read (io/config.cpp), so that
// the laboratory gets their contents and never opens a file: the grading list (sample.grading.file),
// the sphericity table (contact.sphericity.file) and the stress path (test.path.file). Each is read
// within io::kMaxListFileBytes and refused with an InputError naming the key, the file and the line.
#include <string>
#include <vector>

#include "lab/grading.hpp"
#include "lab/sphericity.hpp"
#include "lab/stress_path.hpp"

namespace grainlab::io {

// The diameters [m] of a list file (sample.grading type "list"): one per line, the first field of a
// CSV row; blank lines and '#' comments skipped; one optional header, the first other line, only if
// it holds no digit at all ("diameter_m"; "0.003abc" is a bad diameter). Every value must be a
// diameter in [lab::kMinDiameter, lab::kMaxDiameter].
std::vector<double> readDiameterList(const std::string& path);

// A CSV with a header: one column `sphericity` (a list), or columns `bin_low,bin_high,frequency`
// (a histogram); `key` names the config key in messages.
lab::SphericityDistribution readSphericityFile(const std::string& path, const std::string& key);

// A stress path table (docs/laboratory.md, stress paths): columns s, xx, xx_control, yy, yy_control,
// zz, zz_control; `key` names the config key in messages.
std::vector<lab::PathPoint> readStressPathFile(const std::string& path, const std::string& key);

}  // namespace grainlab::io
