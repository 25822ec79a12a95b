// The generators' manifest writer (synth/manifest_writer.h): every field it
// writes reads back through io/manifest.h to the same value, to the last bit.
#include "synth/manifest_writer.h"

#include <cmath>
#include <fstream>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "tests/support/temp_dir.h"
#include "tests/synth/manifest_match.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

// The reader checks that every file a manifest names exists.
void Touch(const fs::path& folder, const std::optional<fs::path>& file) {
  if (!file) return;
  fs::create_directories((folder / *file).parent_path());
  std::ofstream(folder / *file) << "x";
}

TraceSettings Screen(double time_per_div, double zero_div, std::array<double, 2> band) {
  TraceSettings trace;
  trace.time_per_div = time_per_div;
  trace.volts_per_div = 0.2;
  trace.zero_div = zero_div;
  trace.band_div = band;
  trace.t0_div = 0.2;
  return trace;
}

// Numbers no short decimal holds, so a lost digit shows.
constexpr double kThird = 1.0 / 3.0;

SessionManifest LabSession() {
  SessionManifest manifest;
  manifest.comment = {"Written by a test.", "Two lines of comment."};
  manifest.title = "Every field \"quoted\"";
  manifest.apparatus = ManifestApparatus{22.0, 2.23, Arrangement::kPair};
  manifest.divisions = std::array<int, 2>{10, 8};

  Calibration right;
  right.id = "R-1";
  right.cell = "right";
  right.initial_displacement = 0.7 * kThird;
  right.photo = "calibration/R-1.png";
  right.graticule_corners_px = GraticuleCorners{{{100, 90}, {900.5, 95}, {905, 700}, {98, 702.25}}};
  right.trace = Screen(0.05, std::nextafter(0.56, 1.0), {-3.6, 3.6});
  Calibration left;
  left.id = "L-1";
  left.cell = "left";
  left.initial_displacement = 0.405;
  left.trace = Screen(0.05, -0.741488, {-3.6, 3.6});
  left.trace.csv = "traces/L-1.csv";
  manifest.calibrations = {right, left};

  Run photo;
  photo.id = "1";
  photo.initial_displacement = 0.405 + 1e-12;
  photo.photo = "runs/1.jpg";
  photo.graticule_corners_px = GraticuleCorners{{{10, 10}, {990, 12}, {985, 740}, {12, 735}}};
  photo.calibration = {{"right", "R-1"}, {"left", "L-1"}};
  photo.traces["right"] = Screen(0.5, 3.30415, {0.4, 4.0});
  photo.traces["right"].points_px = {{120.5, 300.25}, {400, 310}, {800.125, 305}};
  photo.traces["left"] = Screen(0.5, -kThird, {-2.4, 0.0});
  TraceSettings contact = Screen(5e-05, -3.9, {-4.0, -2.8});
  contact.t0_div = -10234.567891234567;
  contact.impact = 2;
  photo.traces["contact"] = contact;

  Run csv = photo;
  csv.id = "csv-1";
  csv.photo.reset();
  csv.graticule_corners_px.reset();
  csv.first_rebound = 0;
  csv.traces["right"].points_px.clear();
  for (auto& [name, trace] : csv.traces) trace.csv = "traces/csv-1-" + name + ".csv";

  Run typed;
  typed.id = "typed-1";
  typed.initial_displacement = 0.35;
  typed.rebounds = {0.25, 0.187, 0.141, 0.1};
  typed.fit_rebounds = {1, 3};
  typed.contact_time = 1.234e-4;
  typed.rebound_uncertainty = 0.0005;
  typed.contact_time_uncertainty = 2e-6;
  manifest.runs = {photo, csv, typed};
  return manifest;
}

SessionManifest LogSession() {
  SessionManifest manifest;
  manifest.title = "Logs";
  manifest.units = UnitSystem::kSI;
  Log log;
  log.id = "case1";
  log.experiment = "logs/case1-experiment.csv";
  log.simulation = "logs/case1-simulation.csv";
  log.time_column = "time";
  // Not in alphabetical order: the reader keeps the file's.
  LogChannel encoder;
  encoder.name = "q1";
  encoder.column = "enc1";
  encoder.counts_per_rev = 4096.0;
  encoder.gear_ratio = 50.0;
  LogChannel accelerometer;
  accelerometer.name = "a1";
  accelerometer.column = "acc1";
  accelerometer.sensitivity = 0.1;
  LogChannel strain;  // in SI as it stands
  strain.name = "b0";
  strain.column = "gauge";
  log.channels = {encoder, accelerometer, strain};
  Log experiment_only;
  experiment_only.id = "case2";
  experiment_only.experiment = "logs/case2.csv";
  experiment_only.channels = {accelerometer};
  manifest.logs = {log, experiment_only};
  return manifest;
}

void CheckWrittenAndRead(const SessionManifest& manifest) {
  testing::TempDir dir;
  const fs::path folder = dir.path() / "s";
  for (const Calibration& c : manifest.calibrations) {
    Touch(folder, c.photo);
    Touch(folder, c.trace.csv);
  }
  for (const Run& run : manifest.runs) {
    Touch(folder, run.photo);
    for (const auto& [name, trace] : run.traces) Touch(folder, trace.csv);
  }
  for (const Log& log : manifest.logs) {
    Touch(folder, log.experiment);
    Touch(folder, log.simulation);
  }
  WriteManifest(folder / "session.toml", manifest);
  const ManifestReadResult read = ReadManifest(folder);
  INFO(ManifestText(manifest));
  for (const ManifestWarning& warning : read.warnings) {
    FAIL_CHECK(FormatLocation(warning.where) << ": " << warning.message);
  }
  testing::CheckReadsBack(manifest, read.session);
}

TEST_CASE("synth: a written manifest reads back to the values it was written from") {
  CheckWrittenAndRead(LabSession());
}

TEST_CASE("synth: a written manifest keeps its logs' channels in their order") {
  CheckWrittenAndRead(LogSession());
}

TEST_CASE("synth: a written manifest starts with its comment and says its format") {
  const std::string text = ManifestText(LabSession());
  CHECK(text.rfind("# Written by a test.\n# Two lines of comment.\n", 0) == 0);
  CHECK(text.find("format = 1\n") != std::string::npos);
  CHECK(text.back() == '\n');
  CHECK(text.find("\n\n\n") == std::string::npos);
}

// [specimen]'s keys are io/specimen.h's field names; a field not given is
// not written.
TEST_CASE("synth: a written manifest's [specimen] names each given field by its key") {
  SessionManifest manifest = LabSession();
  Specimen specimen;
  specimen.material = "brass";
  specimen.end_shape = "sphere";
  specimen.sphere_radius = kThird;
  specimen.modulus = 15e6;
  specimen.poisson_ratio = 0.34;
  manifest.specimen = specimen;
  const std::string text = ManifestText(manifest);
  const std::size_t table = text.find("\n[specimen]\n");
  REQUIRE(table != std::string::npos);
  const std::string keys = text.substr(table, text.find("\n\n", table + 1) - table);
  CHECK(keys ==
        "\n[specimen]\nend_shape = \"sphere\"\nmaterial = \"brass\"\nmodulus = 15000000.0\n"
        "poisson_ratio = 0.34000000000000002\nsphere_radius = 0.33333333333333331");
  CHECK(ManifestText(LabSession()).find("[specimen]") == std::string::npos);
}

}  // namespace
}  // namespace impactlab
