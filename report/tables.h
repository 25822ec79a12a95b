// The report's tables (thesis Tables 2-4, eq. 40 and per-run parameters),
// built from a SessionResult as read from the results file. Formatting only:
// nothing here recomputes a result.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pipeline/session_result.h"

namespace impactlab {

// One cell: its text as a reader sees it ("0.05123 ± 0.00012"), and for a
// number the value and standard error themselves, which CSV writes at full
// precision in columns of their own and LaTeX through siunitx.
struct Cell {
  std::string text;
  std::optional<double> value;  // a number
  std::optional<double> sigma;  // its standard error (infinite: not determined)
  int decimals = -1;            // the text's digits after the point (-1: not fixed)
  // Where the cell points (check_these): an anchor of the report, "table-NAME"
  // (a link in Markdown and HTML, \ref{tab:NAME} in LaTeX) or, in HTML only,
  // "run-ID" or "log-ID"; empty: none. CSV writes the text alone.
  std::string link;
  // The text is a unit ("lbf*s/in", a log channel's "m/s^2"): LaTeX typesets
  // it with siunitx where it can.
  bool unit = false;

  Cell() = default;
  Cell(std::string t) : text(std::move(t)) {}  // NOLINT: text cells read as strings
  Cell(const char* t) : text(t) {}             // NOLINT
  Cell(std::string t, std::optional<double> v, std::optional<double> s, int d)
      : text(std::move(t)), value(v), sigma(s), decimals(d) {}
  static Cell Unit(std::string t) {
    Cell c(std::move(t));
    c.unit = true;
    return c;
  }
  bool operator==(const Cell&) const = default;
};

// Cells, captions and notes hold plain text (some of it the user's: run and
// log ids, channel names, failure messages); RenderTable escapes all of it
// for its format (report/text_escape.h, report/html_escape.h).
struct Table {
  std::string name;     // file-name safe (FileSafeName), e.g. "table2_deviations"
  std::string caption;  // e.g. "Deviation of theoretical from experimental response (Table 2)"
  std::vector<std::string> columns;
  std::vector<std::vector<Cell>> rows;
  // What each row is, where some rows summarise the others (Table 3's K avg,
  // the joint fit of all runs): empty when every row is data of one kind;
  // else one word per row ("run", "average", "joint"). CSV writes it as a
  // column "row_kind" of its own and leaves a summary row's first cell (its
  // label for a reader, "K avg") empty; the other formats set the summary
  // rows apart.
  std::vector<std::string> row_kinds;
  std::vector<std::string> notes;  // footnotes
  // Longer texts a reader may unfold: the HTML report folds them under the
  // table (<details>); the text formats leave them out (the results file
  // has them).
  std::vector<std::string> details;
};

// The table as CSV has it, tidy: a column whose numbers carry standard errors
// is followed by "<column> std_error"; numbers at full precision (the
// shortest text that reads back to the double exactly; an undetermined error
// "inf"); no text in a number's place ("-" is an empty cell); where some rows
// summarise the others, a first column "row_kind" (Table::row_kinds).
std::vector<std::string> TidyColumns(const Table& table);
std::vector<std::vector<std::string>> TidyRows(const Table& table);

// One entry of the report's opening "check these" list: a failed run, log or
// prediction, a warning, or a flag on a result (an anomaly, excess scatter, a
// log channel's FFT/fit mismatch or missing oscillation, impacts found on
// different channels), in one sentence, and where it applies.
struct CheckItem {
  std::string text;
  std::string table;    // the table it applies to (its name), or empty
  std::string section;  // the HTML page's section ("run-ID", "log-ID"), or empty
};
std::vector<CheckItem> CheckList(const SessionResult& result);

// Every table, the "check_these" list first (CheckList; one row saying so
// when there is nothing to check).
std::vector<Table> BuildTables(const SessionResult& result);

enum class ReportFormat { kMarkdown, kCsv, kLatex, kHtml };
std::optional<ReportFormat> ParseReportFormat(
    const std::string& name);  // "md", "csv", "tex", "html"

// One document with every table, under `title` (Markdown: a heading; LaTeX:
// a % comment, and the packages it needs: booktabs, siunitx). CSV: each table
// as its own block, introduced by a "# name: caption" comment line
// (CsvComment) and separated by a blank line; `report -f csv -o FOLDER`
// writes one file per table instead.
std::string RenderTables(const std::string& title, const std::vector<Table>& tables,
                         ReportFormat format);
// One table alone (CSV files written one per table; an HTML <table> element).
std::string RenderTable(const Table& table, ReportFormat format);

}  // namespace impactlab
