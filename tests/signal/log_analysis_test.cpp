// Tests of the log stage end to end, against the generator's truth: impact
// instants, frequencies and damping ratios, the comparison, bad rows and the
// decimated (bounded-memory) path; and the sample session in sample_data/.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "io/manifest.h"
#include "signal/log_analysis.h"
#include "synth/beam_logs.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using testing::TempDir;

// A generated session, its manifest's log and the truth.
struct Generated {
  TempDir dir;
  Log log;
  nlohmann::json truth;

  explicit Generated(BeamLogOptions options = {}) {
    truth = GenerateBeamLogs(dir.path() / "session", options).truth;
    log = ReadManifest(dir.path() / "session").session.logs.at(0);
  }
};

const ChannelAnalysis& Channel(const SourceAnalysis& source, const std::string& name) {
  for (const ChannelAnalysis& c : source.channels) {
    if (c.name == name) return c;
  }
  FAIL("no channel " << name);
  return source.channels.front();
}

// The channel's frequency and damping against the truth: within `sigmas` of
// their own uncertainty (plus a floor for the noise-free simulation).
void CheckAgainstTruth(const ChannelAnalysis& channel, const nlohmann::json& truth, double sigmas) {
  INFO("channel " << channel.name);
  REQUIRE(channel.dominant_frequency_hz);
  REQUIRE(channel.damping_ratio);
  const double f = truth["dominant_frequency_hz"], zeta = truth["damping_ratio"];
  CHECK(std::abs(channel.dominant_frequency_hz->value - f) <=
        sigmas * channel.dominant_frequency_hz->sigma + 1e-6 * f);
  CHECK(std::abs(channel.damping_ratio->value - zeta) <=
        sigmas * channel.damping_ratio->sigma + 1e-6 * zeta);
  CHECK_FALSE(channel.frequency_mismatch);
}

void CheckImpact(const SourceAnalysis& source, const nlohmann::json& truth, double rate_hz) {
  REQUIRE(source.impact.found);
  const double error_samples =
      std::abs(source.impact.time_s.value - truth["impact_time_s"].get<double>()) * rate_hz;
  CHECK(error_samples <= 2.0);
}

TEST_CASE("The generated pair: impact within 2 samples, modes within 4 sigma of truth",
          "[log_analysis]") {
  const Generated generated;
  const LogAnalysis analysis = AnalyseLog(generated.log, LogFileRecords(generated.log, {}), {});
  REQUIRE(analysis.ok);
  REQUIRE(analysis.simulation);
  const nlohmann::json& truth = generated.truth;
  CheckImpact(analysis.experiment, truth["experiment"], 1000.0);
  CheckImpact(*analysis.simulation, truth["simulation"], 1000.0);
  for (const char* name : {"q1", "a1", "a2"}) {
    CheckAgainstTruth(Channel(analysis.experiment, name), truth["experiment"]["channels"][name],
                      4.0);
    CheckAgainstTruth(Channel(*analysis.simulation, name), truth["simulation"]["channels"][name],
                      4.0);
  }
  const ChannelAnalysis& a1 = Channel(analysis.experiment, "a1");
  CHECK(a1.units == "m/s^2");
  CHECK(a1.frequency_source == "fit");
  CHECK(a1.spectra.size() == 3);
  CHECK(a1.series.value.size() <= LogAnalysisOptions{}.plot_points);
  CHECK(std::abs(a1.fft_frequency_hz - a1.dominant_frequency_hz->value) < 0.05);
}

