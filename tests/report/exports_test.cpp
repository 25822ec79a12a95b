// The exports as a reader of a paper's tables uses them: tidy CSV (numbers
// at full precision, each standard error in its own column, no text where a
// number belongs) and LaTeX with booktabs and siunitx.
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <catch2/catch.hpp>

#include "io/errors.h"
#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "report/tables.h"
#include "tests/report/thesis_result.h"
#include "tests/support/sample_data.h"
#include "tests/support/temp_dir.h"

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
    std::size_t tidy = t.row_kinds.empty() ? 0 : 1;
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

// The cells of a tidy CSV table by column name.
struct Tidy {
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
  const std::string& At(std::size_t row, const std::string& column) const {
    return rows.at(row).at(ColumnOf(columns, column));
  }
};
Tidy TidyOf(const Table& t) { return {TidyColumns(t), TidyRows(t)}; }

TEST_CASE(
    "exports: fitted parameters in CSV are numbers in columns, one row per model and parameter") {
  const SessionResult r = Thesis();
  const std::vector<Table> tables = BuildTables(r);
  // No value hides in a text: "damping_ratio = 0.089191 ± 2.8e-05 (± 0.0031 scaled); ...".
  const std::regex value_in_text(R"(= *[-+]?[0-9.]+(e[-+]?[0-9]+)? *±)");
  for (const Table& t : tables) {
    for (const auto& row : TidyRows(t)) {
      for (const std::string& cell : row) {
        INFO(t.name << ": " << cell);
        CHECK_FALSE(std::regex_search(cell, value_in_text));
      }
    }
  }
  REQUIRE(r.model_comparison);
  const Tidy models = TidyOf(Named(tables, "model_comparison_parameters"));
  std::size_t row = 0;
  const auto check_model = [&](const std::string& model, bool ok,
                               const std::vector<NamedEstimate>& parameters) {
    if (!ok) return;
    for (const NamedEstimate& p : parameters) {
      INFO(model << " " << p.name);
      CHECK(models.At(row, "Model") == model);
      CHECK(models.At(row, "Parameter") == p.name);
      CHECK(std::stod(models.At(row, "Value")) == p.estimate.value);
      CHECK(std::stod(models.At(row, "Value std_error")) == p.estimate.sigma);
      ++row;
    }
  };
  for (const ComparedRestitutionModel& m : r.model_comparison->restitution_models) {
    check_model(m.fit.name, m.fit.ok, m.fit.parameters);
  }
  for (const ComparedContactLaw& m : r.model_comparison->contact_laws) {
    check_model(m.fit.law, m.fit.ok, m.fit.parameters);
  }
  CHECK(row == models.rows.size());
  REQUIRE(!r.contact_laws.empty());
  const Tidy laws = TidyOf(Named(tables, "contact_law_parameters"));
  row = 0;
  for (const ContactLawFit& fit : r.contact_laws) {
    for (const NamedEstimate& p : fit.parameters) {
      INFO(fit.law << " " << p.name);
      CHECK(laws.At(row, "Law") == fit.law);
      CHECK(std::stod(laws.At(row, "Value")) == p.estimate.value);
      if (fit.scatter.excess && std::isfinite(p.estimate.sigma)) {
        CHECK(std::stod(laws.At(row, "Scaled std error")) ==
              Approx(p.estimate.sigma * fit.scatter.Scale()).epsilon(0.01));
      }
      ++row;
    }
  }
  CHECK(row == laws.rows.size());
  // The comparison itself keeps its statistics, and no parameter text.
  const Table& comparison = Named(tables, "model_comparison");
  CHECK(std::find(comparison.columns.begin(), comparison.columns.end(), "Parameters") ==
        comparison.columns.end());
}

