// A bar's displacement over time: what a photocell's calibration turns a
// trace's volts into (calibration/displacement.h) and what the rebounds are
// read from (rebounds/rebound_extraction.h).
#pragma once

#include <vector>

namespace impactlab {

struct DisplacementHistory {
  std::vector<double> time_s;        // s since release, increasing
  std::vector<double> displacement;  // length units
  std::vector<double> sigma;         // one-sigma per sample (length); empty when unknown
};

}  // namespace impactlab
