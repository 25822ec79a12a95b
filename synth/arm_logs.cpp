#include "synth/arm_logs.h"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace impactlab {

bool ArmLogOptions::Check(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = what;
    return false;
  };
  if (case_number < 1 || case_number > 3) return fail("case_number must be 1, 2 or 3");
  if (!(sample_rate_hz >= 100.0 && sample_rate_hz <= 1e6)) {
    return fail("sample_rate_hz must lie in [100, 1e6]");
  }
  if (!(duration_s > 0.0) || duration_s * sample_rate_hz > kTwoLinkMaxSamples) {
    return fail("duration_s must be positive and give at most 2e6 rows");
  }
  if (!(noise_factor >= 0.0) || !std::isfinite(noise_factor)) {
    return fail("noise_factor must be finite and >= 0");
  }
  if (!(experiment_start_delay_s >= 0.0 && experiment_start_delay_s <= 10.0)) {
    return fail("experiment_start_delay_s must lie in [0, 10] s");
  }
  if (log_id.empty()) return fail("log_id must not be empty");
  // The truth holds the log under its id beside its own keys.
  for (const char* key : {"schema", "version", "seed", "sample_rate_hz"}) {
    if (log_id == key) return fail("log_id must not be one of the truth's own keys");
  }
  return true;
}

TwoLinkParameters ExperimentWithHiddenDifferences(TwoLinkParameters p, double start_delay_s) {
  constexpr double kThickness = 2.4 / 2.5;  // sheet as cut, against as drawn
  for (TwoLinkBeam* beam : {&p.beam1, &p.beam2}) {
    beam->flexural_rigidity_n_m2 *= kThickness * kThickness * kThickness;
    beam->mass_per_length_kg_per_m *= kThickness;
  }
  p.body2.mass_kg *= 1.04;
  for (TwoLinkCase& c : p.cases) c.start_delay_s += start_delay_s;
  return p;
}

TwoLinkLogOptions ArmLogSession(const ArmLogOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("synth-logs: " + error);
  }
  TwoLinkLogOptions session;
  session.cases = {options.case_number};
  session.seed = options.seed;
  session.write_state = false;
  session.log_id = options.log_id;
  session.inject_defects = options.inject_defects;
  session.title = fmt::format("Two-link flexible manipulator, case {} (synthetic logs, seed {})",
                              options.case_number, options.seed);
  session.comment = {
      "Synthetic encoder and accelerometer logs of the two-link flexible arm",
      fmt::format("(impactlab synth-logs --seed {}; docs/logs.md). The experiment hides",
                  options.seed),
      "differences from the simulation; the truth is kept outside the folder."};
  TwoLinkParameters& simulation = session.simulation;
  simulation.sensors.sample_rate_hz = options.sample_rate_hz;
  simulation.cases[options.case_number - 1].duration_s = options.duration_s;
  session.experiment =
      ExperimentWithHiddenDifferences(simulation, options.experiment_start_delay_s);
  session.experiment.sensors.beam_noise_v *= options.noise_factor;
  session.experiment.sensors.body_noise_v *= options.noise_factor;
  return session;
}

}  // namespace impactlab
