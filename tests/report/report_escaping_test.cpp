// Every report format escapes every string from the user's input: hostile
// titles, run and log ids, channel names and messages must come out as text,
// never as LaTeX commands, HTML elements, Markdown structure or spreadsheet
// formulas.
#include <algorithm>
#include <cctype>
#include <set>
#include <sstream>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "report/html_report.h"
#include "report/tables.h"
#include "report/text_escape.h"

namespace impactlab {
namespace {

const std::string kInputFile = "\\input{/etc/hostname}";
const std::string kInputPipe = "\\input{|\"id\"}";
const std::string kScript = "<script>alert(1)</script>";
const std::string kSvg = "<svg onload=alert(1)>";
const std::string kPipes = "| a | b |";
const std::string kFormula = "=HYPERLINK(\"http://x\",\"y\")";
const std::string kSpecials = "#$%&~_^\\{}";
const std::string kTitle = "Session\n\\input{/etc/hostname}\n" + kScript;

SessionResult Hostile() {
  const auto folder = std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "thesis-1969";
  SessionResult r = ReduceSession(ReadManifest(folder).session, {});
  REQUIRE(r.runs.size() >= 6);
  r.title = kTitle;
  const std::vector<std::string> ids = {kInputFile, kInputPipe, kScript,
                                        kSvg,       kPipes,     kFormula + "," + kSpecials};
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (r.kelvin_voigt) {
      for (std::string& id : r.kelvin_voigt->run_ids) {
        if (id == r.runs[i].id) id = ids[i];
      }
    }
    for (RunPrediction& p : r.predictions) {
      if (p.target_run == r.runs[i].id) p.target_run = ids[i];
      if (p.source_run == r.runs[i].id) p.source_run = ids[i];
    }
    r.runs[i].id = ids[i];
  }
  r.runs.push_back(r.runs.back());
  r.runs.back().id = "-1\n+2";
  r.runs.back().ok = false;
  r.runs.back().reason = kScript + "\n" + kPipes + "\n# heading\n`code` *b* [l](javascript:x)";
  r.warnings.push_back(kSvg + kInputFile);

  LogResult log;
  log.id = "../../" + kInputFile;
  log.ok = true;
  LogSourceResult source;
  source.source = "experiment";
  source.impact_method = kPipes + "\n" + kScript;
  ChannelAnalysis channel;
  channel.name = kSvg + kPipes;
  channel.units = "^^5c" + kInputPipe;
  channel.dominant_frequency_hz = Estimate{12.5, 0.1};
  source.channels.push_back(channel);
  log.sources.push_back(source);
  r.logs.push_back(log);

