// LaTeX a paper takes as it is: the structure of every table of the bundled
// sessions (braces and environments balanced, as many cells as the column
// spec has columns, units through siunitx, symbols in mathematics, errors to
// two significant digits, long texts in paragraph columns). That the tables
// also compile, and fit the page, with Debian's TeX: latex_compile_test.cpp.
#include <regex>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "report/latex_table.h"
#include "report/tables.h"
#include "tests/report/thesis_result.h"
#include "tests/support/sample_data.h"

namespace impactlab {
// A named namespace: the test program is one unity build.
namespace latex_test {

std::vector<Table> TablesOf(const std::string& session) {
  return BuildTables(ReduceSession(ReadManifest(testing::kSampleData / session).session, {}));
}

// The text outside $...$ and outside the arguments of \si and \num: what
// TeX typesets as text, where ^ and _ are errors.
std::string TextOutsideMath(const std::string& tex) {
  std::string text;
  bool math = false;
  for (std::size_t i = 0; i < tex.size(); ++i) {
    if (tex[i] == '\\' && i + 1 < tex.size()) {
      for (const char* macro : {"\\si{", "\\num{", "\\ref{", "\\label{"}) {
        if (tex.compare(i, std::string(macro).size(), macro) == 0) {
          i = tex.find('}', i);  // their arguments hold no braces
          break;
        }
      }
      if (tex[i] == '\\') {
        text += tex.substr(i, 2);
        ++i;
      }
      continue;
    }
    if (tex[i] == '$') {
      math = !math;
      continue;
    }
    if (!math) text += tex[i];
  }
  return text;
}

// Braces (not escaped) balance and never close one not opened.
bool BracesBalance(const std::string& tex) {
  int depth = 0;
  for (std::size_t i = 0; i < tex.size(); ++i) {
    if (tex[i] == '\\') {
      ++i;
      continue;
    }
    if (tex[i] == '{') ++depth;
    if (tex[i] == '}' && --depth < 0) return false;
  }
  return depth == 0;
}

// Every \begin{X} ends with its \end{X}, nested properly.
bool EnvironmentsBalance(const std::string& tex) {
  std::vector<std::string> open;
  const std::regex environment(R"(\\(begin|end)\{([a-z*]+)\})");
  for (std::sregex_iterator m(tex.begin(), tex.end(), environment), end; m != end; ++m) {
    if ((*m)[1] == "begin") {
      open.push_back((*m)[2]);
    } else if (open.empty() || open.back() != (*m)[2]) {
      return false;
    } else {
      open.pop_back();
    }
  }
  return open.empty();
}

// The columns of a tabular spec: l, r, c, p{..} and X (with its >{...}).
std::size_t SpecColumns(const std::string& spec) {
  std::size_t n = 0;
  int depth = 0;
  for (char c : spec) {
    if (c == '{') ++depth;
    if (c == '}') --depth;
    if (depth == 0 && std::string("lrcpX").find(c) != std::string::npos) ++n;
  }
  return n;
}

// The cells of one row of the outermost tabular (& at depth 0 of braces).
std::size_t CellsOf(const std::string& row) {
  std::size_t n = 1;
  int depth = 0;
  for (std::size_t i = 0; i < row.size(); ++i) {
    if (row[i] == '\\') {
      ++i;
      continue;
    }
    if (row[i] == '{') ++depth;
    if (row[i] == '}') --depth;
    if (row[i] == '&' && depth == 0) ++n;
  }
  return n;
}

// One table's LaTeX as the test reads it: its column spec, and its rows.
struct Tabular {
  std::string spec;
  std::vector<std::string> rows;
};

Tabular Parse(const std::string& tex) {
  Tabular t;
  const std::regex begin(R"(\\begin\{tabularx?\}(\{\\linewidth\})?\{)");
  std::smatch m;
  REQUIRE(std::regex_search(tex, m, begin));
  std::size_t at = static_cast<std::size_t>(m.position(0) + m.length(0));
  for (int depth = 1; depth > 0; ++at) {
    if (tex[at] == '{') ++depth;
    if (tex[at] == '}') --depth;
    if (depth > 0) t.spec += tex[at];
  }
  const std::size_t end = tex.find("\\bottomrule", at);
  // Rows end with " \\" and a newline; the rules are rows of their own.
  for (std::size_t line = at; line < end;) {
    std::size_t next = tex.find(" \\\\\n", line);
    if (next == std::string::npos || next > end) break;
    std::string row = tex.substr(line, next - line);
    for (const char* rule : {"\\toprule\n", "\\midrule\n"}) {
      for (std::size_t r; (r = row.find(rule)) != std::string::npos;) {
        row.erase(r, std::string(rule).size());
      }
    }
    while (!row.empty() && row.front() == '\n') row.erase(0, 1);
    t.rows.push_back(row);
    line = next + 4;
  }
  return t;
}

TEST_CASE(
    "latex: every table of the bundled sessions is well formed, its cells matching its spec") {
  for (const char* session : {"thesis-1969", "logs-two-link"}) {
    for (const Table& table : TablesOf(session)) {
      INFO(session << ": " << table.name);
      const std::string tex = LatexTable(table);
      CHECK(BracesBalance(tex));
      CHECK(EnvironmentsBalance(tex));
      const Tabular t = Parse(tex);
      CHECK(SpecColumns(t.spec) == table.columns.size());
      REQUIRE(t.rows.size() == table.rows.size() + 1);  // the header, then the rows
      for (const std::string& row : t.rows) {
        INFO(row);
        CHECK(CellsOf(row) == table.columns.size());
      }
      // No text that TeX would take for a superscript or subscript, and no
      // circumflex or star made text: units and symbols are typeset.
      const std::string text = TextOutsideMath(tex);
      INFO(text);
      CHECK(text.find('^') == std::string::npos);
      for (std::size_t i = text.find('_'); i != std::string::npos; i = text.find('_', i + 1)) {
        CHECK((i > 0 && text[i - 1] == '\\'));
      }
      CHECK(tex.find("textasciicircum") == std::string::npos);
      CHECK(tex.find("$^*$") == std::string::npos);
    }
  }
}

TEST_CASE("latex: units through siunitx and headers in mathematics") {
  const std::vector<Table> tables = testing::ThesisTables();
  std::string tex;
  for (const Table& t : tables) tex += LatexTable(t);
  CHECK(LatexHeader("tau_c (us)") == "$\\tau_c$ (\\si{\\micro\\second})");
  CHECK(LatexHeader("C (lbf*s/in)") == "$C$ (\\si{lbf.s/in})");
  CHECK(LatexHeader("Delta K (lbf/in)") == "$\\Delta K$ (\\si{lbf/in})");
  CHECK(LatexHeader("Experimental Xmax (in)") == "Experimental $X_{\\max}$ (\\si{in})");
  CHECK(LatexHeader("spread of ln e") == "spread of $\\ln e$");
  CHECK(LatexHeader("RMS difference (aligned)") == "RMS difference (aligned)");  // no unit
  // In the tables, a long header is stacked on lines, its unit on one of its own.
  for (const char* typeset : {"$\\zeta$", "$\\tau_c$\\\\ (\\si{\\micro\\second})", "$\\sqrt{\\xi}$",
                              "$\\chi^2$", "$C$\\\\ (\\si{lbf.s/in})", "$K$\\\\ (\\si{lbf/in})",
                              "$\\Delta K$", "$X_{\\max}$", "(\\si{in})", "\\si{s/in}"}) {
    INFO(typeset);
    CHECK_THAT(tex, Catch::Contains(typeset));
  }
  for (const char* ascii : {"zeta &", "tau\\_c", "sqrt(xi)", "chi2 &", "lbf$^*$s"}) {
    INFO(ascii);
    CHECK(tex.find(ascii) == std::string::npos);
  }
  CHECK(LatexUnit("m/s^2") == "\\si{m/s^{2}}");
  CHECK(LatexUnit("lbf*s^2/in") == "\\si{lbf.s^{2}/in}");
  CHECK(LatexUnit("N*s/m") == "\\si{N.s/m}");
  // Not a unit of known symbols: text, escaped.
  CHECK(LatexUnit("counts") == "counts");
  CHECK(LatexUnit("^^5c") == "\\textasciicircum{}\\textsuperscript{5c}");
}

TEST_CASE("latex: every error to two significant digits, the value to the same digit") {
  CHECK(LatexUncertain(0.33351, 0.39938, 4) == "\\num{0.33(40)}");
  CHECK(LatexUncertain(0.085084, 0.003812, 5) == "\\num{0.0851(38)}");
  CHECK(LatexUncertain(460429.0, 301.0, 0) == "\\num{460430(300)}");
  CHECK(LatexUncertain(8.7801, 0.396, 3) == "\\num{8.78(40)}");
  // A noiseless simulation's error, far below the digits shown.
  CHECK(LatexUncertain(0.0851, 1.2e-12, 9) == "\\num{0.085100000} $\\pm$ \\num{1.2e-12}");
  std::string tex;
  for (const Table& t : testing::ThesisTables()) tex += LatexTable(t);
  const std::regex uncertain(R"(\\num\{[-+]?[0-9.]+\(([0-9]+)\)\})");
  std::size_t numbers = 0;
  for (std::sregex_iterator m(tex.begin(), tex.end(), uncertain), end; m != end; ++m) {
    std::string digits = (*m)[1];
    while (digits.size() > 2 && digits.back() == '0') digits.pop_back();  // 300: rounded to 10s
    INFO((*m)[0]);
    CHECK(digits.size() <= 2);
    ++numbers;
  }
  CHECK(numbers > 40);
}

TEST_CASE("latex: long texts wrap in paragraph columns and numbers stay right-aligned") {
  for (const Table& table : testing::ThesisTables()) {
    INFO(table.name);
    const Tabular t = Parse(LatexTable(table));
    // The spec's columns in order: X for a text longer than a few words.
    std::vector<char> kinds;
    int depth = 0;
    for (char c : t.spec) {
      if (c == '{') ++depth;
      if (c == '}') --depth;
      if (depth == 0 && std::string("lrX").find(c) != std::string::npos) kinds.push_back(c);
    }
    REQUIRE(kinds.size() == table.columns.size());
    for (std::size_t c = 0; c < table.columns.size(); ++c) {
      for (const auto& row : table.rows) {
        if (row[c].value) {
          if (c > 0) CHECK(kinds[c] == 'r');
        } else if (row[c].text.size() > 40 && row[c].link.empty()) {
          INFO(row[c].text);
          CHECK(kinds[c] == 'X');
        }
      }
    }
  }
}

}  // namespace latex_test
}  // namespace impactlab
