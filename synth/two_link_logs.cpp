#include "synth/two_link_logs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/errors.h"
#include "io/log_reader.h"  // kStandardGravity
#include "multibody/two_link_channels.h"
#include "multibody/two_link_toml.h"
#include "synth/gaussian.h"
#include "synth/log_file_internal.h"
#include "synth/manifest_writer.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

constexpr const char* kAccelerometerColumns[kTwoLinkAccelerometers] = {"acc1", "acc2", "acc3",
                                                                       "acc4"};

double CountsPerRad(const TwoLinkSensors& sensors, const TwoLinkDrive& drive) {
  return sensors.counts_per_rev * drive.gear_ratio / (2.0 * std::numbers::pi);
}

bool IsBeamSensor(int s) { return s == 0 || s == 2; }

double Sensitivity(const TwoLinkSensors& s, int accelerometer) {
  return IsBeamSensor(accelerometer) ? s.beam_sensitivity_v_per_g : s.body_sensitivity_v_per_g;
}

std::ofstream OpenCsv(const fs::path& file, const std::string& header) {
  std::ofstream out(file, std::ios::binary);
  if (!out) throw InputError({file, "", std::nullopt}, "cannot write the file");
  out << header << "\n";
  return out;
}

std::string LogHeader() { return "t,enc1,enc2,acc1,acc2,acc3,acc4"; }

// What the logger records of a clean record: whole encoder counts and
// accelerometer volts with noise in ADC steps.
struct LoggedRecord {
  std::vector<long long> counts_a, counts_b;
  std::array<std::vector<double>, kTwoLinkAccelerometers> volts;
};

LoggedRecord RecordWithLogger(const TwoLinkRecord& r, const TwoLinkParameters& p,
                              std::uint64_t seed) {
  const TwoLinkSensors& s = p.sensors;
  synth_detail::Gaussian noise(seed);
  LoggedRecord logged;
  for (std::size_t i = 0; i < r.time_s.size(); ++i) {
    logged.counts_a.push_back(
        static_cast<long long>(std::floor(r.gearbox_a_rad[i] * CountsPerRad(s, p.drive_a))));
    logged.counts_b.push_back(
        static_cast<long long>(std::floor(r.gearbox_b_rad[i] * CountsPerRad(s, p.drive_b))));
    for (int a = 0; a < kTwoLinkAccelerometers; ++a) {
      const double sigma = IsBeamSensor(a) ? s.beam_noise_v : s.body_noise_v;
      double volts =
          r.acceleration_m_s2[a][i] / kStandardGravity * Sensitivity(s, a) + sigma * noise();
      if (s.adc_lsb_v > 0.0) volts = std::round(volts / s.adc_lsb_v) * s.adc_lsb_v;
      logged.volts[a].push_back(volts);
    }
  }
  return logged;
}

// The experiment's rows; with `inject_defects`, the row a fifth of the way in
// has NaN for acc1, the row two fifths in is written twice and the row three
// fifths in is left out. Returns the defects as written ({"kind", "line",
// "column"}, {"kind", "line"} or {"kind", "time_s"}).
nlohmann::json WriteExperimentCsv(const fs::path& file, const TwoLinkRecord& r,
                                  const LoggedRecord& logged, bool inject_defects) {
  std::ofstream out = OpenCsv(file, LogHeader());
  nlohmann::json defects = nlohmann::json::array();
  const std::size_t rows = r.time_s.size();
  const std::size_t nan_row = rows / 5, duplicate_row = 2 * rows / 5, missing_row = 3 * rows / 5;
  long long line = 1;  // the header
  for (std::size_t i = 0; i < rows; ++i) {
    if (inject_defects && i == missing_row) {
      defects.push_back({{"kind", "missing sample"}, {"time_s", r.time_s[i]}});
      continue;
    }
    std::string row =
        fmt::format("{:.6f},{},{}", r.time_s[i], logged.counts_a[i], logged.counts_b[i]);
    for (int a = 0; a < kTwoLinkAccelerometers; ++a) {
      if (inject_defects && i == nan_row && a == 0) {
        row += ",nan";
        defects.push_back(
            {{"kind", "NaN"}, {"line", line + 1}, {"column", kAccelerometerColumns[a]}});
        continue;
      }
      row += fmt::format(",{:.6f}", logged.volts[a][i]);
    }
    row += "\n";
    out << row;
    ++line;
    if (inject_defects && i == duplicate_row) {
      out << row;
      ++line;
      defects.push_back({{"kind", "duplicated time"}, {"line", line}});
    }
  }
  synth_detail::CloseLog(out, file);
  return defects;
}

