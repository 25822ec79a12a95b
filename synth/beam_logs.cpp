#include "synth/beam_logs.h"

#include <stdexcept>

#include <fmt/format.h>

#include "io/errors.h"
#include "synth/beam_log_writer.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

nlohmann::json ModesJson(const std::vector<BeamPole>& modes) {
  nlohmann::json out = nlohmann::json::array();
  for (const BeamPole& m : modes) {
    out.push_back({{"frequency_hz", m.frequency_hz},
                   {"natural_frequency_hz", m.natural_frequency_hz},
                   {"damping_ratio", m.damping_ratio},
                   {"decay_rate_per_s", m.decay_rate_per_s}});
  }
  return out;
}

nlohmann::json ArmJson(const BeamArm& arm) {
  return {{"length_m", arm.length_m},
          {"mass_per_length_kg_per_m", arm.mass_per_length_kg_per_m},
          {"flexural_rigidity_n_m2", arm.flexural_rigidity_n_m2},
          {"hub_inertia_kg_m2", arm.hub_inertia_kg_m2},
          {"tip_mass_kg", arm.tip_mass_kg},
          {"tip_inertia_kg_m2", arm.tip_inertia_kg_m2},
          {"beam_damping_n_s_per_m2", arm.beam_damping_n_s_per_m2},
          {"hub_damping_n_m_s", arm.hub_damping_n_m_s},
          {"motor_torque_n_m", arm.motor_torque_n_m},
          {"start_angle_rad", arm.start_angle_rad},
          {"wall_angle_rad", arm.wall_angle_rad},
          {"start_delay_s", arm.start_delay_s}};
}

nlohmann::json SensorsJson(const BeamLogOptions& options) {
  const BeamSensors& sensors = options.sensors;
  return {{"counts_per_rev", sensors.counts_per_rev},
          {"gear_ratio", sensors.gear_ratio},
          {"a1_sensitivity_v_per_g", sensors.a1_sensitivity_v_per_g},
          {"a2_sensitivity_v_per_g", sensors.a2_sensitivity_v_per_g},
          {"a1_noise_v", options.noise_factor * sensors.a1_noise_v},
          {"a2_noise_v", options.noise_factor * sensors.a2_noise_v},
          {"adc_lsb_v", sensors.adc_lsb_v},
          {"a1_position", sensors.a1_position},
          {"a2_inboard_m", sensors.a2_inboard_m}};
}

// One source's truth: its impact, its poles and, per channel, the dominant
// post-impact mode: the oscillating one with the most energy, A^2 / sigma.
nlohmann::json SourceTruth(const BeamRecord& record, const BeamArm& arm, const std::string& file) {
  nlohmann::json channels;
  const char* names[] = {"q1", "a1", "a2"};
  const char* units[] = {"rad", "m/s^2", "m/s^2"};
  for (std::size_t c = 0; c < 3; ++c) {
    const auto& amplitudes = record.post_mode_amplitudes[c];
    std::size_t dominant = 0;
    double most = -1.0;
    for (std::size_t m = 0; m < amplitudes.size(); ++m) {
      const double energy = amplitudes[m] * amplitudes[m] / record.post_modes[m].decay_rate_per_s;
      if (record.post_modes[m].frequency_hz > 0.0 && energy > most) {
        most = energy;
        dominant = m;
      }
    }
    channels[names[c]] = {{"units", units[c]},
                          {"post_impact_mode_amplitudes", amplitudes},
                          {"dominant_mode", dominant},
                          {"dominant_frequency_hz", record.post_modes[dominant].frequency_hz},
                          {"damping_ratio", record.post_modes[dominant].damping_ratio}};
  }
  return {{"file", file},
          {"impact_time_s", record.impact_time_s},
          {"impact_speed_m_s", record.impact_speed_m_s},
          {"min_contact_force_n", record.min_contact_force_n},
          {"free_flight_modes", ModesJson(record.free_modes)},
          {"post_impact_modes", ModesJson(record.post_modes)},
          {"channels", channels},
          {"arm", ArmJson(arm)}};
}

