// A sampled signal: an oscilloscope trace from a CSV file or a digitized photo.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <vector>

namespace impactlab {

struct Trace {
  std::vector<double> time_s;       // s since the release (may start before it), increasing
  std::vector<double> volts;        // V
  std::vector<double> sigma_volts;  // one-sigma per sample; empty when unknown
};

// Reads a trace CSV: a header line naming the columns `time_s,volts` (in that
// order; extra columns ignored), then one sample per line. Throws InputError
// naming the file and line for a missing file, a wrong header, a value that is
// not a finite number, or time that does not increase.
Trace ReadTraceCsv(const std::filesystem::path& path);

// The same from a stream (the fuzz target, tests); `path` names the source in
// errors.
Trace ParseTraceCsv(std::istream& in, const std::filesystem::path& path);

// Writes the same format (used by the generator and `digitize`).
void WriteTraceCsv(const std::filesystem::path& path, const Trace& trace);

}  // namespace impactlab