void WriteStateCsv(const fs::path& file, const TwoLinkRecord& r) {
  std::ofstream out = OpenCsv(
      file,
      "t,q1,q2,q3,q4,q5,q6,theta_a,theta_b,q1_dot,q2_dot,q3_dot,q4_dot,q5_dot,q6_dot,"
      "theta_a_dot,theta_b_dot,in_contact,normal_force,friction_force,tip_x,tip_y,voltage_a,"
      "voltage_b");
  for (std::size_t i = 0; i < r.position.size(); ++i) {
    std::string row = fmt::format("{:.6f}", r.time_s[i]);
    for (int c = 0; c < kTwoLinkCoordinates; ++c) row += fmt::format(",{:.10g}", r.position[i](c));
    for (int c = 0; c < kTwoLinkCoordinates; ++c) row += fmt::format(",{:.10g}", r.velocity[i](c));
    row += fmt::format(",{},{:.10g},{:.10g},{:.10g},{:.10g},{:.6g},{:.6g}\n", r.in_contact[i],
                       r.normal_force_n[i], r.friction_force_n[i], r.tip_x_m[i], r.tip_y_m[i],
                       r.voltage_a_v[i], r.voltage_b_v[i]);
    out << row;
  }
  synth_detail::CloseLog(out, file);
}

nlohmann::json RecordJson(const TwoLinkRecord& r, const std::string& parameters_text) {
  nlohmann::json events = nlohmann::json::array();
  for (const TwoLinkEvent& e : r.events) {
    nlohmann::json event = {{"time_s", e.time_s}, {"kind", e.kind}};
    if (e.kind == "impact") {
      event["normal_velocity_before_m_s"] = e.impact.normal_velocity_before_m_s;
      event["tangential_velocity_before_m_s"] = e.impact.tangential_velocity_before_m_s;
      event["normal_impulse_n_s"] = e.impact.normal_impulse_n_s;
      event["tangential_impulse_n_s"] = e.impact.tangential_impulse_n_s;
      event["sticks"] = e.impact.sticks;
      event["slip_reversed"] = e.impact.slip_reversed;
      event["normal_velocity_after_m_s"] = e.impact.normal_velocity_after_m_s;
      event["tangential_velocity_after_m_s"] = e.impact.tangential_velocity_after_m_s;
      event["friction_work_j"] = e.impact.friction_work_j;
      event["normal_work_j"] = e.impact.normal_work_j;
    }
    events.push_back(event);
  }
  return {{"impact_time_s", r.FirstImpact()},
          {"events", events},
          {"steps", r.steps},
          {"max_loop_closure_m", r.max_loop_closure_m},
          {"parameters_toml", parameters_text}};
}

Log CaseLog(const std::string& id, const TwoLinkParameters& p) {
  Log log;
  log.id = id;
  log.experiment = fmt::format("logs/{}-experiment.csv", id);
  log.simulation = fmt::format("logs/{}-simulation.csv", id);
  log.time_column = "t";
  auto encoder = [&](const char* name, const char* column, const TwoLinkDrive& drive) {
    LogChannel c;
    c.name = name;
    c.column = column;
    c.counts_per_rev = p.sensors.counts_per_rev;
    c.gear_ratio = drive.gear_ratio;
    return c;
  };
  log.channels = {encoder(kTwoLinkEncoderAChannel, "enc1", p.drive_a),
                  encoder(kTwoLinkEncoderBChannel, "enc2", p.drive_b)};
  for (int a = 0; a < kTwoLinkAccelerometers; ++a) {
    LogChannel c;
    c.name = kTwoLinkAccelerometerChannels[a];
    c.column = kAccelerometerColumns[a];
    c.sensitivity = Sensitivity(p.sensors, a);
    log.channels.push_back(c);
  }
  return log;
}

}  // namespace