  PhotoOverlay overlay;
  overlay.photo = kSvg + ".jpg";
  overlay.trace_names = {kScript};
  overlay.trace_coverage = {0.5};
  r.runs[0].measured.overlays.push_back(overlay);
  return r;
}

// LaTeX: the only control sequences are the report's own.
void CheckLatexHasOnlyOwnCommands(const std::string& tex) {
  static const std::set<std::string> kAllowed = {
      "begin", "end", "centering", "caption", "label", "usepackage", "toprule", "midrule",
      "bottomrule", "num", "par", "footnotesize", "ref", "textbackslash", "textasciitilde",
      "textasciicircum", "textless", "textgreater", "textbar", "pm",
      // The tables' own typesetting
      // (report/latex_table.h).
      "footnotesize", "scriptsize", "setlength", "tabcolsep", "linewidth", "raggedright",
      "arraybackslash", "si", "textsuperscript", "micro", "milli", "second", "percent", "zeta",
      "tau", "sqrt", "xi", "chi", "sigma", "Delta", "ln", "max", "mathrm"};
  for (std::size_t i = 0; i < tex.size(); ++i) {
    if (tex[i] != '\\') continue;
    REQUIRE(i + 1 < tex.size());
    if (std::isalpha(static_cast<unsigned char>(tex[i + 1]))) {
      std::size_t j = i + 1;
      while (j < tex.size() && std::isalpha(static_cast<unsigned char>(tex[j]))) ++j;
      const std::string name = tex.substr(i + 1, j - i - 1);
      INFO("control sequence \\" << name << " at " << i << ": "
                                 << tex.substr(i > 40 ? i - 40 : 0, 80));
      CHECK(kAllowed.count(name) == 1);
      i = j - 1;
    } else {
      INFO("control symbol at " << i << ": " << tex.substr(i > 40 ? i - 40 : 0, 80));
      CHECK(std::string("#$%&_{}\\").find(tex[i + 1]) != std::string::npos);
      ++i;  // "\\" is one symbol
    }
  }
  CHECK(tex.find("^^") == std::string::npos);
  CHECK(tex.find("\\input") == std::string::npos);
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Pipes that are cell separators (not backslash-escaped).
int CellSeparators(const std::string& line) {
  int n = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (line[i] == '\\') {
      ++i;
    } else if (line[i] == '|') {
      ++n;
    }
  }
  return n;
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// RFC 4180 records; a record starting with '#' is a comment line and skipped,
// as are blank lines.
std::vector<std::vector<std::string>> ParseCsv(const std::string& text, std::size_t* comments) {
  std::vector<std::vector<std::string>> records;
  *comments = 0;
  std::size_t i = 0;
  while (i < text.size()) {
    if (text[i] == '\n') {
      ++i;
      continue;
    }
    if (text[i] == '#') {
      ++*comments;
      i = text.find('\n', i);
      if (i == std::string::npos) break;
      continue;
    }
    std::vector<std::string> record(1);
    bool quoted = false;
    for (; i < text.size(); ++i) {
      const char c = text[i];
      if (quoted) {
        if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
          record.back() += '"';
          ++i;
        } else if (c == '"') {
          quoted = false;
        } else {
          record.back() += c;
        }
      } else if (c == '"' && record.back().empty()) {
        quoted = true;
      } else if (c == ',') {
        record.emplace_back();
      } else if (c == '\n') {
        ++i;
        break;
      } else {
        record.back() += c;
      }
    }
    records.push_back(record);
  }
  return records;
}

TEST_CASE("report_escaping: LaTeX runs no command from the input") {
  const SessionResult r = Hostile();
  const std::string tex = RenderTables(r.title, BuildTables(r), ReportFormat::kLatex);
  CheckLatexHasOnlyOwnCommands(tex);
  // The title stays one % comment line, newlines and all.
  const std::vector<std::string> lines = Lines(tex);
  REQUIRE(lines.size() > 2);
  CHECK_THAT(lines[0], Catch::StartsWith("% Session \\textbackslash{}input\\{/etc/hostname\\}"));
  CHECK(lines[1] == "% Needs in the preamble:");
  CHECK(lines[2] == "%   \\usepackage{booktabs}");
  CHECK(lines[3] == "%   \\usepackage{siunitx}");
  CHECK(lines[4] == "%   \\usepackage{tabularx}");
  CHECK_THAT(lines[5], Catch::StartsWith("\\begin{table}"));
  // The ten specials, each escaped.
  CHECK_THAT(tex, Catch::Contains("\\#\\$\\%\\&\\textasciitilde{}\\_\\textasciicircum{}"
                                  "\\textbackslash{}\\{\\}"));
  // The report's own: ± and the fitted-pair star (braced: after \\ a star
  // would make \\*) still typeset.
  CHECK_THAT(tex, Catch::Contains("$\\pm$"));
  CHECK_THAT(tex, Catch::Contains("& {*} &"));
  // A unit from the input is no siunitx argument: escaped text.
  CHECK(tex.find("\\si{^") == std::string::npos);
}

TEST_CASE("report_escaping: Markdown has no raw HTML and no structure from the input") {
  const SessionResult r = Hostile();
  const std::vector<Table> tables = BuildTables(r);
  const std::string md = RenderTables(r.title, tables, ReportFormat::kMarkdown);
  const std::string lower = Lower(md);
  CHECK(lower.find("<script") == std::string::npos);
  CHECK(lower.find("<svg") == std::string::npos);
  CHECK_THAT(md, Catch::Contains("&lt;script>alert(1)&lt;/script>"));
  const std::vector<std::string> lines = Lines(md);
  // The title is one heading line; the only other headings are the tables'.
  CHECK_THAT(lines[0], Catch::StartsWith("# Session \\\\input"));
  CHECK(lines[1].empty());
  std::size_t headings = 0, rows = 0;
  for (const std::string& line : lines) {
    if (line.rfind("#", 0) == 0) ++headings;
    if (line.rfind("| ", 0) == 0) ++rows;
  }
  CHECK(headings == 1 + tables.size());
  // Every row of every table has its own number of cells.
  std::size_t expected_rows = 0;
  for (const Table& t : tables) expected_rows += 2 + t.rows.size();  // header, rule, rows
  CHECK(rows == expected_rows);
  for (const Table& t : tables) {
    const std::string rendered = RenderTable(t, ReportFormat::kMarkdown);
    for (const std::string& line : Lines(rendered)) {
      if (line.rfind("|", 0) != 0) continue;
      INFO(line);
      CHECK(CellSeparators(line) == static_cast<int>(t.columns.size()) + 1);
    }
  }
  // No code span, emphasis or link from a failure message.
  CHECK_THAT(md, Catch::Contains("\\`code\\` \\*b\\* \\[l\\](javascript:x)"));
}

TEST_CASE("report_escaping: CSV cells read back as written, formulas inert") {
  const SessionResult r = Hostile();
  const std::vector<Table> tables = BuildTables(r);
  const std::string csv = RenderTables(r.title, tables, ReportFormat::kCsv);
  std::size_t comments = 0;
  const auto records = ParseCsv(csv, &comments);
  std::vector<std::vector<std::string>> expected;
  for (const Table& t : tables) {
    expected.push_back(TidyColumns(t));
    for (const auto& row : TidyRows(t)) expected.push_back(row);
  }
  REQUIRE(records.size() == expected.size());
  bool saw_formula = false;
  for (std::size_t k = 0; k < records.size(); ++k) {
    REQUIRE(records[k].size() == expected[k].size());
    for (std::size_t c = 0; c < records[k].size(); ++c) {
      std::string cell = records[k][c];
      const std::string& original = expected[k][c];
      if (!cell.empty() && std::string("=+-@").find(cell[0]) != std::string::npos) {
        INFO(cell);
        CHECK((IsPlainNumber(cell) || cell == "-"));
      }
      if (cell != original && cell == "'" + original) {
        saw_formula = saw_formula || original == kFormula + "," + kSpecials;
        cell.erase(0, 1);
      }
      CHECK(cell == original);
    }
  }
  CHECK(saw_formula);
  // Each table block is introduced by one comment line (a "# heading" inside
  // a quoted multi-line cell is not one).
  CHECK(comments == tables.size());
}

TEST_CASE("report_escaping: CSV formula guard keeps numbers numbers") {
  CHECK(EscapeCsv("-0.5") == "-0.5");
  CHECK(EscapeCsv("+0.0001") == "+0.0001");
  CHECK(EscapeCsv("-1.5e-3") == "-1.5e-3");
  CHECK(EscapeCsv("-") == "-");
  CHECK(EscapeCsv("0.405") == "0.405");
  CHECK(EscapeCsv("=1+1") == "'=1+1");
  CHECK(EscapeCsv("@SUM(A1:A2)") == "'@SUM(A1:A2)");
  CHECK(EscapeCsv("+cmd|' /C calc'!A0") == "'+cmd|' /C calc'!A0");
  CHECK(EscapeCsv("-0.5 ± 0.1") == "'-0.5 ± 0.1");
  CHECK(EscapeCsv("-inf") == "'-inf");
  CHECK(EscapeCsv("a,b") == "\"a,b\"");
  CHECK(EscapeCsv("say \"hi\"") == "\"say \"\"hi\"\"\"");
  CHECK(EscapeCsv("two\nlines") == "\"two\nlines\"");
  CHECK(EscapeCsv("=A1,B1") == "\"'=A1,B1\"");
}

TEST_CASE("report_escaping: table names are safe file names") {
  const SessionResult r = Hostile();
  for (const Table& t : BuildTables(r)) {
    INFO(t.name);
    CHECK(t.name.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                   "0123456789._-") == std::string::npos);
    CHECK(t.name != ".");
    CHECK(t.name != "..");
  }
  CHECK(FileSafeName("..") == "__");
  CHECK(FileSafeName("log_../../x") == "log_.._.._x");
}

TEST_CASE("report_escaping: the HTML report stays escaped") {
  const std::string html = RenderHtmlReport(Hostile());
  const std::string lower = Lower(html);
  // The only scripts are the report's own: dygraphs, and one per figure,
  // whose strings hold the user's text escaped (\u003c for <).
  std::size_t scripts = 0, figures = 0;
  for (std::size_t p = 0; (p = lower.find("<script", p)) != std::string::npos; ++p) {
    ++scripts;
    figures += lower.compare(p, 23, "<script>impactlabplot(\"") == 0 ? 1 : 0;
  }
  CHECK(scripts == figures + 1);
  CHECK(lower.find("<script>alert") == std::string::npos);
  CHECK(lower.find("<svg onload") == std::string::npos);
  CHECK_THAT(html, Catch::Contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
  CHECK_THAT(html, Catch::Contains("&lt;svg onload=alert(1)&gt;"));
}

}  // namespace
}  // namespace impactlab