TEST_CASE("The comparison: frequency differences and the impact offset as in truth",
          "[log_analysis]") {
  const Generated generated;
  const LogAnalysis analysis = AnalyseLog(generated.log, LogFileRecords(generated.log, {}), {});
  REQUIRE(analysis.comparison);
  const LogComparison& comparison = *analysis.comparison;
  REQUIRE(comparison.impact_offset_s);
  CHECK(comparison.impact_offset_s->value ==
        Approx(generated.truth["impact_offset_s"].get<double>()).margin(2e-3));
  const double f_exp = generated.truth["experiment"]["channels"]["a1"]["dominant_frequency_hz"];
  const double f_sim = generated.truth["simulation"]["channels"]["a1"]["dominant_frequency_hz"];
  for (const ChannelComparison& row : comparison.channels) {
    INFO("channel " << row.channel);
    CHECK(row.frequency_difference_hz == Approx(f_sim - f_exp).margin(0.1));
    CHECK(row.frequency_difference_percent == Approx(100.0 * (f_sim - f_exp) / f_exp).margin(1.0));
    CHECK(row.overlap_s > 4.0);
  }
  // Aligning the impacts brings the angle histories together.
  CHECK(comparison.channels[0].channel == "q1");
  CHECK(comparison.channels[0].rms_difference <
        0.5 * comparison.channels[0].rms_difference_unaligned);
  CHECK_THAT(analysis.Brief(), Contains("impact offset"));
}

TEST_CASE("Bad rows are reported with their lines and change nothing else", "[log_analysis]") {
  BeamLogOptions options;
  options.inject_defects = true;
  const Generated generated(options);
  const LogAnalysis analysis = AnalyseLog(generated.log, LogFileRecords(generated.log, {}), {});
  REQUIRE(analysis.ok);
  const LogReadReport& read = analysis.experiment.read;
  CHECK(read.dropped_rows == 2);    // the NaN row and the duplicate
  CHECK(read.filled_samples == 2);  // the NaN row's sample and the missing row
  for (const nlohmann::json& defect : generated.truth["defects"]) {
    if (!defect.contains("line")) continue;
    const long long line = defect["line"];
    CHECK(std::any_of(read.issues.begin(), read.issues.end(),
                      [&](const LogIssue& issue) { return issue.line == line; }));
  }
  CheckImpact(analysis.experiment, generated.truth["experiment"], 1000.0);
  CheckAgainstTruth(Channel(analysis.experiment, "a1"),
                    generated.truth["experiment"]["channels"]["a1"], 4.0);
}

TEST_CASE("A log decimated to fit the memory budget gives the same answers", "[log_analysis]") {
  const Generated generated;
  LogAnalysisOptions options;
  options.max_analysis_samples = 1024;  // 5000 rows: decimated by 5
  const LogAnalysis analysis =
      AnalyseLog(generated.log, LogFileRecords(generated.log, {}), options);
  REQUIRE(analysis.ok);
  CHECK(analysis.experiment.decimation == 5);
  CHECK(analysis.experiment.sample_rate_hz == Approx(1000.0));
  // The instant comes from the full-rate second pass.
  CheckImpact(analysis.experiment, generated.truth["experiment"], 1000.0);
  CheckImpact(*analysis.simulation, generated.truth["simulation"], 1000.0);
  CheckAgainstTruth(Channel(analysis.experiment, "a1"),
                    generated.truth["experiment"]["channels"]["a1"], 4.0);
  CheckAgainstTruth(Channel(*analysis.simulation, "a1"),
                    generated.truth["simulation"]["channels"]["a1"], 4.0);
}

TEST_CASE("An unreadable log is a failed result naming the file", "[log_analysis]") {
  Generated generated;
  fs::remove(generated.log.experiment);
  const LogAnalysis analysis = AnalyseLog(generated.log, LogFileRecords(generated.log, {}), {});
  CHECK_FALSE(analysis.ok);
  CHECK_FALSE(analysis.ok);
  CHECK_THAT(analysis.reason, Contains("case1-experiment.csv"));
  LogAnalysisOptions bad;
  bad.max_fit_samples = 1;
  CHECK_THROWS_AS(AnalyseLog(generated.log, LogFileRecords(generated.log, {}), bad),
                  std::invalid_argument);
}

