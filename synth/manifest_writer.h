// Session manifests written by the generators, with toml++ (the library
// io/manifest.cpp reads them with), under the keys the reader reads
// (docs/manifest.md). The entries are the reader's own types (io/session.h),
// so a generated manifest can be read back and compared with what was planned
// field by field (tests/synth/manifest_writer_test.cpp).
//
// toml++ keeps a table's keys in alphabetical order, so within a table they
// are not in the order docs/manifest.md lists them; the entries themselves
// (calibrations, runs, logs, a log's channels) keep their order, which the
// reader reports them in. A table's numbers are printed with 6 significant
// digits when that is exact, else with 17 (manifest_writer.cpp, Print).
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/session.h"
#include "io/specimen.h"
#include "io/units.h"

namespace impactlab {

// [apparatus] as the thesis gives it: a pendulum's weight, not its mass (the
// reader takes M = weight / g).
struct ManifestApparatus {
  double pendulum_length = 0.0;  // L, length units
  double weight = 0.0;           // W of one pendulum, force units
  Arrangement arrangement = Arrangement::kPair;
};

// What a generated session.toml says. Paths are relative to the session
// folder, as written (the reader returns them resolved against it).
//
// Written when: title if not empty; [apparatus] and [scope] when given; a
// calibration's or run's `photo` and `graticule_corners` when given; a run's
// `calibration` when it names any; `first_rebound` always; `rebounds`,
// `fit_rebounds` with typed-in rebounds; the uncertainties and `contact_time`
// when given; a trace's `csv`, `impact` and `points` when given, its screen
// settings always; a log's `simulation` when given; a channel's
// `counts_per_rev` and `gear_ratio` for an encoder, `sensitivity` when given;
// [specimen] when given, with the keys of its fields that hold something.
struct SessionManifest {
  std::vector<std::string> comment;  // lines above the tables, each written as "# line"
  std::string title;
  UnitSystem units = UnitSystem::kInLbfS;
  std::optional<ManifestApparatus> apparatus;
  std::optional<std::array<int, 2>> divisions;  // [scope]: horizontal, vertical
  std::optional<Specimen> specimen;             // [specimen]: what the bars are
  std::vector<Calibration> calibrations;
  std::vector<Run> runs;
  std::vector<Log> logs;
};

// The manifest's text (format 1).
std::string ManifestText(const SessionManifest& manifest);

// Writes ManifestText to `file`. Throws InputError when it cannot be written.
void WriteManifest(const std::filesystem::path& file, const SessionManifest& manifest);

}  // namespace impactlab
