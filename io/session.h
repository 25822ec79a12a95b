// The lab session manifest, format 1 (docs/manifest.md; contract in session-format.md).
//
// These are plain data: what the manifest says, with paths already resolved and
// checked to lie inside the session folder. Reading and validation live in
// manifest.h; nothing here touches the file system.
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/errors.h"
#include "io/specimen.h"
#include "io/units.h"
#include "options/result_fields.h"
#include "options/settings.h"

namespace impactlab {

enum class Arrangement {
  kPair,  // two identical penduli touching at rest (the thesis's apparatus)
  kWall,  // one pendulum against a rigid stop
};

// impactlab extension: a stage setting as the manifest writes it, in one of
// the stage tables ([digitize], [photocell], [rebound_extraction], [fit],
// [log_analysis]) or an entry's own ([run.digitize], ...); not yet checked
// against the stages' options, which pipeline/stage_options.h applies it to.
struct StageSetting {
  SettingValue value;
  InputLocation where;  // the manifest, the full key ("run \"r1\".digitize.traces.method"), line
};
// By key below the stage tables, e.g. "digitize.traces.method".
using StageSettings = std::map<std::string, StageSetting>;

// The stage tables, in the order reduce runs the stages, and [products]: which
// session-level products to make (pipeline/products.h).
inline constexpr std::array<std::string_view, 6> kStageTables = {
    "digitize", "photocell", "rebound_extraction", "fit", "log_analysis", "products"};

struct Apparatus {
  double pendulum_length = 0.0;  // L, length units
  double mass = 0.0;             // M of one pendulum, mass units (weight / g when given as weight)
  double gravity = 0.0;          // g, length/s^2 (the unit system's default unless given)
  Arrangement arrangement = Arrangement::kPair;

  // What the results file keeps as fields (options/result_fields.h); the
  // arrangement is the manifest's only.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("pendulum_length", self.pendulum_length, Quantity::kLength, "L");
    visit("mass", self.mass, Quantity::kMass, "M of one pendulum");
    visit("gravity", self.gravity, Quantity::kAcceleration, "g");
  }
};

// Screen settings of one oscillograph trace. Positions are in graticule
// divisions: vertical from the graticule centre (up positive), horizontal from
// the left edge.
struct TraceSettings {
  double time_per_div = 0.0;                     // s/div
  double volts_per_div = 0.0;                    // V/div
  double zero_div = 0.0;                         // screen height of 0 V
  std::array<double, 2> band_div = {-4.0, 4.0};  // vertical band the trace stays in
  double t0_div = 0.0;                           // screen position of t = 0 (the release)
  std::optional<int> impact;                 // contact traces: which impact the delayed sweep shows
  std::optional<std::filesystem::path> csv;  // digital trace (time_s,volts) instead of the photo
  // Manual hint (docs/manifest.md, `points`): photo pixels (x right, y down,
  // pixel centres at integers) the trace passes through; empty: none given.
  // The tracking is made to pass through them where the search alone strays.
  std::vector<std::array<double, 2>> points_px;
};

// Manual hint (docs/manifest.md, `graticule_corners`): the photo pixels of the
// graticule's outer corners, in the order top-left, top-right, bottom-right,
// bottom-left as seen on the screen, i.e. screen (0, +ny/2), (nx, +ny/2),
// (nx, -ny/2), (0, -ny/2). They replace the search for the grid's lattice.
using GraticuleCorners = std::array<std::array<double, 2>, 4>;

struct Calibration {
  std::string id;
  std::string cell;                   // "right" or "left"
  double initial_displacement = 0.0;  // X0 of the freely swinging pendulum, length units
  std::optional<std::filesystem::path> photo;
  std::optional<GraticuleCorners> graticule_corners_px;  // manual hint for the photo
  TraceSettings trace;
  StageSettings settings;  // its own [calibration.digitize] and [calibration.photocell]
};

struct Run {
  std::string id;
  double initial_displacement = 0.0;  // X0: half the gap between the bars at release
  std::optional<std::filesystem::path> photo;
  std::optional<GraticuleCorners> graticule_corners_px;  // manual hint for the photo
  std::map<std::string, std::string> calibration;        // cell ("right"/"left") -> calibration id
  int first_rebound = 1;  // rebound, counting from the first impact, that the tables call 0
  std::map<std::string, TraceSettings> traces;  // "right", "left", "contact"

