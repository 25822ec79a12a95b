// A CSV-trace session written by a test: the traces as time_s,volts files
// and the manifest naming them (two cells, R and L, calibrated by CSV sweeps;
// one run "run" with right and left traces).
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/trace.h"

namespace impactlab::testing {

inline void WriteCsv(const std::filesystem::path& path, const std::vector<double>& t,
                     const std::vector<double>& v) {
  Trace trace;
  trace.time_s = t;
  trace.volts = v;
  WriteTraceCsv(path, trace);
}

// The manifest of traces/R.csv, traces/L.csv (calibrations from `x0`) and
// traces/run-right.csv, traces/run-left.csv (run "run" from `x0`) on a
// pendulum of `length`: `run_keys` are added to the [[run]] table,
// `run_tables` after it (e.g. a contact trace).
inline void WriteCsvManifest(const std::filesystem::path& dir, const std::string& title,
                             double length, double x0, const std::string& run_keys = "",
                             const std::string& run_tables = "") {
  std::ofstream(dir / "session.toml")
      << fmt::format(R"(format = 1
title = "{}"
[apparatus]
pendulum_length = {}
weight = 2.23
[[calibration]]
id = "R"
cell = "right"
initial_displacement = {}
[calibration.trace]
csv = "traces/R.csv"
[[calibration]]
id = "L"
cell = "left"
initial_displacement = {}
[calibration.trace]
csv = "traces/L.csv"
[[run]]
id = "run"
initial_displacement = {}
calibration = {{ right = "R", left = "L" }}
{}[run.traces.right]
csv = "traces/run-right.csv"
[run.traces.left]
csv = "traces/run-left.csv"
{})",
                     title, length, x0, x0, x0, run_keys, run_tables);
}

}  // namespace impactlab::testing
