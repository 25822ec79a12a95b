#include "io/trace.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <istream>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "io/errors.h"

namespace impactlab {
namespace {

std::string_view TrimBlanks(std::string_view s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == ' ' || s.back() == '\t'))
    s.remove_suffix(1);
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  return s;
}

// The comma-separated field `index` of `line`, trimmed.
std::string_view Field(std::string_view line, int index) {
  for (int i = 0; i < index; ++i) {
    const auto comma = line.find(',');
    if (comma == std::string_view::npos) return {};
    line.remove_prefix(comma + 1);
  }
  return TrimBlanks(line.substr(0, line.find(',')));
}

double ParseNumber(std::string_view text, const std::filesystem::path& path, long long line,
                   const char* column) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    throw InputError({path, column, line},
                     fmt::format("expected a finite number, found \"{}\"", text));
  }
  return value;
}

}  // namespace

Trace ReadTraceCsv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError({path, "", std::nullopt}, "cannot open the trace file");
  return ParseTraceCsv(in, path);
}

Trace ParseTraceCsv(std::istream& in, const std::filesystem::path& path) {
  std::string line;
  if (!std::getline(in, line)) {
    throw InputError({path, "header", 1},
                     "the file is empty; expected the header \"time_s,volts\" and samples");
  }
  if (Field(line, 0) != "time_s" || Field(line, 1) != "volts") {
    throw InputError(
        {path, "header", 1},
        fmt::format("expected the header \"time_s,volts\", found \"{}\"", TrimBlanks(line)));
  }
  Trace trace;
  long long number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (TrimBlanks(line).empty()) continue;
    const double t = ParseNumber(Field(line, 0), path, number, "time_s");
    const double v = ParseNumber(Field(line, 1), path, number, "volts");
    if (!trace.time_s.empty() && !(t > trace.time_s.back())) {
      throw InputError(
          {path, "time_s", number},
          fmt::format("time must increase, found {} after {}", t, trace.time_s.back()));
    }
    trace.time_s.push_back(t);
    trace.volts.push_back(v);
  }
  if (trace.time_s.size() < 2) {
    throw InputError({path, "", number}, "a trace needs at least two samples");
  }
  return trace;
}

void WriteTraceCsv(const std::filesystem::path& path, const Trace& trace) {
  std::ofstream out(path);
  out << "time_s,volts\n";
  for (std::size_t i = 0; i < trace.time_s.size(); ++i) {
    out << fmt::format("{:.12g},{:.9g}\n", trace.time_s[i], trace.volts[i]);
  }
  if (!out) throw InputError({path, "", std::nullopt}, "cannot write the trace file");
}

}  // namespace impactlab