TEST_CASE("The sample session sample_data/logs-two-link matches its truth file", "[log_analysis]") {
  const fs::path folder = fs::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "logs-two-link";
  const ManifestReadResult manifest = ReadManifest(folder);
  CHECK(manifest.warnings.empty());
  REQUIRE(manifest.session.logs.size() == 1);
  nlohmann::json truth;
  std::ifstream(folder.string() + ".truth.json") >> truth;
  const LogAnalysis analysis =
      AnalyseLog(manifest.session.logs[0], LogFileRecords(manifest.session.logs[0], {}), {});
  REQUIRE(analysis.ok);
  // Written by `impactlab simulate two-link` (docs/two-link.md): the truth
  // has each source's first impact. The experiment's hidden differences
  // (sample_data/two-link/experiment.toml) were chosen to give the document's
  // comparison: the first beam rings at 10.96 Hz measured against 11.53-11.59
  // Hz simulated, and the impact comes about 0.07 s late.
  const double rate = truth["sample_rate_hz"];
  CheckImpact(analysis.experiment, truth["case1"]["experiment"], rate);
  CheckImpact(*analysis.simulation, truth["case1"]["simulation"], rate);
  const auto a1_frequency_hz = [](const SourceAnalysis& source) {
    const ChannelAnalysis& a1 = Channel(source, "a1");
    REQUIRE(a1.dominant_frequency_hz);
    return a1.dominant_frequency_hz->value;
  };
  CHECK_THAT(a1_frequency_hz(analysis.experiment), WithinAbs(10.96, 0.2));
  CHECK_THAT(a1_frequency_hz(*analysis.simulation), WithinAbs(11.56, 0.2));
  const double impact_delay_s = truth["case1"]["experiment"]["impact_time_s"].get<double>() -
                                truth["case1"]["simulation"]["impact_time_s"].get<double>();
  CHECK_THAT(impact_delay_s, WithinAbs(0.07, 0.01));
}

TEST_CASE("Log analysis options: the defaults pass Check", "[log_analysis]") {
  std::string error;
  CHECK(LogAnalysisOptions{}.Check(&error));
  LogAnalysisOptions bad;
  bad.max_analysis_samples = 10;
  CHECK_FALSE(bad.Check(&error));
  CHECK_THAT(error, Contains("max_analysis_samples"));
}

TEST_CASE("The analysis reads only the records it is handed, never a file itself",
          "[log_analysis]") {
  const Generated generated;
  const LogAnalysis from_files = AnalyseLog(generated.log, LogFileRecords(generated.log, {}), {});
  REQUIRE(from_files.ok);
  // The experiment's record held in memory, served in blocks of 333 samples;
  // the manifest's files moved away.
  const LogSeries series =
      ReadLogSeries(generated.log.folder / generated.log.experiment, generated.log.time_column,
                    generated.log.channels, LogSource::kExperiment);
  Log moved = generated.log;
  moved.experiment = "nowhere.csv";
  moved.simulation.reset();
  int reads = 0;
  const LogRecord in_memory = [&](const LogBlockCallback& on_block) {
    ++reads;
    const std::size_t n = series.time_s.size();
    for (std::size_t first = 0; first < n; first += 333) {
      const std::size_t end = std::min(n, first + 333);
      LogBlock block;
      block.first_sample = static_cast<long long>(first);
      block.sample_interval_s = series.report.sample_interval_s;
      block.estimated_samples = static_cast<long long>(n);
      block.time_s.assign(series.time_s.begin() + first, series.time_s.begin() + end);
      for (const auto& channel : series.values) {
        block.values.emplace_back(channel.begin() + first, channel.begin() + end);
      }
      on_block(block);
    }
    return series.report;
  };
  const LogAnalysis analysis = AnalyseLog(moved, {in_memory, std::nullopt}, {});
  REQUIRE(analysis.ok);
  CHECK(reads == 1);  // whole at once: no second pass without decimation
  CHECK_FALSE(analysis.simulation.has_value());
  CHECK(analysis.experiment.impact.time_s.value == from_files.experiment.impact.time_s.value);
  REQUIRE(analysis.experiment.channels.size() == from_files.experiment.channels.size());
  for (std::size_t c = 0; c < analysis.experiment.channels.size(); ++c) {
    const ChannelAnalysis &a = analysis.experiment.channels[c],
                          &b = from_files.experiment.channels[c];
    REQUIRE(a.dominant_frequency_hz.has_value() == b.dominant_frequency_hz.has_value());
    if (a.dominant_frequency_hz) {
      CHECK(a.dominant_frequency_hz->value == b.dominant_frequency_hz->value);
    }
  }
}

}  // namespace
}  // namespace impactlab
