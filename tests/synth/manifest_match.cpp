#include "tests/synth/manifest_match.h"

#include <catch2/catch.hpp>

namespace impactlab::testing {
namespace {

namespace fs = std::filesystem;

// The reader returns a path resolved against the session folder.
std::optional<fs::path> Resolved(const Session& read, const std::optional<fs::path>& planned) {
  if (!planned) return std::nullopt;
  return (read.folder / *planned).lexically_normal();
}

void CheckTrace(const Session& read, const TraceSettings& planned, const TraceSettings& trace) {
  CHECK(trace.time_per_div == planned.time_per_div);
  CHECK(trace.volts_per_div == planned.volts_per_div);
  CHECK(trace.zero_div == planned.zero_div);
  CHECK(trace.band_div == planned.band_div);
  CHECK(trace.t0_div == planned.t0_div);
  CHECK(trace.impact == planned.impact);
  CHECK(trace.csv == Resolved(read, planned.csv));
  CHECK(trace.points_px == planned.points_px);
}

void CheckCalibration(const Session& read, const Calibration& planned, const Calibration& c) {
  INFO("calibration " << planned.id);
  CHECK(c.id == planned.id);
  CHECK(c.cell == planned.cell);
  CHECK(c.initial_displacement == planned.initial_displacement);
  CHECK(c.photo == Resolved(read, planned.photo));
  CHECK(c.graticule_corners_px == planned.graticule_corners_px);
  CheckTrace(read, planned.trace, c.trace);
}

void CheckRun(const Session& read, const Run& planned, const Run& run) {
  INFO("run " << planned.id);
  CHECK(run.id == planned.id);
  CHECK(run.initial_displacement == planned.initial_displacement);
  CHECK(run.photo == Resolved(read, planned.photo));
  CHECK(run.graticule_corners_px == planned.graticule_corners_px);
  CHECK(run.calibration == planned.calibration);
  CHECK(run.first_rebound == planned.first_rebound);
  REQUIRE(run.traces.size() == planned.traces.size());
  for (const auto& [name, trace] : planned.traces) {
    INFO("trace " << name);
    REQUIRE(run.traces.count(name) == 1);
    CheckTrace(read, trace, run.traces.at(name));
  }
  CHECK(run.rebounds == planned.rebounds);
  CHECK(run.contact_time == planned.contact_time);
  CHECK(run.fit_rebounds == planned.fit_rebounds);
  CHECK(run.rebound_uncertainty == planned.rebound_uncertainty);
  CHECK(run.contact_time_uncertainty == planned.contact_time_uncertainty);
}

void CheckLog(const Session& read, const Log& planned, const Log& log) {
  INFO("log " << planned.id);
  CHECK(log.id == planned.id);
  CHECK(log.experiment == *Resolved(read, planned.experiment));
  CHECK(log.simulation == Resolved(read, planned.simulation));
  CHECK(log.time_column == planned.time_column);
  REQUIRE(log.channels.size() == planned.channels.size());
  for (std::size_t i = 0; i < planned.channels.size(); ++i) {
    INFO("channel " << planned.channels[i].name);
    CHECK(log.channels[i].name == planned.channels[i].name);
    CHECK(log.channels[i].column == planned.channels[i].column);
    CHECK(log.channels[i].counts_per_rev == planned.channels[i].counts_per_rev);
    CHECK(log.channels[i].gear_ratio == planned.channels[i].gear_ratio);
    CHECK(log.channels[i].sensitivity == planned.channels[i].sensitivity);
  }
}

}  // namespace

void CheckReadsBack(const SessionManifest& planned, const Session& read) {
  CHECK(read.format == 1);
  CHECK(read.title == planned.title);
  CHECK(read.units == planned.units);
  REQUIRE(read.apparatus.has_value() == planned.apparatus.has_value());
  if (planned.apparatus) {
    CHECK(read.apparatus->pendulum_length == planned.apparatus->pendulum_length);
    // Given as a weight, read as M = W / g (g: the unit system's standard).
    CHECK(read.apparatus->mass == planned.apparatus->weight / read.apparatus->gravity);
    CHECK(read.apparatus->arrangement == planned.apparatus->arrangement);
  }
  if (planned.divisions) CHECK(read.divisions == *planned.divisions);
  CHECK(read.rejected.empty());
  REQUIRE(read.calibrations.size() == planned.calibrations.size());
  for (std::size_t i = 0; i < planned.calibrations.size(); ++i) {
    CheckCalibration(read, planned.calibrations[i], read.calibrations[i]);
  }
  REQUIRE(read.runs.size() == planned.runs.size());
  for (std::size_t i = 0; i < planned.runs.size(); ++i) {
    CheckRun(read, planned.runs[i], read.runs[i]);
  }
  REQUIRE(read.logs.size() == planned.logs.size());
  for (std::size_t i = 0; i < planned.logs.size(); ++i) {
    CheckLog(read, planned.logs[i], read.logs[i]);
  }
}

}  // namespace impactlab::testing
