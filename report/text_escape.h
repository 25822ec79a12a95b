// Escaping for the report's text formats. Every string the report prints can
// come from the user's input (a session title, run, calibration and log ids,
// channel names, failure messages, notes), so every one goes through the
// escape of its format; nothing in a report is markup from the data.
// HTML and SVG: html_escape.h.
#pragma once

#include <string>

namespace impactlab {

// LaTeX text (in a tabular cell, a caption, a paragraph, or a % comment): the
// ten specials # $ % & ~ _ ^ \ { } become their escaped forms (so no \input,
// no ^^5c trick, no group can be opened), < > | [ ] are made text, and
// newlines, tabs and other control characters become spaces (a newline would
// end a % comment; a blank line a paragraph; form feed is \par). "±" becomes
// $\pm$; "*" is braced (after \\ it would be \\*); a power in prose
// ("c k^(-1/(n+1))") a superscript, a lone "^" \textasciicircum{}.
std::string EscapeLatex(const std::string& text);

// Markdown text, in a table cell, a heading or a paragraph: a '<' that
// could open a tag and an '&' that could start an entity are HTML-escaped
// (no raw HTML: <script>, <svg onload=...>; "p < 0.001" stays as it is), a
// leading '>' backslash-escaped (no quote), Markdown's own
// specials \ ` * _ [ ] | # ~ are backslash-escaped (no code spans, emphasis,
// links, images, cell breaks or headings), a leading - + or digit-dot is
// escaped (no list), and newlines and other control characters become spaces
// (a newline would end a table row or a heading).
std::string EscapeMarkdown(const std::string& text);

// One CSV cell (RFC 4180): quoted, with quotes doubled, when it holds a
// comma, a quote, CR or LF. A cell a spreadsheet would run as a formula
// (starting with = + - @, tab or CR) gets a leading single quote, unless it
// is a plain number (-0.5, +0.0001, 1e-3) or a lone "-" (the tables' "no
// value"), which stay as they are.
std::string EscapeCsv(const std::string& cell);

// True for a plain decimal number: optional sign, digits with at most one
// point (at least one digit), optional exponent.
bool IsPlainNumber(const std::string& text);

// A single-line comment for a CSV stream ("# ..."): control characters
// become spaces and double quotes single ones, so a reader that does not skip
// comments still sees one line with no open quote.
std::string CsvComment(const std::string& text);

// A file-name-safe form: every byte other than A-Z a-z 0-9 . _ - becomes
// "_", so a table named after a run or log id cannot leave the folder its
// CSV is written to (no "/", no "..", as "." alone or ".." alone become "_").
std::string FileSafeName(const std::string& name);

}  // namespace impactlab
