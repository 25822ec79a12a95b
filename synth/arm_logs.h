// `impactlab synth-logs`: an experiment/simulation pair of encoder and
// accelerometer logs of the two-link flexible arm (multibody/,
// docs/two-link.md), with its truth, for the log stage's tests and benchmarks
// (docs/logs.md, "Sample data"). The simulation is the nominal arm; the
// experiment is the same arm with differences a lab would not know of, seen
// through its logger (whole counts, noise, ADC steps). The session is written
// by synth/two_link_logs.h, as `impactlab simulate two-link` writes one.
#pragma once

#include <cstdint>
#include <string>

#include "multibody/two_link_parameters.h"
#include "synth/two_link_logs.h"

namespace impactlab {

struct ArmLogOptions {
  std::uint64_t seed = 1;  // the experiment's noise; the same seed writes the same bytes
  int case_number = 1;     // the document's case (docs/two-link.md)
  double sample_rate_hz = 1000.0;
  double duration_s = 5.0;
  double noise_factor = 1.0;                // scales the accelerometers' noise (0: none)
  double experiment_start_delay_s = 0.055;  // the experiment's motors start this much later
  bool inject_defects = false;  // a NaN, a duplicated and a missing row in the experiment
  std::string log_id = "case1";

  bool Check(std::string* error) const;
};

// The hidden differences (with the default delay, those of
// sample_data/two-link/experiment.toml): both beams cut from 2.4 mm sheet
// instead of the 2.5 mm drawn (E I x (2.4/2.5)^3, rho A x 0.96), RB2 4 %
// heavier, the motors started `start_delay_s` later in every case. a1 then
// rings near 10.8 Hz against 11.6 Hz simulated, and case 1's first impact
// comes about 0.07 s late.
TwoLinkParameters ExperimentWithHiddenDifferences(TwoLinkParameters simulation,
                                                  double start_delay_s = 0.055);

// What WriteTwoLinkSession is given for the options: the nominal arm sampled
// at the rate for the duration as the simulation, its experiment above with
// the noise scaled, one case, no state histories. Throws
// std::invalid_argument for options that fail Check().
TwoLinkLogOptions ArmLogSession(const ArmLogOptions& options);

}  // namespace impactlab
