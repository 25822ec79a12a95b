// Rebounds that the free pendulum cannot explain (the thesis saw both): one
// that lasts longer or shorter than the pendulum's half period at its own
// amplitude by more than the two uncertainties allow, and one whose maximum
// exceeds its predecessor's (an impact cannot add energy). Either means the
// swing was disturbed (the support wires' vibration, a second contact) or
// the reading is wrong; the rebound is marked, not dropped.
#pragma once

#include <string>
#include <vector>

#include "model/pendulum.h"

namespace impactlab {

struct ReboundAnomaly {
  int rebound = 0;  // session numbering
  std::string why;  // one sentence, with the numbers
};

struct ReboundAnomalyOptions {
  double sigmas = 3.0;  // how far beyond the combined uncertainty counts
};

// The tests FindReboundAnomalies makes of these rebounds: each maximum
// against its predecessor, each duration whose sigma is known against the
// half period.
int CountReboundTests(const std::vector<double>& xmax, const std::vector<double>& duration,
                      const std::vector<double>& duration_sigma);

// The threshold, in sigmas, at which `tests` independent tests with honest
// (normal) errors raise a false alarm with probability `false_alarm_rate`
// in all (two-sided, Bonferroni: each at false_alarm_rate / tests). 1 %
// over 24 tests: 3.53 sigma; over 60: 3.76.
double AnomalyThreshold(double false_alarm_rate, int tests);

// `xmax_sigma` and `duration_sigma` may be empty or hold zeros (unknown):
// then a maximum above its predecessor is marked at any excess, and a
// duration is checked only where its sigma is known. `duration` may be empty
// (typed-in maxima).
std::vector<ReboundAnomaly> FindReboundAnomalies(const Pendulum& pendulum,
                                                 const std::vector<double>& xmax,
                                                 const std::vector<double>& xmax_sigma,
                                                 const std::vector<double>& duration,
                                                 const std::vector<double>& duration_sigma,
                                                 const ReboundAnomalyOptions& options = {});

}  // namespace impactlab
