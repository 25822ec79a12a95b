#include "report/text_escape.h"

#include <algorithm>
#include <cctype>
#include <cstring>

namespace impactlab {
namespace {

bool IsControl(char c) {
  const auto u = static_cast<unsigned char>(c);
  return u < 0x20 || u == 0x7F;
}

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// A list marker is followed by a space or a tab ("-" alone, an empty item,
// is left as it is: the tables' "no value").
bool ListMarkerEnds(const std::string& text, std::size_t next) {
  return next < text.size() && (text[next] == ' ' || text[next] == '\t');
}

// The power after a '^' at `at`: a parenthesised group (with its
// parentheses, balanced) or a run of letters, digits and a leading sign;
// empty if none.
std::string PowerAfter(const std::string& text, std::size_t at) {
  if (at >= text.size()) return "";
  if (text[at] == '(') {
    int depth = 0;
    for (std::size_t j = at; j < text.size(); ++j) {
      if (text[j] == '(') ++depth;
      if (text[j] == ')' && --depth == 0) return text.substr(at, j - at + 1);
    }
    return "";
  }
  std::size_t end = at;
  if (text[end] == '-' || text[end] == '+') ++end;
  while (end < text.size() && std::isalnum(static_cast<unsigned char>(text[end]))) ++end;
  if (end == at || (end == at + 1 && !std::isalnum(static_cast<unsigned char>(text[at])))) {
    return "";
  }
  return text.substr(at, end - at);
}

}  // namespace

std::string EscapeLatex(const std::string& text) {
  static const std::string kPlusMinus = "±";
  std::string out;
  out.reserve(text.size() + text.size() / 4);
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text.compare(i, kPlusMinus.size(), kPlusMinus) == 0) {
      out += "$\\pm$";
      i += kPlusMinus.size() - 1;
      continue;
    }
    const char c = text[i];
    switch (c) {
      case '#':
      case '$':
      case '%':
      case '&':
      case '_':
      case '{':
      case '}':
        out += '\\';
        out += c;
        break;
      case '~':
        out += "\\textasciitilde{}";
        break;
      case '^': {
        // A power in prose ("k^(-1/(n+1))", "in^n") as a superscript; a
        // circumflex alone as itself.
        const std::string power = PowerAfter(text, i + 1);
        if (power.empty()) {
          out += "\\textasciicircum{}";
        } else {
          const bool grouped = text[i + 1] == '(';
          out += "\\textsuperscript{" +
                 EscapeLatex(grouped ? power.substr(1, power.size() - 2) : power) + "}";
          i += power.size();
        }
        break;
      }
      case '\\':
        out += "\\textbackslash{}";
        break;
      case '<':
        out += "\\textless{}";
        break;
      case '>':
        out += "\\textgreater{}";
        break;
      case '|':
        out += "\\textbar{}";
        break;
      case '[':  // a cell starting with [ after \\ would be read as \\[length]
        out += "{[}";
        break;
      case ']':
        out += "{]}";
        break;
      case '*':  // braced: after \\ it would make \\*, a command
        out += "{*}";
        break;
      default:
        out += IsControl(c) ? ' ' : c;
    }
  }
  return out;
}

std::string EscapeMarkdown(const std::string& text) {
  std::string out;
  out.reserve(text.size() + text.size() / 4);
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    switch (c) {
      // Only what could start markup is escaped, so that prose reads as it
      // is in a terminal too ("p < 0.001", "e -> 1", "Q & A"): a '<' that
      // could open a tag, an '&' that could start an entity, a '>' that
      // could start a quote.
      case '<':
        out += i + 1 < text.size() && (std::isalpha(static_cast<unsigned char>(text[i + 1])) ||
                                       std::strchr("/!?", text[i + 1]) != nullptr)
                   ? "&lt;"
                   : "<";
        break;
      case '&':
        out += i + 1 < text.size() &&
                       (std::isalnum(static_cast<unsigned char>(text[i + 1])) || text[i + 1] == '#')
                   ? "&amp;"
                   : "&";
        break;
      case '>':
        out += i == 0 ? "\\>" : ">";
        break;
      case '\\':
      case '`':
      case '*':
      case '_':
      case '[':
      case ']':
      case '|':
      case '#':
      case '~':
        out += '\\';
        out += c;
        break;
      case '-':
      case '+':
        if (i == 0 && ListMarkerEnds(text, 1)) out += '\\';  // "- item", "+ item"
        out += c;
        break;
      case '.':
        // "1. item" at the start of a line is an ordered list item.
        if (i > 0 && text.find_first_not_of("0123456789") == i && ListMarkerEnds(text, i + 1)) {
          out += '\\';
        }
        out += c;
        break;
      default:
        out += IsControl(c) ? ' ' : c;
    }
  }
  return out;
}

bool IsPlainNumber(const std::string& text) {
  std::size_t i = 0;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
  std::size_t digits = 0;
  while (i < text.size() && IsDigit(text[i])) ++i, ++digits;
  if (i < text.size() && text[i] == '.') {
    ++i;
    while (i < text.size() && IsDigit(text[i])) ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    std::size_t exponent_digits = 0;
    while (i < text.size() && IsDigit(text[i])) ++i, ++exponent_digits;
    if (exponent_digits == 0) return false;
  }
  return i == text.size();
}

std::string EscapeCsv(const std::string& cell) {
  std::string text = cell;
  if (!text.empty() && std::strchr("=+-@\t\r", text[0]) != nullptr && text != "-" &&
      !IsPlainNumber(text)) {
    text.insert(0, 1, '\'');
  }
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    out += c;
    if (c == '"') out += '"';
  }
  return out + "\"";
}

std::string CsvComment(const std::string& text) {
  std::string out = text;
  for (char& c : out) {
    if (IsControl(c)) c = ' ';
    if (c == '"') c = '\'';
  }
  return out;
}

std::string FileSafeName(const std::string& name) {
  std::string out = name;
  for (char& c : out) {
    const auto u = static_cast<unsigned char>(c);
    if (!(std::isalnum(u) && u < 0x80) && c != '.' && c != '_' && c != '-') c = '_';
  }
  if (out.empty() || out == "." || out == "..")
    out = std::string(std::max<std::size_t>(out.size(), 1), '_');
  return out;
}

}  // namespace impactlab
