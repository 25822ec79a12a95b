// The exports as a reader of a paper's tables uses them: tidy CSV (numbers
// at full precision, each standard error in its own column, no text where a
// number belongs) and LaTeX with booktabs and siunitx.
#include <cmath>
#include <cstdlib>
#include <string>

#include <fmt/format.h>
#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "report/tables.h"
#include "tests/report/thesis_result.h"

namespace impactlab {
namespace {

using testing::Thesis;

const Table& Named(const std::vector<Table>& tables, const std::string& name) {
  for (const Table& t : tables) {
    if (t.name == name) return t;
  }
  FAIL("no table " << name);
  return tables.front();
}

std::size_t ColumnOf(const std::vector<std::string>& columns, const std::string& name) {
  const auto at = std::find(columns.begin(), columns.end(), name);
  REQUIRE(at != columns.end());
  return static_cast<std::size_t>(at - columns.begin());
}

// The whole cell is one number (strtod reads all of it).
bool IsNumber(const std::string& cell) {
  if (cell.empty()) return false;
  char* end = nullptr;
  std::strtod(cell.c_str(), &end);
  return end == cell.c_str() + cell.size();
}

TEST_CASE("exports: CSV holds each estimate and its standard error, exactly, in two columns") {
  const SessionResult r = Thesis();
  const std::vector<Table> tables = BuildTables(r);
  const Table& t = Named(tables, "kelvin_voigt_parameters");
  const std::vector<std::string> columns = TidyColumns(t);
  const std::size_t zeta = ColumnOf(columns, "zeta");
  CHECK(columns.at(zeta + 1) == "zeta std_error");
  const auto rows = TidyRows(t);
  REQUIRE(rows.size() == r.runs.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    INFO("run " << r.runs[i].id);
    REQUIRE(rows[i].size() == columns.size());
    const Estimate& truth = r.runs[i].fits.kelvin_voigt->damping_ratio;
    // Read back, the very doubles of the results: no rounding on the way.
    CHECK(std::stod(rows[i][zeta]) == truth.value);
    CHECK(std::stod(rows[i][zeta + 1]) == truth.sigma);
  }
}

TEST_CASE("exports: no CSV column mixes numbers and text") {
  const SessionResult r = Thesis();
  for (const Table& t : BuildTables(r)) {
    const std::vector<std::string> columns = TidyColumns(t);
    const auto rows = TidyRows(t);
    // A column holding a number anywhere holds one, or nothing, everywhere.
    std::size_t tidy = 0;
    for (std::size_t c = 0; c < t.columns.size(); ++c, ++tidy) {
      const bool numeric = std::any_of(t.rows.begin(), t.rows.end(),
                                       [&](const auto& row) { return row[c].value.has_value(); });
      const bool with_sigma =
          tidy + 1 < columns.size() && columns[tidy + 1] == t.columns[c] + " std_error";
      if (!numeric) continue;
      for (const auto& row : rows) {
        INFO(t.name << ": " << columns[tidy] << " = \"" << row[tidy] << "\"");
        CHECK((row[tidy].empty() || IsNumber(row[tidy])));
        if (with_sigma) CHECK((row[tidy + 1].empty() || IsNumber(row[tidy + 1])));
      }
      if (with_sigma) ++tidy;
    }
  }
}

TEST_CASE("exports: LaTeX uses booktabs rules, siunitx numbers, a label and a caption") {
  const SessionResult r = Thesis();
  const std::vector<Table> tables = BuildTables(r);
  const std::string tex =
      RenderTable(Named(tables, "kelvin_voigt_parameters"), ReportFormat::kLatex);
  CHECK_THAT(tex, Catch::Contains("\\toprule") && Catch::Contains("\\midrule") &&
                      Catch::Contains("\\bottomrule") &&
                      Catch::Contains("\\label{tab:kelvin_voigt_parameters}") &&
                      Catch::Contains("\\caption{"));
  CHECK(tex.find("\\hline") == std::string::npos);
  // zeta of the first run as value(error in its last digits), both as printed elsewhere.
  const Estimate& zeta = r.runs[0].fits.kelvin_voigt->damping_ratio;
  const Cell& cell = Named(tables, "kelvin_voigt_parameters").rows[0][2];
  REQUIRE(cell.decimals >= 0);
  const long long last = std::llround(zeta.sigma * std::pow(10.0, cell.decimals));
  CHECK(last >= 10);  // two significant digits of the error
  CHECK_THAT(tex,
             Catch::Contains(fmt::format("\\num{{{:.{}f}({})}}", zeta.value, cell.decimals, last)));
}

TEST_CASE("exports: a log channel with a frequency in one source only has no difference") {
  // signal/log_analysis.cpp leaves the difference NaN when either source has
  // no dominant frequency; the table says so with a dash.
  LogResult log;
  log.id = "case1";
  log.ok = true;
  LogChannelResult measured;
  measured.channel = "a2";
  measured.units = "m/s^2";
  LogChannelResult simulated = measured;
  simulated.dominant_frequency_hz = Estimate{31.03, 0.10};
  log.sources = {{"experiment", {}, "", {measured}}, {"simulation", {}, "", {simulated}}};
  LogComparisonRow row;
  row.channel = "a2";
  row.units = "m/s^2";
  row.difference_hz = row.difference_percent = std::nan("");
  row.rms_difference = 0.99;
  log.comparison = {row};
  SessionResult r;
  r.logs = {log};
  const std::vector<Table> tables = BuildTables(r);
  const Table& t = Named(tables, "log_case1");
  REQUIRE(t.rows.size() == 1);
  const std::vector<Cell>& cells = t.rows[0];
  CHECK(cells.at(ColumnOf(t.columns, "Simulation f (Hz)")).text.find("31.03") == 0);
  CHECK(cells.at(ColumnOf(t.columns, "Difference (Hz)")).text == "-");
  CHECK(cells.at(ColumnOf(t.columns, "Difference (%)")).text == "-");
  const std::string markdown = RenderTable(t, ReportFormat::kMarkdown);
  CHECK(markdown.find("+nan") == std::string::npos);
  CHECK(markdown.find("| nan") == std::string::npos);
}

}  // namespace
}  // namespace impactlab
