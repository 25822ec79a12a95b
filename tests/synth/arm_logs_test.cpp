// `impactlab synth-logs` (synth/arm_logs.h): the session it writes follows
// session-format.md and reads back without warnings, the same seed writes the same
// bytes, the experiment hides the sample session's differences, and the
// defects the truth lists are where it says.
#include "synth/arm_logs.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "io/errors.h"
#include "io/log_reader.h"
#include "io/manifest.h"
#include "multibody/two_link_keys.h"
#include "multibody/two_link_toml.h"
#include "tests/support/temp_dir.h"
#include "tests/support/text_file.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

TEST_CASE("synth-logs: the session reads back cleanly and the same seed writes the same bytes",
          "[arm_logs]") {
  TempDir dir;
  ArmLogOptions options;
  options.seed = 7;
  options.duration_s = 2.5;  // the first impact is at 1.69 s (simulation), 1.76 s (experiment)
  const TwoLinkLogSummary a = WriteTwoLinkSession(dir.path() / "a", ArmLogSession(options));
  WriteTwoLinkSession(dir.path() / "b", ArmLogSession(options));
  ArmLogOptions other = options;
  other.seed = 8;
  WriteTwoLinkSession(dir.path() / "c", ArmLogSession(other));
  const fs::path file = "logs/case1-experiment.csv";
  CHECK(testing::ReadText(dir.path() / "a" / file) == testing::ReadText(dir.path() / "b" / file));
  CHECK(testing::ReadText(dir.path() / "a" / file) != testing::ReadText(dir.path() / "c" / file));
  REQUIRE(a.rows.size() == 1);
  CHECK(a.rows[0] == 2501);  // t = k / 1000 s, k = 0 ... 2500
  CHECK_FALSE(fs::exists(dir.path() / "a" / "state"));

  const ManifestReadResult manifest = ReadManifest(dir.path() / "a");
  CHECK(manifest.warnings.empty());
  REQUIRE(manifest.session.logs.size() == 1);
  const Log& log = manifest.session.logs[0];
  CHECK(log.id == "case1");
  REQUIRE(log.simulation);
  REQUIRE(log.channels.size() == 6);
  const TwoLinkParameters nominal = TwoLinkParameters::Nominal();
  CHECK(log.channels[0].name == "q1");
  CHECK(log.channels[0].counts_per_rev == nominal.sensors.counts_per_rev);
  CHECK(log.channels[0].gear_ratio == nominal.drive_a.gear_ratio);
  CHECK(log.channels[2].name == "a1");
  CHECK(log.channels[2].sensitivity == nominal.sensors.beam_sensitivity_v_per_g);
  CHECK(a.truth["schema"] == "impactlab-two-link-truth");
  const double experiment_impact = a.truth["case1"]["experiment"]["impact_time_s"];
  const double simulation_impact = a.truth["case1"]["simulation"]["impact_time_s"];
  CHECK(experiment_impact > simulation_impact);  // the motors started later

  CHECK_THROWS_AS(WriteTwoLinkSession(dir.path() / "a", ArmLogSession(options)), InputError);
  other.sample_rate_hz = 1.0;
  CHECK_THROWS_AS(ArmLogSession(other), std::invalid_argument);
  other = options;
  other.log_id.clear();
  CHECK_THROWS_AS(ArmLogSession(other), std::invalid_argument);
}

TEST_CASE("synth-logs: the experiment hides the sample session's differences, and its noise",
          "[arm_logs]") {
  // sample_data/two-link/experiment.toml types the same differences in,
  // rounded to 4 digits.
  const fs::path file =
      fs::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "two-link" / "experiment.toml";
  const TwoLinkParameters nominal = TwoLinkParameters::Nominal();
  TwoLinkParameters typed = ParseTwoLinkParameters(testing::ReadText(file), file, nominal);
  TwoLinkParameters hidden = ExperimentWithHiddenDifferences(nominal);
  // The typed file moves only case 1's start; the hidden differences move
  // every case's alike.
  for (int c = 1; c < 3; ++c) typed.cases[c].start_delay_s = hidden.cases[c].start_delay_s;
  std::vector<double> typed_values, hidden_values;
  std::vector<std::string> keys;
  VisitTwoLinkKeys(typed, [&](const char* section, const char* key, auto& value, auto, auto) {
    keys.push_back(std::string(section) + "." + key);
    typed_values.push_back(static_cast<double>(value));
  });
  VisitTwoLinkKeys(hidden, [&](const char*, const char*, auto& value, auto, auto) {
    hidden_values.push_back(static_cast<double>(value));
  });
  REQUIRE(typed_values.size() == hidden_values.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    INFO(keys[i]);
    CHECK(hidden_values[i] == Approx(typed_values[i]).epsilon(2e-4));
  }

  ArmLogOptions options;
  options.noise_factor = 3.0;
  const TwoLinkLogOptions session = ArmLogSession(options);
  CHECK(session.experiment.sensors.beam_noise_v == 3.0 * nominal.sensors.beam_noise_v);
  CHECK(session.experiment.sensors.body_noise_v == 3.0 * nominal.sensors.body_noise_v);
  CHECK(session.simulation.sensors.beam_noise_v == nominal.sensors.beam_noise_v);
}

TEST_CASE("synth-logs --defects: the truth lists the NaN, duplicated and missing rows as written",
          "[arm_logs]") {
  TempDir dir;
  ArmLogOptions options;
  options.duration_s = 1.0;  // 1001 rows; no impact needed to place the defects
  options.inject_defects = true;
  options.log_id = "arm";
  const TwoLinkLogSummary summary = WriteTwoLinkSession(dir.path() / "s", ArmLogSession(options));
  const nlohmann::json& defects = summary.truth["arm"]["defects"];
  REQUIRE(defects.size() == 3);
  std::vector<std::string> lines;
  {
    std::ifstream in(dir.path() / "s" / "logs" / "arm-experiment.csv");
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  CHECK(lines.size() == 1 + 1001);  // the header; one row twice, one left out
  for (const nlohmann::json& defect : defects) {
    INFO(defect.dump());
    if (defect["kind"] == "NaN") {
      const std::string& row = lines.at(defect["line"].get<std::size_t>() - 1);
      CHECK(defect["column"] == "acc1");
      CHECK(row.find(",nan,") != std::string::npos);
    } else if (defect["kind"] == "duplicated time") {
      const auto line = defect["line"].get<std::size_t>();
      CHECK(lines.at(line - 1) == lines.at(line - 2));
    } else {
      CHECK(defect["kind"] == "missing sample");
      const std::string time = fmt::format("{:.6f},", defect["time_s"].get<double>());
      for (const std::string& row : lines) CHECK(row.rfind(time, 0) == std::string::npos);
    }
  }
}

}  // namespace
}  // namespace impactlab
