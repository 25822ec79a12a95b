// The report's tables (thesis Tables 2-4, eq. 40 and per-run parameters),
// built from a SessionResult as read from the results file. Formatting only:
// nothing here recomputes a result.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pipeline/session_result.h"

namespace impactlab {

// Cells, captions and notes hold plain text (some of it the user's: run and
// log ids, channel names, failure messages); RenderTable escapes all of it
// for its format (report/text_escape.h, report/html_escape.h).
struct Table {
  std::string name;     // file-name safe (FileSafeName), e.g. "table2_deviations"
  std::string caption;  // e.g. "Deviation of theoretical from experimental response (Table 2)"
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> notes;  // footnotes
};

std::vector<Table> BuildTables(const SessionResult& result);

enum class ReportFormat { kMarkdown, kCsv, kLatex, kHtml };
std::optional<ReportFormat> ParseReportFormat(
    const std::string& name);  // "md", "csv", "tex", "html"

// One document with every table, under `title` (Markdown: a heading; LaTeX:
// a % comment). CSV: each table as its own block, introduced by a
// "# name: caption" comment line (CsvComment) and separated by a blank line.
std::string RenderTables(const std::string& title, const std::vector<Table>& tables,
                         ReportFormat format);
// One table alone (CSV files written one per table; an HTML <table> element).
std::string RenderTable(const Table& table, ReportFormat format);

}  // namespace impactlab
