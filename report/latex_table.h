// A report table as LaTeX a paper takes as it is: booktabs rules, numbers
// and units through siunitx (\num{0.33(40)}, \si{lbf.s/in}), headers in
// mathematics ($\tau_c$ (\si{\micro\second})), and long texts (reasons,
// anomalies, verdicts) in tabularx paragraph columns, so that every table
// fits the page. The preamble needs booktabs, siunitx and tabularx.
#pragma once

#include <string>

#include "report/tables.h"

namespace impactlab {

// The packages the tables need, as preamble lines.
inline constexpr const char* kLatexPackages =
    "\\usepackage{booktabs}\n\\usepackage{siunitx}\n\\usepackage{tabularx}\n";

std::string LatexTable(const Table& table);

// A column header, "tau_c (us)" -> "$\tau_c$ (\si{\micro\second})": the
// physics' symbols in mathematics, a unit in parentheses through siunitx;
// any other text escaped.
std::string LatexHeader(const std::string& column);

// A unit, "lbf*s/in" -> "\si{lbf.s/in}", "m/s^2" -> "\si{m/s^2}", "us" ->
// "\si{\micro\second}"; a text that is not a unit of known symbols (a log
// channel's "counts") escaped as text.
std::string LatexUnit(const std::string& unit);

// A number with its standard error for siunitx, the error to two significant
// digits: \num{0.33(40)}; an error below `most_decimals` digits (a noiseless
// simulation's) as \num{0.0851} $\pm$ \num{1.2e-12}.
std::string LatexUncertain(double value, double sigma, int most_decimals);

}  // namespace impactlab