  // Measured values typed in by hand (refitting published data).
  std::vector<double> rebounds;              // Xmax of rebound 0, 1, 2, ... (session numbering)
  std::optional<double> contact_time;        // s
  std::array<int, 2> fit_rebounds = {0, 1};  // the pair a < b the closed-form fit uses
  // impactlab extensions (docs/manifest.md): reading uncertainties of typed-in values.
  std::optional<double> rebound_uncertainty;       // length units, one standard deviation
  std::optional<double> contact_time_uncertainty;  // s, one standard deviation
  StageSettings settings;  // its own [run.digitize] and [run.rebound_extraction]
  // impactlab extension: its own [run.specimen], the keys that differ from the
  // session's [specimen] (empty: none); SpecimenOf gives the two merged.
  Specimen specimen;

  bool HasTypedRebounds() const { return !rebounds.empty(); }
};

struct LogChannel {
  std::string name;                      // e.g. "q1"
  std::string column;                    // CSV column
  std::optional<double> counts_per_rev;  // encoder: angle = 2 pi counts / (cpr * gear_ratio)
  double gear_ratio = 1.0;
  std::optional<double> sensitivity;  // accelerometer: V per g
};

struct Log {
  std::string id;
  std::filesystem::path folder;  // the session folder its files must lie in
  std::filesystem::path experiment;
  std::optional<std::filesystem::path> simulation;
  std::string time_column = "t";
  std::vector<LogChannel> channels;
  StageSettings settings;  // its own [log.log_analysis]
};

// impactlab extension: session-wide reduction settings ([reduction] table).
struct ReductionSettings {
  // One contact time for every run (the thesis's "average experimental contact
  // time", Table 3); a run's own contact_time is used when this is absent.
  std::optional<double> contact_time;  // s
  // "per-run": K from each run's own fit; "average": the mean K of the runs is
  // used for every run and C follows from it (the thesis's design expedient).
  bool average_stiffness = false;
  std::string convention = "exact";      // pendulum: "exact" or "thesis" (PENDUL's small angle)
  std::string separation = "kinematic";  // Kelvin-Voigt contact end: "kinematic" or "force"
};

// impactlab extension: predict one run from another run's parameters (Table 4).
struct Prediction {
  std::string source_run;  // parameters are fitted on this run
  std::string target_run;  // and predict this run's rebounds
  int start_rebound = 0;   // the target's measured rebound the prediction starts from
};

// An entry of the manifest ([[run]], [[calibration]], [[log]] or
// [[prediction]]) that could not be read. It fails alone: the session keeps
// the others, and the runs that need a rejected calibration are rejected too.
struct RejectedEntry {
  std::string table;     // "run", "calibration", "log" or "prediction"
  std::string id;        // its id, or "#N" (1-based position) when it has no usable id
  std::size_t position;  // 0-based among the tables of its kind in the manifest
  InputLocation where;   // the manifest, the key and its line
  std::string problem;   // what was expected and what was found

  std::string Reason() const { return FormatLocation(where) + ": " + problem; }
};

struct Session {
  std::filesystem::path folder;    // the session folder (read-only to us)
  std::filesystem::path manifest;  // folder / "session.toml"
  int format = 1;
  std::string title;
  UnitSystem units = UnitSystem::kInLbfS;
  std::optional<Apparatus> apparatus;  // required when the session has runs
  std::array<int, 2> divisions = {10, 8};
  std::vector<Calibration> calibrations;
  std::vector<Run> runs;
  std::vector<Log> logs;
  ReductionSettings reduction;
  StageSettings settings;  // the stage tables: every run's, calibration's and log's
  std::vector<Prediction> predictions;
  std::vector<RejectedEntry> rejected;  // in manifest order within each kind
  Specimen specimen;  // impactlab extension: [specimen], what the bars are (empty: not given)

  // The rejected entries of one kind ("run", "calibration", ...).
  std::vector<RejectedEntry> Rejected(std::string_view table) const {
    std::vector<RejectedEntry> out;
    for (const RejectedEntry& entry : rejected) {
      if (entry.table == table) out.push_back(entry);
    }
    return out;
  }
};

// A run's specimen: the session's [specimen] with the run's own
// [run.specimen] keys put in its place, key by key.
inline Specimen SpecimenOf(const Specimen& session, const Specimen& run) {
  Specimen merged = session;
  if (!run.material.empty()) merged.material = run.material;
  if (!run.end_shape.empty()) merged.end_shape = run.end_shape;
  for (auto [own, field] : {std::pair{&run.edge_radius, &merged.edge_radius},
                            std::pair{&run.sphere_radius, &merged.sphere_radius},
                            std::pair{&run.contact_stiffness, &merged.contact_stiffness},
                            std::pair{&run.bar_length, &merged.bar_length},
                            std::pair{&run.bar_diameter, &merged.bar_diameter},
                            std::pair{&run.modulus, &merged.modulus},
                            std::pair{&run.poisson_ratio, &merged.poisson_ratio}}) {
    if (*own) *field = *own;
  }
  return merged;
}

}  // namespace impactlab