TEST_CASE("exports: summary rows are rows of their own kind and Table 3's Delta K keeps its sign") {
  const SessionResult r = Thesis();
  const std::vector<Table> tables = BuildTables(r);
  REQUIRE(r.kelvin_voigt);
  const SessionKelvinVoigt& s = *r.kelvin_voigt;
  const Tidy table3 = TidyOf(Named(tables, "table3_stiffness"));
  CHECK(table3.columns.front() == "row_kind");
  bool negative = false;
  for (std::size_t i = 0; i + 1 < table3.rows.size(); ++i) {
    const std::string& run = table3.At(i, "Run");
    INFO(run);
    CHECK(table3.At(i, "row_kind") == "run");
    const auto at = std::find(s.run_ids.begin(), s.run_ids.end(), run);
    REQUIRE(at != s.run_ids.end());
    const double delta = s.spread.deviation[static_cast<std::size_t>(at - s.run_ids.begin())];
    // K - K avg, sign and all (the file's -3294 is no 3294).
    CHECK(std::stod(table3.At(i, "Delta K (lbf/in)")) == Approx(delta).margin(0.5));
    negative = negative || delta < 0.0;
  }
  CHECK(negative);
  // K avg: a row of kind "average", with no run in the Run column.
  const std::size_t last = table3.rows.size() - 1;
  CHECK(table3.At(last, "row_kind") == "average");
  CHECK(table3.At(last, "Run").empty());
  CHECK(std::stod(table3.At(last, "K (lbf/in)")) == Approx(s.spread.average).margin(0.5));
  // The joint Poynting-Thomson fit: a row of kind "joint", not a run called "all runs".
  const Tidy pt = TidyOf(Named(tables, "poynting_thomson"));
  CHECK(pt.At(pt.rows.size() - 1, "row_kind") == "joint");
  CHECK(pt.At(pt.rows.size() - 1, "Runs").empty());
  CHECK(pt.At(0, "row_kind") == "run");
  for (const auto& row : pt.rows) {
    for (const std::string& cell : row) CHECK(cell.find("all runs") == std::string::npos);
  }
}

TEST_CASE("exports: Markdown prose reads as it is, with no HTML escapes") {
  const std::string md = RenderTables("thesis", BuildTables(Thesis()), ReportFormat::kMarkdown);
  CHECK_THAT(md, Catch::Contains("(p < 0.001)"));
  CHECK(md.find("&lt;") == std::string::npos);
  CHECK(md.find("&gt;") == std::string::npos);
  CHECK(md.find("&amp;") == std::string::npos);
}

TEST_CASE("exports: the manifest's warnings reach every text format") {
  testing::TempDir dir;
  const std::filesystem::path session = dir.path() / "session";
  std::filesystem::create_directories(session);
  {
    std::ifstream in(testing::kSampleData / "thesis-1969" / "session.toml");
    std::ostringstream text;
    text << in.rdbuf();
    std::string manifest = text.str();
    const std::string key = "convention = \"exact\"\n";
    REQUIRE(manifest.find(key) != std::string::npos);
    manifest.insert(manifest.find(key), "conventoin = \"exact\"\n");  // a typo'd key
    std::ofstream(session / "session.toml") << manifest;
  }
  // As `reduce` keeps them: in the results' warnings, where it found them first.
  const ManifestReadResult read = ReadManifest(session);
  REQUIRE(read.warnings.size() == 1);
  SessionResult r = ReduceSession(read.session, {});
  r.warnings.insert(r.warnings.begin(),
                    FormatLocation(read.warnings[0].where) + ": " + read.warnings[0].message);
  for (const ReportFormat format :
       {ReportFormat::kMarkdown, ReportFormat::kLatex, ReportFormat::kCsv}) {
    const std::string text = RenderTables(r.title, BuildTables(r), format);
    INFO(static_cast<int>(format));
    CHECK_THAT(text, Catch::Contains("conventoin") && Catch::Contains("did you mean"));
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
  ChannelAnalysis measured;
  measured.name = "a2";
  measured.units = "m/s^2";
  ChannelAnalysis simulated = measured;
  simulated.dominant_frequency_hz = Estimate{31.03, 0.10};
  log.sources = {{"experiment", {}, "", {measured}}, {"simulation", {}, "", {simulated}}};
  ChannelComparison row;
  row.channel = "a2";
  row.units = "m/s^2";
  row.frequency_difference_hz = row.frequency_difference_percent = std::nan("");
  row.rms_difference = 0.99;
  log.comparison = LogComparison{};
  log.comparison->channels = {row};
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