void WriteTwoLinkSimulationCsv(const fs::path& file, const TwoLinkRecord& r) {
  std::ofstream out = OpenCsv(file, LogHeader());
  for (std::size_t i = 0; i < r.time_s.size(); ++i) {
    fmt::format_to(std::ostreambuf_iterator<char>(out),
                   "{:.6f},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g}\n", r.time_s[i],
                   r.gearbox_a_rad[i], r.gearbox_b_rad[i], r.acceleration_m_s2[0][i],
                   r.acceleration_m_s2[1][i], r.acceleration_m_s2[2][i], r.acceleration_m_s2[3][i]);
  }
  synth_detail::CloseLog(out, file);
}

TwoLinkMeasurement LoggedMeasurement(const TwoLinkParameters& p, const TwoLinkRecord& r,
                                     std::uint64_t seed) {
  const LoggedRecord logged = RecordWithLogger(r, p, seed);
  TwoLinkMeasurement m;
  m.time_s = r.time_s;
  m.encoder_a_step_rad = 1.0 / CountsPerRad(p.sensors, p.drive_a);
  m.encoder_b_step_rad = 1.0 / CountsPerRad(p.sensors, p.drive_b);
  std::vector<double> q1, q4;
  for (std::size_t i = 0; i < r.time_s.size(); ++i) {
    q1.push_back(static_cast<double>(logged.counts_a[i]) * m.encoder_a_step_rad);
    q4.push_back(static_cast<double>(logged.counts_b[i]) * m.encoder_b_step_rad);
  }
  m.q1_rad = std::move(q1);
  m.q4_rad = std::move(q4);
  for (int a = 0; a < kTwoLinkAccelerometers; ++a) {
    std::vector<double> values = logged.volts[a];
    for (double& v : values) v *= kStandardGravity / Sensitivity(p.sensors, a);
    m.acceleration_m_s2[a] = std::move(values);
  }
  return m;
}

std::uint64_t CaseSeed(std::uint64_t seed, int case_number) {
  return seed + static_cast<std::uint64_t>(case_number);
}