// The session: one log whose channels the paper names q1 (the hub's encoder),
// a1 and a2 (the accelerometers), with the scales that turn the experiment's
// counts and volts into SI.
SessionManifest LogsManifest(const BeamLogOptions& options, const std::string& experiment_file,
                             const std::string& simulation_file) {
  SessionManifest manifest;
  manifest.comment = {
      "Synthetic encoder and accelerometer logs: a flexible arm whose tip",
      fmt::format("strikes a wall (impactlab synth-logs --seed {}; docs/logs.md). Truth is",
                  options.seed),
      "kept outside the folder."};
  manifest.title =
      fmt::format("Flexible arm striking a wall (synthetic logs, seed {})", options.seed);
  manifest.units = UnitSystem::kSI;
  Log log;
  log.id = options.log_id;
  log.experiment = experiment_file;
  log.simulation = simulation_file;
  log.time_column = kBeamLogTimeColumn;
  LogChannel q1;
  q1.name = "q1";
  q1.column = kBeamLogEncoderColumn;
  q1.counts_per_rev = options.sensors.counts_per_rev;
  q1.gear_ratio = options.sensors.gear_ratio;
  LogChannel a1;
  a1.name = "a1";
  a1.column = kBeamLogA1Column;
  a1.sensitivity = options.sensors.a1_sensitivity_v_per_g;
  LogChannel a2;
  a2.name = "a2";
  a2.column = kBeamLogA2Column;
  a2.sensitivity = options.sensors.a2_sensitivity_v_per_g;
  log.channels = {q1, a1, a2};
  manifest.logs.push_back(log);
  return manifest;
}

}  // namespace

bool BeamLogOptions::Check(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = what;
    return false;
  };
  if (!simulation.Check(error)) return false;
  if (!ExperimentArm(*this).Check(error)) return false;
  if (!(sample_rate_hz >= 100.0 && sample_rate_hz <= 1e6)) {
    return fail("sample_rate_hz must lie in [100, 1e6]");
  }
  if (!(duration_s > 0.0) || duration_s * sample_rate_hz > 5e7) {
    return fail("duration_s must be positive and give at most 5e7 rows");
  }
  if (!(noise_factor >= 0.0)) return fail("noise_factor must be >= 0");
  if (log_id.empty()) return fail("log_id must not be empty");
  return true;
}

BeamArm ExperimentArm(const BeamLogOptions& options) {
  BeamArm arm = options.simulation;
  arm.tip_inertia_kg_m2 *= options.experiment_tip_inertia_factor;
  arm.hub_damping_n_m_s *= options.experiment_hub_damping_factor;
  arm.start_delay_s = options.experiment_start_delay_s;
  return arm;
}

BeamLogSummary GenerateBeamLogs(const fs::path& folder, const BeamLogOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("BeamLogOptions: " + error);
  }
  std::error_code ec;
  if (fs::exists(folder) && !fs::is_empty(folder, ec)) {
    throw InputError({folder, "", std::nullopt}, "the output folder exists and is not empty");
  }
  fs::create_directories(folder / "logs", ec);
  if (ec) throw InputError({folder / "logs", "", std::nullopt}, "cannot create the folder");

  const BeamArm experiment_arm = ExperimentArm(options);
  const BeamSensors& sensors = options.sensors;
  const BeamRecord sim =
      SimulateBeam(options.simulation, sensors, options.sample_rate_hz, options.duration_s);
  const BeamRecord exp =
      SimulateBeam(experiment_arm, sensors, options.sample_rate_hz, options.duration_s);

  const std::string experiment_file = fmt::format("logs/{}-experiment.csv", options.log_id);
  const std::string simulation_file = fmt::format("logs/{}-simulation.csv", options.log_id);
  WriteSimulationLog(folder / simulation_file, sim);
  const nlohmann::json defects = WriteExperimentLog(
      folder / experiment_file, LogExperiment(exp, sensors, options.noise_factor, options.seed),
      options.inject_defects);
  BeamLogSummary summary;
  summary.manifest = LogsManifest(options, experiment_file, simulation_file);
  WriteManifest(folder / "session.toml", summary.manifest);

  summary.rows = static_cast<int>(exp.time_s.size());
  summary.experiment_impact_s = exp.impact_time_s;
  summary.simulation_impact_s = sim.impact_time_s;
  summary.truth = {{"schema", "impactlab-logs-truth"},
                   {"version", 1},
                   {"seed", options.seed},
                   {"log_id", options.log_id},
                   {"sample_rate_hz", options.sample_rate_hz},
                   {"duration_s", options.duration_s},
                   {"sensors", SensorsJson(options)},
                   {"experiment", SourceTruth(exp, experiment_arm, experiment_file)},
                   {"simulation", SourceTruth(sim, options.simulation, simulation_file)},
                   {"impact_offset_s", sim.impact_time_s - exp.impact_time_s},
                   {"defects", defects}};
  return summary;
}

}  // namespace impactlab
