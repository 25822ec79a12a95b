// `impactlab synth-logs`: encoder and accelerometer logs of a flexible arm whose
// tip strikes a wall, as an experiment/simulation pair with exact truth
// (docs/logs.md, "Sample data"; the second source document, section 3).
//
// The arm and its sensors are synth/beam_model.h, its motion
// synth/beam_simulation.h, the log files synth/beam_log_writer.h. The
// experiment has Gaussian voltage noise, a 16-bit ADC, integer counts and its
// own parameters (a heavier tip body, more motor friction, a later start); the
// simulation is the nominal model in SI, clean.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "synth/beam_model.h"
#include "synth/beam_simulation.h"
#include "synth/manifest_writer.h"

namespace impactlab {

struct BeamLogOptions {
  std::uint64_t seed = 1;  // noise; the same seed writes the same bytes
  double sample_rate_hz = 1000.0;
  double duration_s = 5.0;
  BeamArm simulation;  // the nominal model
  // The experiment: the nominal arm with these differences.
  double experiment_tip_inertia_factor = 1.26;  // heavier tip body: 10.9 Hz
  double experiment_hub_damping_factor = 1.02;  // more friction: slower, later impact
  double experiment_start_delay_s = 0.042;      // the logger started before the motor
  BeamSensors sensors;
  double noise_factor = 1.0;    // scales both accelerometer noises
  bool inject_defects = false;  // a NaN, a duplicated and a missing row in the experiment
  std::string log_id = "case1";

  bool Check(std::string* error) const;
};

struct BeamLogSummary {
  int rows = 0;  // per file
  double experiment_impact_s = 0.0;
  double simulation_impact_s = 0.0;
  nlohmann::json truth;      // schema "impactlab-logs-truth" 1 (docs/logs.md)
  SessionManifest manifest;  // what session.toml says
};

// Writes `folder`/session.toml and `folder`/logs/<id>-{experiment,simulation}.csv.
// The folder must not exist or be empty. Throws std::invalid_argument for bad
// options, InputError for a folder that cannot be written.
BeamLogSummary GenerateBeamLogs(const std::filesystem::path& folder, const BeamLogOptions& options);

// The experiment's arm for the options.
BeamArm ExperimentArm(const BeamLogOptions& options);

}  // namespace impactlab
