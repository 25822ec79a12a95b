// The report's opening "check these" list and the logs' flags, as a user
// reads them in every format, against what the sample sessions are known to
// hold: the two-link logs' channels without oscillation (q1, a4), their
// FFT/fit mismatches and the experiment's a2 without a spectral peak; a
// prediction whose source run is misspelled.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "report/html_report.h"
#include "report/tables.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
// Named, not anonymous: the unity build joins this folder's tests, whose
// helpers share names.
namespace check_list_test {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;

const fs::path kSamples = fs::path(IMPACTLAB_SOURCE_DIR) / "sample_data";

const SessionResult& Logs() {
  static const SessionResult result =
      ReduceSession(ReadManifest(kSamples / "logs-two-link").session, {});
  return result;
}

const Table& Named(const std::vector<Table>& tables, const std::string& name) {
  for (const Table& t : tables) {
    if (t.name == name) return t;
  }
  FAIL("no table " << name);
  return tables.front();
}

std::size_t ColumnOf(const Table& t, const std::string& name) {
  const auto at = std::find(t.columns.begin(), t.columns.end(), name);
  REQUIRE(at != t.columns.end());
  return static_cast<std::size_t>(at - t.columns.begin());
}

const std::vector<Cell>& RowOf(const Table& t, const std::string& first) {
  for (const auto& row : t.rows) {
    if (row.at(0).text == first) return row;
  }
  FAIL("no row " << first << " in " << t.name);
  return t.rows.front();
}

// Every format of the report, as `impactlab report` writes it.
std::vector<std::pair<std::string, std::string>> AllFormats(const SessionResult& r) {
  const std::vector<Table> tables = BuildTables(r);
  return {{"md", RenderTables(r.title, tables, ReportFormat::kMarkdown)},
          {"csv", RenderTables(r.title, tables, ReportFormat::kCsv)},
          {"tex", RenderTables(r.title, tables, ReportFormat::kLatex)},
          {"html", RenderHtmlReport(r)}};
}

TEST_CASE("check_list: the logs sample's flags open every format, linked to their table") {
  const std::vector<Table> tables = BuildTables(Logs());
  REQUIRE_FALSE(tables.empty());
  const Table& check = tables.front();
  CHECK(check.name == "check_these");
  std::string items;
  for (const auto& row : check.rows) {
    items += row[0].text + "\n";
    CHECK(row[1].link == "table-log_case1");
  }
  CHECK_THAT(items, Contains("no oscillation, so no dominant frequency, on q1 (both)"));
  CHECK_THAT(items, Contains("a4 (both)"));
  CHECK_THAT(items, Contains("the FFT peak and the fitted frequency disagree on a1 (experiment), "
                             "a2 (simulation), a3 (experiment) and a4 (both)"));
  CHECK_THAT(items, Contains("no spectral peak above the noise (the fitted mode is used) on a2 "
                             "(experiment)"));
  for (const auto& [format, text] : AllFormats(Logs())) {
    INFO(format);
    // The list comes before any other table.
    const std::size_t list = text.find("no oscillation, so no dominant frequency");
    REQUIRE(list != std::string::npos);
    CHECK(list < text.find("dominant frequencies and damping, experiment against"));
    CHECK_THAT(text, Contains("disagree on a1 (experiment)"));
    // Each flag in words: the notes table (the HTML's table of them too).
    CHECK_THAT(text, Contains("FFT peak 10.693 Hz and fitted 10.85 Hz disagree"));
    CHECK_THAT(text, Contains("no spectral peak above the noise; the fit's strongest"));
  }
  const auto formats = AllFormats(Logs());
  CHECK_THAT(formats[0].second, Contains("[log\\_case1](#table-log_case1)"));
  CHECK_THAT(formats[0].second, Contains("<a id=\"table-log_case1\"></a>"));
  CHECK_THAT(formats[2].second, Contains("Table~\\ref{tab:log_case1}"));
  CHECK_THAT(formats[3].second, Contains("<a href=\"#table-log_case1\">log_case1</a>"));
}

TEST_CASE("check_list: a channel with no oscillation has no frequency and says so") {
  const std::vector<Table> tables = BuildTables(Logs());
  const Table& t = Named(tables, "log_case1");
  const auto& q1 = RowOf(t, "q1");
  CHECK(q1.at(ColumnOf(t, "Experiment f (Hz)")).text == "none");
  CHECK(q1.at(ColumnOf(t, "Simulation f (Hz)")).text == "none");
  CHECK(q1.at(ColumnOf(t, "Difference (%)")).text == "-");
  CHECK(q1.at(ColumnOf(t, "Flags")).text == "no oscillation (both)");
  // a1, the mid-beam accelerometer, oscillates: its frequencies stay.
  const auto& a1 = RowOf(t, "a1");
  REQUIRE(a1.at(ColumnOf(t, "Experiment f (Hz)")).value);
  CHECK(*a1.at(ColumnOf(t, "Experiment f (Hz)")).value == Approx(10.850).margin(0.01));
  CHECK(a1.at(ColumnOf(t, "Flags")).text ==
        "FFT/fit mismatch (experiment); ring-down fit caveat (experiment)");
  // CSV: an empty cell, no text, where q1's frequency would be.
  const std::string csv = RenderTable(t, ReportFormat::kCsv);
  CHECK_THAT(csv, Contains("\nq1,,,,,,,,,,,"));
  CHECK(csv.find("none") == std::string::npos);
  // The note says why, in words.
  const Table& notes = Named(tables, "log_case1_notes");
  bool said = false;
  for (const auto& row : notes.rows) {
    said = said || (row[0].text == "q1" && row[2].text.rfind("no oscillation: ", 0) == 0);
  }
  CHECK(said);
}

TEST_CASE("check_list: impact instants compared like with like, the offset in the CSV") {
  const std::vector<Table> tables = BuildTables(Logs());
  const Table& t = Named(tables, "log_case1_impact");
  const auto& experiment = RowOf(t, "experiment");
  const auto& simulation = RowOf(t, "simulation");
  const auto& simulation_compared = RowOf(t, "simulation, compared");
  const auto& offset = RowOf(t, "simulation - experiment");
  // The simulation's strongest jump is a4's, the experiment's a3's: both are
  // compared on a3, and the simulation's own instant has a row of its own.
  CHECK(experiment.at(2).text == "accelerometer a3");
  CHECK(simulation.at(2).text == "accelerometer a4");
  CHECK(simulation_compared.at(2).text == "accelerometer a3");
  CHECK(offset.at(2).text == "accelerometer a3 in both");
  REQUIRE(offset.at(1).value);
  CHECK(*offset.at(1).value == Approx(*simulation_compared.at(1).value - *experiment.at(1).value));
  // Truth: 1.687047 - 1.758973 s; each instant within half a sample.
  CHECK(*offset.at(1).value == Approx(-0.07193).margin(0.001));
  const std::string csv = RenderTable(t, ReportFormat::kCsv);
  CHECK_THAT(csv, Contains("Source,Impact time (s),Impact time (s) std_error,Found by"));
  CHECK_THAT(csv, Contains(fmt::format("simulation - experiment,{},", *offset.at(1).value)));
}

TEST_CASE("check_list: a misspelled prediction is in the list in every format") {
  testing::TempDir dir;
  const fs::path session = dir.path() / "thesis";
  fs::copy(kSamples / "thesis-1969", session, fs::copy_options::recursive);
  std::stringstream text;
  text << std::ifstream(session / "session.toml").rdbuf();
  std::string toml = text.str();
  const std::string right = "source_run = \"0.323\"";
  REQUIRE(toml.find(right) != std::string::npos);
  toml.replace(toml.find(right), right.size(), "source_run = \"0.32\"");
  std::ofstream(session / "session.toml") << toml;

  const SessionResult r = ReduceSession(ReadManifest(session).session, {});
  CHECK(r.predictions.empty());
  for (const auto& [format, report] : AllFormats(r)) {
    INFO(format);
    CHECK_THAT(report, Contains("prediction") && Contains("skipped"));
    CHECK_THAT(report, Contains("0.32"));
    CHECK(report.find("prediction") < report.find("Deviation of theoretical response"));
  }
}

TEST_CASE("check_list: a failed run is linked to its section and its status row") {
  SessionResult r;
  RunResult run;
  run.id = "0.405";
  run.reason = "session.toml:12: run \"0.405\".photo: expected an existing file";
  r.runs = {run};
  const std::vector<CheckItem> items = CheckList(r);
  REQUIRE(items.size() == 1);
  CHECK_THAT(items[0].text, Catch::StartsWith("run 0.405 failed: session.toml:12"));
  CHECK(items[0].section == "run-0.405");
  CHECK(items[0].table == "kelvin_voigt_parameters");
  const std::string html = RenderHtmlReport(r);
  CHECK_THAT(html, Contains("<a href=\"#run-0.405\">run 0.405 failed"));
  CHECK(html.find("run 0.405 failed") < html.find("<h2 id=\"summary\">"));
}

TEST_CASE("check_list: nothing to check says so") {
  const SessionResult r;
  CHECK(CheckList(r).empty());
  const std::vector<Table> tables = BuildTables(r);
  REQUIRE(tables.size() == 1);
  CHECK_THAT(tables[0].rows.at(0).at(0).text, Catch::StartsWith("Nothing"));
}

}  // namespace check_list_test
}  // namespace impactlab