namespace {

// The cases' simulations and files, into a folder made ready for them.
TwoLinkLogSummary WriteTwoLinkCases(const fs::path& folder, const TwoLinkLogOptions& options) {
  const TwoLinkModel simulation_model(options.simulation);
  const TwoLinkModel experiment_model(options.experiment);
  SessionManifest manifest;
  manifest.comment = options.comment;
  if (manifest.comment.empty()) {
    manifest.comment = {"Encoder and accelerometer logs of the two-link flexible manipulator",
                        "(impactlab simulate two-link; docs/two-link.md). The experiment is the",
                        "simulator with the experiment's parameters and the logger's noise; the",
                        "simulation is the simulation's parameters, clean, in SI."};
  }
  manifest.title =
      options.title.empty() ? "Two-link flexible manipulator (simulated logs)" : options.title;
  manifest.units = UnitSystem::kSI;
  TwoLinkLogSummary summary;
  summary.truth = {{"schema", "impactlab-two-link-truth"},
                   {"version", 1},
                   {"seed", options.seed},
                   {"sample_rate_hz", options.experiment.sensors.sample_rate_hz}};
  const std::string experiment_text = TwoLinkParametersText(options.experiment);
  const std::string simulation_text = TwoLinkParametersText(options.simulation);
  std::size_t simulations = 0;
  for (int number : options.cases) {
    const TwoLinkCase& experiment_case = options.experiment.cases[number - 1];
    const TwoLinkCase& simulation_case = options.simulation.cases[number - 1];
    TwoLinkSimulationOptions integration = options.integration;
    integration.keep_state = options.write_state;
    const auto simulated = [&, total = 2 * options.cases.size()](const char* source) {
      if (options.on_progress) options.on_progress({number, source, ++simulations, total});
    };
    // A case the model refuses writes no session: its reason, as a refusal.
    const auto refuse_unless_ok = [&](const TwoLinkRecord& record, const char* source) {
      if (!record.ok)
        throw std::domain_error(fmt::format("case {} {}: {}", number, source, record.reason));
    };
    const TwoLinkRecord experiment =
        SimulateTwoLink(experiment_model, experiment_case, integration);
    refuse_unless_ok(experiment, "experiment");
    simulated("experiment");
    // The same parameters give the same record: simulated once.
    const bool same = experiment_text == simulation_text;
    std::optional<TwoLinkRecord> simulated_apart;
    if (!same) {
      simulated_apart = SimulateTwoLink(simulation_model, simulation_case, integration);
      refuse_unless_ok(*simulated_apart, "simulation");
    }
    const TwoLinkRecord& simulation = same ? experiment : *simulated_apart;
    simulated("simulation");
    for (const auto& [source, record] :
         {std::pair{"experiment", &experiment}, std::pair{"simulation", &simulation}}) {
      for (const std::string& warning : record->warnings) {
        summary.warnings.push_back(fmt::format("case {} {}: {}", number, source, warning));
      }
      if (same) break;
    }
    const Log log = CaseLog(options.log_id.empty() ? fmt::format("case{}", number) : options.log_id,
                            options.experiment);
    const nlohmann::json defects = WriteExperimentCsv(
        folder / log.experiment, experiment,
        RecordWithLogger(experiment, options.experiment, CaseSeed(options.seed, number)),
        options.inject_defects);
    WriteTwoLinkSimulationCsv(folder / *log.simulation, simulation);
    if (options.write_state) {
      WriteStateCsv(folder / "state" / fmt::format("{}-experiment.csv", log.id), experiment);
      WriteStateCsv(folder / "state" / fmt::format("{}-simulation.csv", log.id), simulation);
    }
    manifest.logs.push_back(log);
    summary.truth[log.id] = {{"experiment", RecordJson(experiment, experiment_text)},
                             {"simulation", RecordJson(simulation, simulation_text)}};
    if (options.inject_defects) summary.truth[log.id]["defects"] = defects;
    summary.rows.push_back(static_cast<int>(experiment.time_s.size()));
  }
  WriteManifest(folder / "session.toml", manifest);
  return summary;
}

}  // namespace

TwoLinkLogSummary WriteTwoLinkSession(const fs::path& folder, const TwoLinkLogOptions& options) {
  if (options.cases.empty()) throw std::invalid_argument("simulate two-link: no case chosen");
  if (!options.log_id.empty() && options.cases.size() > 1) {
    throw std::invalid_argument("simulate two-link: a log id names one case's log, not several");
  }
  for (std::size_t i = 0; i < options.cases.size(); ++i) {
    const int number = options.cases[i];
    if (number < 1 || number > 3) {
      throw std::invalid_argument(fmt::format("simulate two-link: no case {} (1, 2 or 3)", number));
    }
    if (std::find(options.cases.begin(), options.cases.begin() + i, number) !=
        options.cases.begin() + i) {
      throw std::invalid_argument(
          fmt::format("simulate two-link: case {} is chosen twice (a session holds one log per "
                      "case)",
                      number));
    }
  }
  std::error_code ec;
  const bool folder_existed = fs::exists(folder);
  if (folder_existed && !fs::is_empty(folder, ec)) {
    throw InputError({folder, "", std::nullopt}, "the output folder exists and is not empty");
  }
  fs::create_directories(folder / "logs", ec);
  if (options.write_state) fs::create_directories(folder / "state", ec);
  if (ec) throw InputError({folder, "", std::nullopt}, "cannot create the folder: " + ec.message());
  // A run that fails takes away what it wrote (the folder was empty or
  // absent), so that the same command can simply be run again.
  try {
    return WriteTwoLinkCases(folder, options);
  } catch (...) {
    std::error_code ignored;
    if (folder_existed) {
      std::vector<fs::path> written;
      for (const auto& entry : fs::directory_iterator(folder, ignored)) {
        written.push_back(entry.path());
      }
      for (const fs::path& entry : written) fs::remove_all(entry, ignored);
    } else {
      fs::remove_all(folder, ignored);
    }
    throw;
  }
}

}  // namespace impactlab
