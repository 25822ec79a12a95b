// Tests of the log reader: unit conversion against the closed forms, and every
// reading rule (io/log_reader.h) applied and reported with its line.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/errors.h"
#include "io/log_reader.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using testing::TempDir;

LogChannel Encoder(const std::string& name, const std::string& column, double cpr, double gear) {
  LogChannel c;
  c.name = name;
  c.column = column;
  c.counts_per_rev = cpr;
  c.gear_ratio = gear;
  return c;
}

LogChannel Accelerometer(const std::string& name, const std::string& column, double v_per_g) {
  LogChannel c;
  c.name = name;
  c.column = column;
  c.sensitivity = v_per_g;
  return c;
}

LogChannel Plain(const std::string& name) {
  LogChannel c;
  c.name = name;
  c.column = name;
  return c;
}

fs::path Write(const TempDir& dir, const std::string& text) {
  const fs::path path = dir.path() / "log.csv";
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// `rows` rows of "t,x" at 1 ms with x = 2 t, after the header.
std::string Ramp(int rows) {
  std::string text = "t,x\n";
  for (int i = 0; i < rows; ++i) text += fmt::format("{:.3f},{:.6f}\n", i * 1e-3, 2e-3 * i);
  return text;
}

// The line of the row holding sample i of Ramp (the header is line 1).
long long LineOf(int i) { return i + 2; }

// Replaces the whole line `line` (1-based) of `text`.
std::string ReplaceLine(const std::string& text, long long line, const std::string& with) {
  std::size_t begin = 0;
  for (long long l = 1; l < line; ++l) begin = text.find('\n', begin) + 1;
  const std::size_t end = text.find('\n', begin);
  return text.substr(0, begin) + with + text.substr(end);
}

std::string DropLine(const std::string& text, long long line) {
  std::size_t begin = 0;
  for (long long l = 1; l < line; ++l) begin = text.find('\n', begin) + 1;
  return text.substr(0, begin) + text.substr(text.find('\n', begin) + 1);
}

const LogIssue* FindIssue(const LogReadReport& report, LogIssueKind kind) {
  for (const LogIssue& issue : report.issues) {
    if (issue.kind == kind) return &issue;
  }
  return nullptr;
}

TEST_CASE("Encoder counts become radians and accelerometer volts m/s^2", "[log_reader]") {
  TempDir dir;
  const fs::path file = Write(dir,
                              "time,enc,acc,other\n"
                              "0.0,1000,0.05,7\n"
                              "0.1,-2048,-0.2,8\n"
                              "0.2,0,0,9\n");
  const std::vector<LogChannel> channels = {Encoder("q1", "enc", 4096, 50),
                                            Accelerometer("a1", "acc", 0.1), Plain("other")};
  const LogSeries series = ReadLogSeries(file, "time", channels, LogSource::kExperiment);
  REQUIRE(series.time_s.size() == 3);
  const double rad_per_count = 2.0 * std::numbers::pi / (4096.0 * 50.0);
  CHECK(series.values[0][0] == Approx(1000 * rad_per_count).epsilon(1e-15));
  CHECK(series.values[0][1] == Approx(-2048 * rad_per_count).epsilon(1e-15));
  CHECK(series.values[1][0] == Approx(0.5 * kStandardGravity).epsilon(1e-15));
  CHECK(series.values[1][1] == Approx(-2.0 * kStandardGravity).epsilon(1e-15));
  CHECK(series.values[2][1] == 8.0);  // neither key: SI as it stands
  CHECK(series.report.sample_interval_s == Approx(0.1));
  CHECK(series.report.IssueCount() == 0);
}

TEST_CASE("A simulation log is taken in SI as it stands", "[log_reader]") {
  TempDir dir;
  const fs::path file = Write(dir, "t,enc,acc\n0,0.25,-3.5\n0.001,0.5,4\n");
  const LogSeries series =
      ReadLogSeries(file, "t", {Encoder("q1", "enc", 4096, 1), Accelerometer("a1", "acc", 0.1)},
                    LogSource::kSimulation);
  CHECK(series.values[0][1] == 0.5);
  CHECK(series.values[1][0] == -3.5);
}

TEST_CASE("Blank, comment and CRLF lines, quoted names and extra columns are accepted",
          "[log_reader]") {
  TempDir dir;
  const fs::path file = Write(dir,
                              "# logger v2\r\n"
                              "\"t\", \"x\" ,unused\r\n"
                              "0, 1.5 ,zz\r\n"
                              "\r\n"
                              "# a pause\r\n"
                              "+0.001,2,zz\r\n"
                              "0.002,3");  // no newline at the end
  const LogSeries series = ReadLogSeries(file, "t", {Plain("x")}, LogSource::kSimulation);
  CHECK(series.values[0] == std::vector<double>{1.5, 2.0, 3.0});
  CHECK(series.report.data_rows == 3);
}

TEST_CASE("A missing column is refused with the file, the key and line 1", "[log_reader]") {
  TempDir dir;
  const fs::path file = Write(dir, Ramp(10));
  try {
    ReadLogSeries(file, "t", {Plain("x"), Accelerometer("a2", "acc2", 0.005)},
                  LogSource::kExperiment);
    FAIL("expected an InputError");
  } catch (const InputError& error) {
    CHECK(error.where().file == file);
    CHECK(error.where().key == "channels.a2");
    CHECK(error.where().line == 1);
    CHECK_THAT(error.problem(), Contains("acc2") && Contains("t,x"));
  }
  CHECK_THROWS_AS(ReadLogSeries(file, "time", {Plain("x")}, LogSource::kExperiment), InputError);
  CHECK_THROWS_AS(ReadLogSeries(dir.path() / "none.csv", "t", {}, LogSource::kExperiment),
                  InputError);
}

TEST_CASE("A NaN row is dropped, reported with its line, and its sample interpolated",
          "[log_reader]") {
  TempDir dir;
  const std::string text = ReplaceLine(Ramp(300), LineOf(100), "0.100,nan");
  const LogSeries series =
      ReadLogSeries(Write(dir, text), "t", {Plain("x")}, LogSource::kSimulation);
  REQUIRE(series.time_s.size() == 300);
  CHECK(series.values[0][100] == Approx(0.2).epsilon(1e-12));  // linear: exact on a ramp
  CHECK(series.report.dropped_rows == 1);
  CHECK(series.report.filled_samples == 1);
  const LogIssue* bad = FindIssue(series.report, LogIssueKind::kBadValue);
  REQUIRE(bad != nullptr);
  CHECK(bad->line == LineOf(100));
  CHECK(bad->column == "x");
  CHECK_THAT(bad->detail, Contains("nan"));
  const LogIssue* gap = FindIssue(series.report, LogIssueKind::kMissingSamples);
  REQUIRE(gap != nullptr);
  CHECK(gap->line == LineOf(101));
  CHECK_THAT(series.report.Summary(), Contains(fmt::format("log.csv:{}: x:", LineOf(100))));
}

TEST_CASE("Text, empty fields and short rows are bad values too", "[log_reader]") {
  TempDir dir;
  std::string text = Ramp(400);
  text = ReplaceLine(text, LineOf(10), "0.010,abc");
  text = ReplaceLine(text, LineOf(20), "0.020,");
  text = ReplaceLine(text, LineOf(30), "0.030");
  text = ReplaceLine(text, LineOf(40), "0.040,inf");
  const LogSeries series = ReadLogSeries(Write(dir, text), "t", {Plain("x")},
                                         LogSource::kSimulation, {.max_bad_fraction = 0.02});
  CHECK(series.report.issue_counts[static_cast<int>(LogIssueKind::kBadValue)] == 4);
  CHECK(series.time_s.size() == 400);
}

TEST_CASE("A duplicated time keeps the first row and reports the second", "[log_reader]") {
  TempDir dir;
  std::string text = Ramp(300);
  text = ReplaceLine(text, LineOf(50), "0.049,999");  // same time as row 49, other value
  const LogSeries series =
      ReadLogSeries(Write(dir, text), "t", {Plain("x")}, LogSource::kSimulation);
  const LogIssue* duplicate = FindIssue(series.report, LogIssueKind::kDuplicateTime);
  REQUIRE(duplicate != nullptr);
  CHECK(duplicate->line == LineOf(50));
  CHECK(series.values[0][49] == Approx(0.098));
  // Row 50 is lost, so sample 50 is interpolated between rows 49 and 51.
  CHECK(series.values[0][50] == Approx(0.1));
  CHECK(series.time_s.size() == 300);
}

TEST_CASE("Time going back drops the row and reports it", "[log_reader]") {
  TempDir dir;
  std::string text = Ramp(300);
  text = ReplaceLine(text, LineOf(60), "0.010,5");
  const LogSeries series =
      ReadLogSeries(Write(dir, text), "t", {Plain("x")}, LogSource::kSimulation);
  const LogIssue* back = FindIssue(series.report, LogIssueKind::kBackwardTime);
  REQUIRE(back != nullptr);
  CHECK(back->line == LineOf(60));
  CHECK(series.report.dropped_rows == 1);
  for (std::size_t i = 1; i < series.time_s.size(); ++i) {
    REQUIRE(series.time_s[i] > series.time_s[i - 1]);
  }
}

TEST_CASE("Missing samples are interpolated up to the limit and refused beyond it",
          "[log_reader]") {
  TempDir dir;
  std::string text = Ramp(300);
  for (int i = 103; i >= 100; --i) text = DropLine(text, LineOf(i));  // 4 rows missing
  const LogSeries series =
      ReadLogSeries(Write(dir, text), "t", {Plain("x")}, LogSource::kSimulation);
  CHECK(series.time_s.size() == 300);
  CHECK(series.report.filled_samples == 4);
  CHECK(series.values[0][102] == Approx(0.204).epsilon(1e-12));
  CHECK(series.time_s[102] == Approx(0.102).epsilon(1e-12));
  CHECK(series.report.dropped_rows == 0);

  try {
    ReadLogSeries(Write(dir, text), "t", {Plain("x")}, LogSource::kSimulation,
                  {.max_fill_samples = 3});
    FAIL("expected an InputError");
  } catch (const InputError& error) {
    CHECK(error.where().line == LineOf(100));  // the row after the gap, before rows shifted
    CHECK_THAT(error.problem(), Contains("4 missing samples"));
  }
}

TEST_CASE("Jittered time stamps are reported as irregular and kept", "[log_reader]") {
  TempDir dir;
  std::string text = Ramp(300);
  text = ReplaceLine(text, LineOf(150), "0.1504,0.3");  // 0.4 interval late
  const LogSeries series =
      ReadLogSeries(Write(dir, text), "t", {Plain("x")}, LogSource::kSimulation);
  CHECK(series.time_s.size() == 300);
  const LogIssue* irregular = FindIssue(series.report, LogIssueKind::kIrregularStep);
  REQUIRE(irregular != nullptr);
  CHECK(irregular->line == LineOf(150));
  CHECK(series.time_s[150] == 0.1504);
}

TEST_CASE("Too many bad rows refuse the log", "[log_reader]") {
  TempDir dir;
  std::string text = Ramp(300);
  for (int i = 10; i < 20; i += 2)
    text = ReplaceLine(text, LineOf(i), fmt::format("{},x", i * 1e-3));
  try {
    ReadLogSeries(Write(dir, text), "t", {Plain("x")}, LogSource::kSimulation);
    FAIL("expected an InputError");
  } catch (const InputError& error) {
    CHECK_THAT(error.problem(), Contains("5 of 300 rows were dropped"));
  }
}

TEST_CASE("Blocks are bounded, in order, and cover the log once", "[log_reader]") {
  TempDir dir;
  const fs::path file = Write(dir, Ramp(10000));
  std::size_t largest = 0;
  long long next = 0;
  double last_time = -1.0;
  auto on_block = [&](const LogBlock& block) {
    largest = std::max(largest, block.time_s.size());
    CHECK(block.first_sample == next);
    next += static_cast<long long>(block.time_s.size());
    CHECK(block.time_s.front() > last_time);
    last_time = block.time_s.back();
    CHECK(block.estimated_samples >= next);
    CHECK(std::abs(block.estimated_samples - 10000) < 200);  // known from the first block on
  };
  const LogReadReport report =
      ReadLogCsv(file, "t", {Plain("x")}, LogSource::kSimulation, {.block_rows = 777}, on_block);
  CHECK(largest == 777);
  CHECK(next == 10000);
  CHECK(report.samples == 10000);
  CHECK(report.mean_interval_s == Approx(1e-3).epsilon(1e-12));
}

TEST_CASE("Log read options: the defaults pass Check and nonsense is refused", "[log_reader]") {
  std::string error;
  CHECK(LogReadOptions{}.Check(&error));
  CHECK_FALSE(LogReadOptions{.block_rows = 0}.Check(&error));
  CHECK_FALSE(LogReadOptions{.jitter_tolerance = 0.6}.Check(&error));
  CHECK_FALSE(LogReadOptions{.max_bad_fraction = 2.0}.Check(&error));
  TempDir dir;
  CHECK_THROWS_AS(ReadLogSeries(Write(dir, Ramp(10)), "t", {Plain("x")}, LogSource::kSimulation,
                                {.rate_estimate_rows = 1}),
                  std::invalid_argument);
}

}  // namespace
}  // namespace impactlab
