#include "report/latex_table.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "report/text_escape.h"
#include "report/uncertainty.h"

namespace impactlab {
namespace {

// A text column whose longest cell is longer than this is a paragraph
// column (tabularx's X, wrapped to the width left); shorter ones stay on one
// line. Characters.
constexpr std::size_t kProseChars = 24;
// A header of a one-line column breaks into lines of about this many
// characters (its unit on a line of its own), so that the header is no wider
// than the column's numbers.
constexpr std::size_t kHeaderLineChars = 10;
// A table of this many columns or more is set in \scriptsize, a narrower one
// in \footnotesize (as papers set their tables), with 4 pt between columns:
// the widest of the report's tables then fit an article's text width.
constexpr std::size_t kManyColumns = 9;

// The unit symbols siunitx is given: a session's two systems' (in, lbf, s;
// m, kg, N) and those of the logs and the report's own columns.
std::optional<std::string> UnitSymbol(const std::string& symbol) {
  static const std::map<std::string, std::string> kMacros = {
      {"us", "\\micro\\second"}, {"ms", "\\milli\\second"}, {"%", "\\percent"}};
  static const char* kLiteral[] = {"in", "lbf", "s", "m", "mm",  "kg", "g",
                                   "N",  "Hz",  "V", "A", "rad", "deg"};
  if (const auto macro = kMacros.find(symbol); macro != kMacros.end()) return macro->second;
  for (const char* literal : kLiteral) {
    if (symbol == literal) return symbol;
  }
  return std::nullopt;
}

// "lbf*s^2/in" as siunitx literal units ("lbf.s^{2}/in"), or nothing where
// a part is not a known symbol with an integer or one-letter power.
std::optional<std::string> SiunitxUnit(const std::string& unit) {
  std::string out;
  std::size_t i = 0;
  while (i < unit.size()) {
    const std::size_t end = unit.find_first_of("*/^", i);
    const std::string symbol = unit.substr(i, end == std::string::npos ? end : end - i);
    const auto si = UnitSymbol(symbol);
    if (!si) return std::nullopt;
    out += *si;
    i = end == std::string::npos ? unit.size() : end;
    if (i < unit.size() && unit[i] == '^') {
      std::size_t stop = unit.find_first_of("*/", i + 1);
      if (stop == std::string::npos) stop = unit.size();
      const std::string power = unit.substr(i + 1, stop - i - 1);
      const bool integer =
          !power.empty() &&
          power.find_first_not_of("0123456789", power[0] == '-' ? 1 : 0) == std::string::npos &&
          power != "-";
      const bool letter = power.size() == 1 && std::isalpha(static_cast<unsigned char>(power[0]));
      if (!integer && !letter) return std::nullopt;
      out += "^{" + power + "}";
      i = stop;
    }
    if (i < unit.size()) {
      if (i + 1 == unit.size()) return std::nullopt;  // "lbf/"
      out += unit[i] == '*' ? '.' : '/';
      ++i;
    }
  }
  if (out.empty()) return std::nullopt;
  return out;
}

// One word of a header: as it reads in plain text (for its length) and in LaTeX.
struct HeaderWord {
  std::string plain, latex;
};

std::vector<HeaderWord> HeaderWords(const std::string& column) {
  static const std::map<std::string, std::string> kSymbols = {
      {"zeta", "$\\zeta$"},   {"e", "$e$"},
      {"K", "$K$"},           {"C", "$C$"},
      {"K1", "$K_1$"},        {"K2", "$K_2$"},
      {"tau_c", "$\\tau_c$"}, {"sqrt(xi)", "$\\sqrt{\\xi}$"},
      {"chi2", "$\\chi^2$"},  {"Xmax", "$X_{\\max}$"},
      {"X0", "$X_0$"},        {"sigma", "$\\sigma$"},
      {"k", "$k$"},           {"f", "$f$"}};
  std::string text = column;
  std::optional<HeaderWord> unit;
  if (const std::size_t open = text.rfind(" ("); open != std::string::npos && text.back() == ')') {
    const std::string inside = text.substr(open + 2, text.size() - open - 3);
    if (const auto si = SiunitxUnit(inside)) {
      unit = HeaderWord{"(" + inside + ")", "(\\si{" + *si + "})"};
      text.resize(open);
    }
  }
  std::vector<std::string> words;
  for (std::size_t i = 0; i <= text.size();) {
    const std::size_t space = std::min(text.find(' ', i), text.size());
    if (space > i) words.push_back(text.substr(i, space - i));
    i = space + 1;
  }
  std::vector<HeaderWord> out;
  for (std::size_t i = 0; i < words.size(); ++i) {
    const std::string& w = words[i];
    if (i + 1 < words.size() && w == "Delta" && words[i + 1] == "K") {
      out.push_back({"Delta K", "$\\Delta K$"});
      ++i;
    } else if (i + 1 < words.size() && w == "ln" && words[i + 1] == "e") {
      out.push_back({"ln e", "$\\ln e$"});
      ++i;
    } else if (const auto symbol = kSymbols.find(w); symbol != kSymbols.end()) {
      out.push_back({w, symbol->second});
    } else {
      out.push_back({w, EscapeLatex(w)});
    }
  }
  if (unit) out.push_back(*unit);
  return out;
}

// A header stacked in lines of about kHeaderLineChars (the unit on its own),
// aligned as its column is.
std::string StackedHeader(const std::string& column, char align) {
  const std::vector<HeaderWord> words = HeaderWords(column);
  std::vector<std::string> lines;
  std::size_t length = 0;
  for (std::size_t i = 0; i < words.size(); ++i) {
    const bool unit = words[i].plain.front() == '(' && i + 1 == words.size() && i > 0;
    if (lines.empty() || unit || length + 1 + words[i].plain.size() > kHeaderLineChars) {
      lines.push_back(words[i].latex);
      length = words[i].plain.size();
    } else {
      lines.back() += " " + words[i].latex;
      length += 1 + words[i].plain.size();
    }
  }
  if (lines.size() <= 1) return lines.empty() ? "" : lines.front();
  std::string stacked = fmt::format("\\begin{{tabular}}[b]{{@{{}}{}@{{}}}}", align);
  for (std::size_t i = 0; i < lines.size(); ++i) stacked += (i ? "\\\\ " : "") + lines[i];
  return stacked + "\\end{tabular}";
}

// "3.2313e+05" as "323130": a count of thousands reads (and fits a column)
// better than a power of ten. Only up to 10^6, and only where the digits
// shown stay the same; other texts as they are.
std::string WithoutPositiveExponent(const std::string& text) {
  const std::size_t e = text.find("e+");
  if (e == std::string::npos || !IsPlainNumber(text)) return text;
  const int exponent = std::stoi(text.substr(e + 2));
  if (exponent > 6) return text;
  return fmt::format("{:.0f}", std::stod(text));
}

// A caption or note: its symbols written in words ("sqrt(xi)", "chi2") in
// mathematics, as in the headers; the rest escaped. Only names that are
// symbols wherever they stand: a lone "e" or "K" in prose stays a letter.
std::string LatexProse(const std::string& text) {
  static const std::pair<const char*, const char*> kSymbols[] = {
      {"sqrt(chi2/dof)", "$\\sqrt{\\chi^2/\\mathrm{dof}}$"},
      {"sqrt(xi)", "$\\sqrt{\\xi}$"},
      {"xi", "$\\xi$"},
      {"Delta K", "$\\Delta K$"},
      {"chi2", "$\\chi^2$"},
      {"zeta", "$\\zeta$"},
      {"tau_c", "$\\tau_c$"},
      {"Xmax", "$X_{\\max}$"},
      {"X0", "$X_0$"}};
  const auto word_edge = [&](std::size_t at) {
    return at >= text.size() || !std::isalnum(static_cast<unsigned char>(text[at]));
  };
  std::string out, plain;
  for (std::size_t i = 0; i < text.size();) {
    bool matched = false;
    if (i == 0 || word_edge(i - 1)) {
      for (const auto& [word, math] : kSymbols) {
        const std::size_t n = std::string(word).size();
        if (text.compare(i, n, word) == 0 && word_edge(i + n)) {
          out += EscapeLatex(plain) + math;
          plain.clear();
          i += n;
          matched = true;
          break;
        }
      }
    }
    if (!matched) plain += text[i++];
  }
  return out + EscapeLatex(plain);
}

std::string LatexCell(const Cell& cell) {
  if (cell.link.rfind("table-", 0) == 0) {
    return fmt::format("Table~\\ref{{tab:{}}}", cell.link.substr(6));
  }
  if (cell.unit) return LatexUnit(cell.text);
  if (!cell.value || !std::isfinite(*cell.value)) return EscapeLatex(cell.text);
  if (cell.sigma) {
    // "undetermined": abbreviated, as the table's note says.
    if (!std::isfinite(*cell.sigma)) return "n.d.";
    if (*cell.sigma > 0.0) return LatexUncertain(*cell.value, *cell.sigma, cell.decimals);
  }
  return fmt::format("\\num{{{}}}", WithoutPositiveExponent(cell.text));
}

// How long a cell reads, for the choice of a column's kind: a name without
// spaces (an identifier, "contact_laws.hunt_crossley_n") cannot wrap, and
// counts as short.
std::size_t ShownLength(const Cell& cell) {
  if (cell.link.rfind("table-", 0) == 0) return 9;  // "Table 12"
  if (std::count(cell.text.begin(), cell.text.end(), ' ') < 2) return 0;
  return cell.text.size();
}

bool Undetermined(const Cell& cell) {
  return cell.value && cell.sigma && !std::isfinite(*cell.sigma);
}

}  // namespace

std::string LatexUnit(const std::string& unit) {
  if (const auto si = SiunitxUnit(unit)) return "\\si{" + *si + "}";
  return EscapeLatex(unit);
}

std::string LatexHeader(const std::string& column) {
  std::string out;
  for (const HeaderWord& w : HeaderWords(column)) out += (out.empty() ? "" : " ") + w.latex;
  return out;
}

std::string LatexUncertain(double value, double sigma, int most_decimals) {
  const RoundedEstimate r = RoundToError(value, sigma);
  if (most_decimals >= 0 && r.decimals > most_decimals) {
    return fmt::format("\\num{{{:.{}f}}} $\\pm$ \\num{{{:.2g}}}", value, most_decimals, sigma);
  }
  return fmt::format("\\num{{{}({})}}", r.value, r.sigma_digits);
}

std::string LatexTable(const Table& t) {
  // A column of numbers is right-aligned, of short texts left-aligned, of
  // long texts a paragraph (X) column sharing the width the others leave.
  std::vector<char> kinds;
  for (std::size_t c = 0; c < t.columns.size(); ++c) {
    bool numeric = false;
    std::size_t longest = 0;
    for (const auto& row : t.rows) {
      if (c >= row.size()) continue;
      if (row[c].value) {
        numeric = true;
      } else {
        longest = std::max(longest, ShownLength(row[c]));
      }
    }
    kinds.push_back(c > 0 && numeric ? 'r' : longest > kProseChars ? 'X' : 'l');
  }
  const bool paragraphs = std::find(kinds.begin(), kinds.end(), 'X') != kinds.end();
  std::string spec = "@{}";
  for (char k : kinds)
    spec += k == 'X' ? std::string(">{\\raggedright\\arraybackslash}X") : std::string(1, k);
  spec += "@{}";

  std::string out = fmt::format(
      "\\begin{{table}}[htbp]\n\\centering\n\\caption{{{}}}\n\\label{{tab:{}}}\n"
      "\\{}\\setlength{{\\tabcolsep}}{{4pt}}\n",
      LatexProse(t.caption), t.name,
      t.columns.size() >= kManyColumns ? "scriptsize" : "footnotesize");
  out += paragraphs ? fmt::format("\\begin{{tabularx}}{{\\linewidth}}{{{}}}\n", spec)
                    : fmt::format("\\begin{{tabular}}{{{}}}\n", spec);
  out += "\\toprule\n";
  for (std::size_t c = 0; c < t.columns.size(); ++c) {
    out += (c ? " & " : "") +
           (kinds[c] == 'X' ? LatexHeader(t.columns[c]) : StackedHeader(t.columns[c], kinds[c]));
  }
  out += " \\\\\n\\midrule\n";
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    // The summary rows (K avg, the joint fit) set apart by a rule.
    if (i > 0 && i < t.row_kinds.size() && t.row_kinds[i] != t.row_kinds[i - 1]) {
      out += "\\midrule\n";
    }
    const auto& row = t.rows[i];
    for (std::size_t c = 0; c < row.size(); ++c) out += (c ? " & " : "") + LatexCell(row[c]);
    out += " \\\\\n";
  }
  out += fmt::format("\\bottomrule\n\\end{{{}}}\n", paragraphs ? "tabularx" : "tabular");
  bool undetermined = false;
  for (const auto& row : t.rows) {
    undetermined = undetermined || std::any_of(row.begin(), row.end(), Undetermined);
  }
  std::vector<std::string> notes = t.notes;
  if (undetermined) notes.push_back("n.d.: not determined by the data (undetermined).");
  for (const auto& note : notes) {
    out += fmt::format("\n\\par\\footnotesize {}\n", LatexProse(note));
  }
  return out + "\\end{table}\n\n";
}

}  // namespace impactlab
