// Tests of the manifest reader: valid sessions read to the expected values, and
// every kind of bad manifest is refused with the file, the key, the line and what
// was expected.
#include <fmt/format.h>
// Show std::optional values (lines) in failed checks.
#define CATCH_CONFIG_ENABLE_OPTIONAL_STRINGMAKER
#include <catch2/catch.hpp>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include "io/manifest.h"
#include "tests/io/session_folder.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using testing::SessionFolder;
using testing::TempDir;

// The 1-based line of the `occurrence`-th (1-based) line containing `needle`.
long long LineContaining(const std::string& text, std::string_view needle, int occurrence = 1) {
  long long line = 1;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    if (std::string_view(text).substr(start, end - start).find(needle) != std::string_view::npos &&
        --occurrence == 0) {
      return line;
    }
    start = end + 1;
    ++line;
  }
  FAIL("no line contains " << needle);
  return 0;
}

struct Failure {
  InputLocation where;
  std::string problem;
  std::string what;
};

// The manifest's refusal: an InputError for the whole manifest, or else the
// first entry rejected alone.
Failure ReadFailure(const SessionFolder& folder) {
  try {
    const ManifestReadResult result = folder.Read();
    if (!result.session.rejected.empty()) {
      const RejectedEntry& entry = result.session.rejected.front();
      return Failure{entry.where, entry.problem, entry.Reason()};
    }
  } catch (const InputError& error) {
    return Failure{error.where(), error.problem(), error.what()};
  }
  FAIL("the manifest was accepted, but an InputError or a rejected entry was expected");
  return {};
}

// Writes `text`, reads it, and checks the error names the manifest, `key` and
// `line`, and says `expected`.
void CheckRefused(const SessionFolder& folder, const std::string& text, const std::string& key,
                  std::optional<long long> line, const std::string& expected) {
  folder.Write(text);
  const Failure failure = ReadFailure(folder);
  INFO("message: " << failure.what);
  CHECK(failure.where.file == folder.manifest());
  CHECK(failure.where.key == key);
  CHECK(failure.where.line == line);
  CHECK_THAT(failure.problem, Contains(expected));
  CHECK_THAT(failure.what, Contains(folder.manifest().string()));
}

// The example of session-format.md, with the left calibration it refers to.
const std::string kExample =
    R"toml(format = 1                      # required; this page describes format 1
title = "Steel bars, plane ends"
units = "in-lbf-s"              # "in-lbf-s" (g = 385.644 in/s^2) or "SI" (m, kg, N, s)

[apparatus]
pendulum_length = 22.0          # L
weight = 2.23                   # weight of one pendulum (force units); or `mass = ...`
gravity = 385.644               # optional, defaults to the value for `units`
arrangement = "pair"            # "pair": two identical penduli touching at rest (default);
                                # "wall": one pendulum against a rigid stop

[scope]                         # defaults for every trace below; any trace may override
divisions = [10, 8]             # graticule divisions, horizontal x vertical

[[calibration]]
id = "R-0.234"
cell = "right"                  # "right" or "left": which photocell this calibrates
initial_displacement = 0.234    # release displacement X0 of the freely swinging pendulum
photo = "calibration/R-0.234.jpg"
[calibration.trace]
time_per_div = 0.05             # s/div
volts_per_div = 0.2             # V/div
zero_div = -3.0                 # screen height of 0 V, in divisions from the graticule centre, up
                                # positive; it may lie off screen
band_div = [-4.0, 4.0]          # the vertical band (divisions from centre) the trace stays in
t0_div = 0.0                    # screen position of t = 0 (the release), divisions from the left edge

[[calibration]]
id = "L-0.234"
cell = "left"
initial_displacement = 0.234
photo = "calibration/L-0.234.jpg"
[calibration.trace]
time_per_div = 0.05
volts_per_div = 0.2
zero_div = 3.0
band_div = [-4.0, 4.0]
t0_div = 0.5

[[run]]
id = "0.234"
initial_displacement = 0.234    # X0: half the gap measured between the bars at release
photo = "runs/0.234.jpg"
calibration = { right = "R-0.234", left = "L-0.234" }
first_rebound = 1               # which rebound, counting from the first impact, the
                                # table calls rebound 0 (the thesis's Figure 15); default 1
[run.traces.right]              # displacement photocell of the right pendulum
time_per_div = 0.5
volts_per_div = 0.2
zero_div = 0.5
band_div = [0.0, 4.0]
t0_div = 0.0
[run.traces.left]
time_per_div = 0.5
volts_per_div = 0.2
zero_div = -3.5
band_div = [-4.0, 0.0]
t0_div = 0.0
[run.traces.contact]            # contact circuit: high while the bars touch
time_per_div = 100e-6
volts_per_div = 1.0
zero_div = -3.0
band_div = [-4.0, -1.0]
impact = 2                      # which impact (counting from the first) the delayed sweep shows

[[run]]
id = "0.405"
initial_displacement = 0.405
contact_time = 352e-6           # s, optional
rebounds = [0.293, 0.195, 0.117, 0.060, 0.053]   # Xmax of rebound 0, 1, 2, …
fit_rebounds = [0, 1]           # optional, any run: the two rebounds a closed-form

[[run]]
id = "csv"
initial_displacement = 0.3
[run.traces.right]
csv = "traces/csv-right.csv"

[[log]]
id = "case1"
experiment = "logs/case1-experiment.csv"
simulation = "logs/case1-simulation.csv"   # optional: a model's output in the same columns
time_column = "t"                          # seconds
[log.channels]
q1 = { column = "enc1", counts_per_rev = 4096, gear_ratio = 1.0 }   # encoder -> angle
q4 = { column = "enc2", counts_per_rev = 4096, gear_ratio = 1.0 }
a1 = { column = "acc1", sensitivity = 0.100 }   # V per g; the column is in volts
a2 = { column = "acc2", sensitivity = 0.005 }
)toml";

void TouchExampleFiles(const SessionFolder& folder) {
  for (const char* file :
       {"calibration/R-0.234.jpg", "calibration/L-0.234.jpg", "runs/0.234.jpg",
        "traces/csv-right.csv", "logs/case1-experiment.csv", "logs/case1-simulation.csv"}) {
    folder.Touch(file);
  }
}

// The start of most bad manifests below: valid on its own.
using testing::kManifestHeader;

// A valid run read from a photo, for cases that break one of its keys.
const std::string kPhotoRun = R"toml(
[[run]]
id = "0.234"
initial_displacement = 0.234
photo = "runs/0.234.jpg"
[run.traces.right]
time_per_div = 0.5
volts_per_div = 0.2
zero_div = 0.5
band_div = [0.0, 4.0]
)toml";

// A valid typed-in run.
const std::string kTypedRun = R"toml(
[[run]]
id = "0.405"
initial_displacement = 0.405
rebounds = [0.293, 0.195, 0.117, 0.060, 0.053]
)toml";

// ---------------------------------------------------------------------------
// Valid sessions.

TEST_CASE("manifest: the session-format example reads to the expected values") {
  SessionFolder folder;
  TouchExampleFiles(folder);
  folder.Write(kExample);
  const ManifestReadResult result = folder.Read();
  const Session& session = result.session;

  CHECK(result.warnings.empty());
  CHECK(session.folder == folder.path());
  CHECK(session.manifest == folder.manifest());
  CHECK(session.format == 1);
  CHECK(session.title == "Steel bars, plane ends");
  CHECK(session.units == UnitSystem::kInLbfS);
  REQUIRE(session.apparatus);
  CHECK(session.apparatus->pendulum_length == 22.0);
  CHECK(session.apparatus->gravity == 385.644);
  CHECK(session.apparatus->mass == Approx(2.23 / 385.644).epsilon(1e-14));
  CHECK(session.apparatus->arrangement == Arrangement::kPair);
  CHECK(session.divisions == std::array<int, 2>{10, 8});

  REQUIRE(session.calibrations.size() == 2);
  const Calibration& right = session.calibrations[0];
  CHECK(right.id == "R-0.234");
  CHECK(right.cell == "right");
  CHECK(right.initial_displacement == 0.234);
  CHECK(right.photo == folder.path() / "calibration/R-0.234.jpg");
  CHECK(right.trace.time_per_div == 0.05);
  CHECK(right.trace.volts_per_div == 0.2);
  CHECK(right.trace.zero_div == -3.0);
  CHECK(right.trace.band_div == std::array<double, 2>{-4.0, 4.0});
  CHECK(right.trace.t0_div == 0.0);
  CHECK_FALSE(right.trace.impact);
  CHECK_FALSE(right.trace.csv);
  CHECK(session.calibrations[1].cell == "left");
  CHECK(session.calibrations[1].trace.t0_div == 0.5);

  REQUIRE(session.runs.size() == 3);
  const Run& photo_run = session.runs[0];
  CHECK(photo_run.id == "0.234");
  CHECK(photo_run.initial_displacement == 0.234);
  CHECK(photo_run.photo == folder.path() / "runs/0.234.jpg");
  CHECK(photo_run.calibration ==
        std::map<std::string, std::string>{{"right", "R-0.234"}, {"left", "L-0.234"}});
  CHECK(photo_run.first_rebound == 1);
  CHECK_FALSE(photo_run.HasTypedRebounds());
  REQUIRE(photo_run.traces.size() == 3);
  CHECK(photo_run.traces.at("right").zero_div == 0.5);
  CHECK(photo_run.traces.at("right").band_div == std::array<double, 2>{0.0, 4.0});
  CHECK(photo_run.traces.at("left").zero_div == -3.5);
  const TraceSettings& contact = photo_run.traces.at("contact");
  CHECK(contact.time_per_div == 100e-6);
  CHECK(contact.volts_per_div == 1.0);
  CHECK(contact.band_div == std::array<double, 2>{-4.0, -1.0});
  CHECK(contact.t0_div == 0.0);  // not given: the default
  CHECK(contact.impact == 2);

  const Run& typed = session.runs[1];
  CHECK(typed.id == "0.405");
  CHECK_FALSE(typed.photo);
  CHECK(typed.contact_time == 352e-6);
  CHECK(typed.rebounds == std::vector<double>{0.293, 0.195, 0.117, 0.060, 0.053});
  CHECK(typed.fit_rebounds == std::array<int, 2>{0, 1});
  CHECK(typed.traces.empty());

  const Run& csv_run = session.runs[2];
  CHECK_FALSE(csv_run.photo);
  REQUIRE(csv_run.traces.count("right") == 1);
  CHECK(csv_run.traces.at("right").csv == folder.path() / "traces/csv-right.csv");

  REQUIRE(session.logs.size() == 1);
  const Log& log = session.logs[0];
  CHECK(log.id == "case1");
  CHECK(log.experiment == folder.path() / "logs/case1-experiment.csv");
  CHECK(log.simulation == folder.path() / "logs/case1-simulation.csv");
  CHECK(log.time_column == "t");
  REQUIRE(log.channels.size() == 4);
  // In the order written, not toml++'s sorted order.
  CHECK(log.channels[0].name == "q1");
  CHECK(log.channels[0].column == "enc1");
  CHECK(log.channels[0].counts_per_rev == 4096.0);
  CHECK(log.channels[0].gear_ratio == 1.0);
  CHECK_FALSE(log.channels[0].sensitivity);
  CHECK(log.channels[1].name == "q4");
  CHECK(log.channels[2].name == "a1");
  CHECK(log.channels[2].sensitivity == 0.1);
  CHECK_FALSE(log.channels[2].counts_per_rev);
  CHECK(log.channels[3].name == "a2");

  CHECK_FALSE(session.reduction.contact_time);
  CHECK_FALSE(session.reduction.average_stiffness);
  CHECK(session.reduction.convention == "exact");
  CHECK(session.reduction.separation == "kinematic");
  CHECK(session.predictions.empty());
}

TEST_CASE("manifest: [scope] trace keys are defaults every trace may override; SI units") {
  SessionFolder folder;
  folder.Touch("runs/a.png");
  folder.Touch("calibration/r.png");
  folder.Write(R"toml(format = 1
units = "SI"
[apparatus]
pendulum_length = 0.56
weight = 9.80665
[scope]
divisions = [12, 10]
time_per_div = 0.5
volts_per_div = 0.2
t0_div = 1.0
impact = 3
[[calibration]]
id = "r"
cell = "right"
initial_displacement = 0.006
photo = "calibration/r.png"
[[run]]
id = "a"
initial_displacement = 0.006
photo = "runs/a.png"
calibration = { right = "r" }
[run.traces.right]
zero_div = 0.5
band_div = [0.0, 4.0]
[run.traces.left]
volts_per_div = 0.5
zero_div = -3.5
[run.traces.contact]
time_per_div = 1e-4
)toml");
  const Session session = folder.Read().session;
  CHECK(session.units == UnitSystem::kSI);
  REQUIRE(session.apparatus);
  CHECK(session.apparatus->gravity == 9.80665);
  CHECK(session.apparatus->mass == Approx(1.0).epsilon(1e-15));
  CHECK(session.apparatus->arrangement == Arrangement::kPair);  // the default
  CHECK(session.divisions == std::array<int, 2>{12, 10});

  // The calibration has no trace table at all: everything comes from [scope].
  const TraceSettings& calibration = session.calibrations.at(0).trace;
  CHECK(calibration.time_per_div == 0.5);
  CHECK(calibration.volts_per_div == 0.2);
  CHECK(calibration.t0_div == 1.0);
  CHECK_FALSE(calibration.impact);

  const auto& traces = session.runs.at(0).traces;
  CHECK(traces.at("right").time_per_div == 0.5);
  CHECK(traces.at("right").volts_per_div == 0.2);
  CHECK(traces.at("right").t0_div == 1.0);
  CHECK(traces.at("left").volts_per_div == 0.5);  // overridden
  CHECK(traces.at("left").zero_div == -3.5);
  CHECK(traces.at("left").band_div == std::array<double, 2>{-5.0, 5.0});  // whole screen
  CHECK(traces.at("contact").time_per_div == 1e-4);
  CHECK(traces.at("contact").volts_per_div == 0.2);
  CHECK(traces.at("contact").zero_div == 0.0);
  CHECK(traces.at("contact").impact == 3);
  CHECK_FALSE(traces.at("right").impact);
}

TEST_CASE("manifest: a typed-in session with the impactlab extensions reads") {
  SessionFolder folder;
  folder.Write(R"toml(format = 1
title = "Table 3, refitted"
[apparatus]
pendulum_length = 22.0
mass = 0.0058
[[run]]
id = "0.405"
initial_displacement = 0.405
contact_time = 352e-6
rebounds = [0.293, 0.195, 0.117, 0.060, 0.053]
fit_rebounds = [1, 3]
first_rebound = 2
rebound_uncertainty = 0.002
contact_time_uncertainty = 5e-6
[[run]]
id = "0.234"
initial_displacement = 0.234
rebounds = [0.170, 0.111]
[reduction]
contact_time = 340e-6
stiffness = "average"
convention = "thesis"
separation = "force"
[[prediction]]
source_run = "0.405"
target_run = "0.234"
start_rebound = 1
[[prediction]]
source_run = "0.234"
target_run = "0.405"
)toml");
  const ManifestReadResult result = folder.Read();
  CHECK(result.warnings.empty());
  const Session& session = result.session;
  CHECK(session.title == "Table 3, refitted");
  REQUIRE(session.apparatus);
  CHECK(session.apparatus->mass == 0.0058);
  CHECK(session.apparatus->gravity == 385.644);
  REQUIRE(session.runs.size() == 2);
  const Run& run = session.runs[0];
  CHECK_FALSE(run.photo);
  CHECK(run.HasTypedRebounds());
  CHECK(run.rebounds.size() == 5);
  CHECK(run.contact_time == 352e-6);
  CHECK(run.fit_rebounds == std::array<int, 2>{1, 3});
  CHECK(run.first_rebound == 2);
  CHECK(run.rebound_uncertainty == 0.002);
  CHECK(run.contact_time_uncertainty == 5e-6);
  CHECK_FALSE(session.runs[1].rebound_uncertainty);
  CHECK(session.reduction.contact_time == 340e-6);
  CHECK(session.reduction.average_stiffness);
  CHECK(session.reduction.convention == "thesis");
  CHECK(session.reduction.separation == "force");
  REQUIRE(session.predictions.size() == 2);
  CHECK(session.predictions[0].source_run == "0.405");
  CHECK(session.predictions[0].target_run == "0.234");
  CHECK(session.predictions[0].start_rebound == 1);
  CHECK(session.predictions[1].start_rebound == 0);
}

TEST_CASE("manifest: the example in docs/manifest.md reads without warnings") {
  std::ifstream doc(fs::path(IMPACTLAB_SOURCE_DIR) / "docs/manifest.md");
  REQUIRE(doc);
  const std::string text((std::istreambuf_iterator<char>(doc)), std::istreambuf_iterator<char>());
  const std::size_t example = text.find("## Example");
  REQUIRE(example != std::string::npos);
  const std::size_t start = text.find("```toml\n", example) + 8;
  const std::size_t end = text.find("```", start);
  REQUIRE(end != std::string::npos);

  SessionFolder folder;
  for (const char* file : {"calibration/R-0.234.jpg", "calibration/L-0.234.jpg", "runs/0.234.jpg",
                           "traces/0.234-contact.csv", "logs/case1-experiment.csv"}) {
    folder.Touch(file);
  }
  folder.Write(text.substr(start, end - start));
  const ManifestReadResult result = folder.Read();
  for (const ManifestWarning& warning : result.warnings) {
    FAIL_CHECK(FormatLocation(warning.where) << ": " << warning.message);
  }
  const Session& session = result.session;
  CHECK(session.apparatus->mass == Approx(2.23 / 385.644));
  CHECK(session.calibrations.at(1).trace.band_div == std::array<double, 2>{-4.0, 4.0});
  CHECK(session.runs.at(0).traces.at("contact").csv == folder.path() / "traces/0.234-contact.csv");
  CHECK(session.runs.at(1).rebound_uncertainty == 0.002);
  CHECK(session.reduction.average_stiffness);
  CHECK(session.predictions.size() == 1);
}

TEST_CASE("manifest: the project's sample session reads without warnings") {
  const fs::path sample = fs::path(IMPACTLAB_SOURCE_DIR) / "sample_data/thesis-1969";
  const ManifestReadResult result = ReadManifest(sample);
  for (const ManifestWarning& warning : result.warnings) {
    FAIL_CHECK(FormatLocation(warning.where) << ": " << warning.message);
  }
  CHECK_FALSE(result.session.runs.empty());
  CHECK(result.session.apparatus.has_value());
}

TEST_CASE("manifest: ParseManifest resolves paths against the manifest's folder") {
  SessionFolder folder;
  folder.Touch("runs/a.jpg");
  const ManifestReadResult result = ParseManifest(kManifestHeader + R"toml(
[[run]]
id = "a"
initial_displacement = 0.2
photo = "runs/a.jpg"
[run.traces.right]
time_per_div = 0.5
volts_per_div = 0.2
)toml",
                                                  folder.manifest());
  CHECK(result.session.folder == folder.path());
  CHECK(result.session.manifest == folder.manifest());
  CHECK(result.session.runs.at(0).photo == folder.path() / "runs/a.jpg");
  CHECK(result.session.units == UnitSystem::kInLbfS);
  CHECK(result.session.divisions == std::array<int, 2>{10, 8});
  // No [scope] band: the trace may be anywhere on the 8-division-high screen.
  CHECK(result.session.runs.at(0).traces.at("right").band_div == std::array<double, 2>{-4.0, 4.0});
}

TEST_CASE("manifest: a session without runs needs no apparatus") {
  SessionFolder folder;
  folder.Touch("logs/x.csv");
  folder.Write(
      "format = 1\n[[log]]\nid = \"x\"\nexperiment = \"logs/x.csv\"\n"
      "[log.channels]\nq1 = { counts_per_rev = 1024, gear_ratio = 2.0 }\n");
  const Session session = folder.Read().session;
  CHECK_FALSE(session.apparatus);
  REQUIRE(session.logs.at(0).channels.size() == 1);
  CHECK(session.logs[0].channels[0].column == "q1");  // defaults to the channel's name
  CHECK(session.logs[0].channels[0].gear_ratio == 2.0);
  CHECK_FALSE(session.logs[0].simulation);
}

TEST_CASE("manifest: reading never writes into the session folder") {
  SessionFolder folder;
  TouchExampleFiles(folder);
  folder.Write(kExample);
  const auto listing = [&] {
    std::set<std::string> files;
    for (const auto& entry : fs::recursive_directory_iterator(folder.path())) {
      files.insert(entry.path().string() + " " +
                   std::to_string(entry.is_regular_file() ? fs::file_size(entry) : 0));
    }
    return files;
  };
  const auto before = listing();
  folder.Read();
  CHECK(listing() == before);
}

// ---------------------------------------------------------------------------
// Unknown keys.

TEST_CASE("manifest: unknown keys give warnings and do not stop reading") {
  SessionFolder folder;
  folder.Touch("runs/0.234.jpg");
  const std::string text = kManifestHeader + "colour = \"red\"\n" + kPhotoRun +
                           "volts_per_dvi = 0.3\n"
                           "[run.traces.left]\ntime_per_div = 0.5\nvolts_per_div = 0.2\n"
                           "impact = 2\n" +
                           kTypedRun + "contact_tme = 1e-4\n" +
                           "[run.traces.middle]\nzero_div = 1\n" + "[mystery]\nx = 1\n";
  folder.Write(text);
  const ManifestReadResult result = folder.Read();
  CHECK(result.session.runs.size() == 2);
  CHECK(result.session.runs[0].traces.at("right").volts_per_div == 0.2);

  std::vector<std::pair<std::string, std::optional<long long>>> found;
  for (const ManifestWarning& warning : result.warnings) {
    INFO(FormatLocation(warning.where) << ": " << warning.message);
    CHECK(warning.where.file == folder.manifest());
    found.emplace_back(warning.where.key, warning.where.line);
  }
  using Found = std::pair<std::string, std::optional<long long>>;
  CHECK(std::count(found.begin(), found.end(),
                   Found{"apparatus.colour", LineContaining(text, "colour")}) == 1);
  CHECK(std::count(found.begin(), found.end(),
                   Found{"run \"0.234\".traces.right.volts_per_dvi",
                         LineContaining(text, "volts_per_dvi")}) == 1);
  CHECK(std::count(found.begin(), found.end(),
                   Found{"run \"0.234\".traces.left.impact", LineContaining(text, "impact")}) == 1);
  CHECK(std::count(found.begin(), found.end(),
                   Found{"run \"0.405\".contact_tme", LineContaining(text, "contact_tme")}) == 1);
  CHECK(std::count(found.begin(), found.end(),
                   Found{"run \"0.405\".traces.middle", LineContaining(text, "middle")}) == 1);
  CHECK(std::count(found.begin(), found.end(),
                   Found{"mystery", LineContaining(text, "[mystery]")}) == 1);
  CHECK(found.size() == 6);

  const auto colour = std::find_if(result.warnings.begin(), result.warnings.end(),
                                   [](const auto& w) { return w.where.key == "apparatus.colour"; });
  REQUIRE(colour != result.warnings.end());
  CHECK(colour->message == "unknown key 'colour' (ignored)");
}

TEST_CASE("manifest: a mistyped key is answered with the key it was likely meant to be") {
  SessionFolder folder;
  const std::string text = kManifestHeader + kTypedRun + "contact_tme = 1e-4\n" + R"toml(
[[run]]
id = "typo-x0"
initial_displacment = 0.3
rebounds = [0.2, 0.1]

[[run]]
id = "typo-rebounds"
initial_displacement = 0.3
rebounds_ = [0.2, 0.1]
)toml";
  folder.Write(text);
  const ManifestReadResult result = folder.Read();
  const auto warning =
      std::find_if(result.warnings.begin(), result.warnings.end(),
                   [](const auto& w) { return w.where.key == "run \"0.405\".contact_tme"; });
  REQUIRE(warning != result.warnings.end());
  CHECK(warning->message == "unknown key 'contact_tme' (ignored) (did you mean \"contact_time\"?)");
  // The required key's absence is said with the near miss beside it, and the
  // run that has only a mistyped `rebounds` is told which key it missed.
  REQUIRE(result.session.rejected.size() == 2);
  CHECK_THAT(result.session.rejected[0].Reason(),
             Catch::Contains("required key is missing") &&
                 Catch::Contains("the table has `initial_displacment`: a typo?"));
  CHECK_THAT(result.session.rejected[1].Reason(),
             Catch::Contains("nothing to reduce") &&
                 Catch::Contains("`rebounds_` is not a key (did you mean \"rebounds\"?)"));
}

TEST_CASE("manifest: the session folder or its session.toml reads the same") {
  const fs::path sample = fs::path(IMPACTLAB_SOURCE_DIR) / "sample_data/thesis-1969";
  const Session by_folder = ReadManifest(sample).session;
  const Session by_manifest = ReadManifest(sample / "session.toml").session;
  CHECK(by_manifest.folder == by_folder.folder);
  CHECK(by_manifest.runs.size() == by_folder.runs.size());
  CHECK(SessionFolderOf(sample / "session.toml") == sample);
  CHECK(SessionFolderOf(sample) == sample);
}

// ---------------------------------------------------------------------------
// Bad manifests: each names the file, the key, the line, and what was expected.

TEST_CASE("manifest: a negative volts_per_div names the key and line") {
  SessionFolder folder;
  folder.Touch("runs/0.234.jpg");
  std::string text = kManifestHeader + kPhotoRun;
  text.replace(text.find("volts_per_div = 0.2"), 19, "volts_per_div = -0.2");
  CheckRefused(folder, text, "run \"0.234\".traces.right.volts_per_div",
               LineContaining(text, "-0.2"), "expected a positive number of V/div, found -0.2");
}

TEST_CASE("manifest: a string where a number belongs is refused") {
  SessionFolder folder;
  const std::string text =
      kManifestHeader + "[[run]]\nid = \"x\"\ninitial_displacement = \"abc\"\n";
  CheckRefused(folder, text, "run \"x\".initial_displacement", LineContaining(text, "abc"),
               "expected a positive displacement X0 (in), found string \"abc\"");
}

TEST_CASE("manifest: nan and inf are refused although TOML allows them") {
  SessionFolder folder;
  SECTION("nan pendulum length") {
    const std::string text = "format = 1\n[apparatus]\npendulum_length = nan\nweight = 2.0\n";
    CheckRefused(folder, text, "apparatus.pendulum_length", 3,
                 "expected a positive length (in), found nan, which is not a finite number");
  }
  SECTION("inf time/div in [scope]") {
    const std::string text = kManifestHeader + "[scope]\ntime_per_div = inf\n";
    CheckRefused(folder, text, "scope.time_per_div", LineContaining(text, "inf"),
                 "expected a positive number of s/div, found inf");
  }
}

TEST_CASE("manifest: a missing or wrong format is refused") {
  SessionFolder folder;
  SECTION("missing") {
    CheckRefused(folder, "title = \"x\"\n", "format", std::nullopt,
                 "required key is missing; expected the manifest format 1");
  }
  SECTION("format 2") {
    CheckRefused(folder, "title = \"x\"\nformat = 2\n", "format", 2,
                 "expected the manifest format 1, found 2");
  }
  SECTION("a string") {
    CheckRefused(folder, "format = \"1\"\n", "format", 1,
                 "expected the manifest format 1, found string \"1\"");
  }
}

TEST_CASE("manifest: an unknown units string is refused") {
  SessionFolder folder;
  CheckRefused(folder, "format = 1\n\nunits = \"cgs\"\n", "units", 3,
               "expected \"in-lbf-s\" or \"SI\", found \"cgs\"");
}

TEST_CASE("manifest: the apparatus needs exactly one of weight and mass") {
  SessionFolder folder;
  SECTION("both") {
    const std::string text = kManifestHeader + "mass = 0.006\n";
    CheckRefused(folder, text, "apparatus.mass", LineContaining(text, "mass"),
                 "expected either `weight` or `mass` of one pendulum, found both");
  }
  SECTION("neither") {
    const std::string text = "format = 1\n[apparatus]\npendulum_length = 22.0\n";
    CheckRefused(folder, text, "apparatus", 2,
                 "required key is missing; expected `weight` (lbf) or `mass` (lbf*s^2/in)");
  }
  SECTION("zero weight") {
    const std::string text = "format = 1\n[apparatus]\npendulum_length = 22.0\nweight = 0\n";
    CheckRefused(folder, text, "apparatus.weight", 4, "expected a positive weight (lbf), found 0");
  }
  SECTION("negative gravity") {
    const std::string text = kManifestHeader + "gravity = -9.8\n";
    CheckRefused(folder, text, "apparatus.gravity", LineContaining(text, "gravity"),
                 "expected a positive acceleration (in/s^2), found -9.8");
  }
}

TEST_CASE("manifest: runs without an [apparatus] are refused") {
  SessionFolder folder;
  const std::string text = "format = 1\n" + kTypedRun;
  CheckRefused(folder, text, "apparatus", std::nullopt,
               fmt::format("expected an [apparatus] table, which a session with runs needs (the "
                           "first run is run \"0.405\" at line {})",
                           LineContaining(text, "[[run]]")));
}

TEST_CASE("manifest: a required key missing from a run points at the run's header") {
  SessionFolder folder;
  const std::string text = kManifestHeader + "\n[[run]]\nid = \"x\"\nrebounds = [0.1]\n";
  CheckRefused(folder, text, "run \"x\".initial_displacement", LineContaining(text, "[[run]]"),
               "required key is missing; expected a positive displacement X0 (in)");
}

TEST_CASE("manifest: a band_div with lo >= hi is refused") {
  SessionFolder folder;
  folder.Touch("runs/0.234.jpg");
  std::string text = kManifestHeader + kPhotoRun;
  text.replace(text.find("band_div = [0.0, 4.0]"), 21, "band_div = [4.0, -4.0]");
  CheckRefused(folder, text, "run \"0.234\".traces.right.band_div",
               LineContaining(text, "band_div"), "with lo < hi, found [4, -4]");
}

TEST_CASE("manifest: duplicate ids are refused") {
  SessionFolder folder;
  SECTION("runs") {
    const std::string text = kManifestHeader + kTypedRun + kTypedRun;
    CheckRefused(folder, text, "run \"0.405\".id", LineContaining(text, "id = ", 2),
                 fmt::format("expected an id no other run has, found \"0.405\", already used by "
                             "the run at line {}",
                             LineContaining(text, "id = ")));
  }
  SECTION("calibrations") {
    folder.Touch("c.png");
    const std::string calibration =
        "\n[[calibration]]\nid = \"R\"\ncell = \"right\"\ninitial_displacement = 0.2\n"
        "photo = \"c.png\"\n[calibration.trace]\ntime_per_div = 0.05\nvolts_per_div = 0.2\n";
    const std::string text = "format = 1\n" + calibration + calibration;
    CheckRefused(folder, text, "calibration \"R\".id", LineContaining(text, "id = ", 2),
                 "expected an id no other calibration has, found \"R\"");
  }
  SECTION("logs") {
    folder.Touch("l.csv");
    const std::string log = "\n[[log]]\nid = \"L\"\nexperiment = \"l.csv\"\n";
    const std::string text = "format = 1\n" + log + log;
    CheckRefused(folder, text, "log \"L\".id", LineContaining(text, "id = ", 2),
                 "expected an id no other log has, found \"L\"");
  }
}

TEST_CASE("manifest: a run's calibration must exist and be for the same cell") {
  SessionFolder folder;
  folder.Touch("c.png");
  const std::string calibration =
      "\n[[calibration]]\nid = \"R\"\ncell = \"right\"\ninitial_displacement = 0.2\n"
      "photo = \"c.png\"\n[calibration.trace]\ntime_per_div = 0.05\nvolts_per_div = 0.2\n";
  SECTION("unknown id") {
    const std::string text = kManifestHeader + calibration + kTypedRun +
                             "calibration = { right = \"R\", left = \"L-9\" }\n";
    CheckRefused(folder, text, "run \"0.405\".calibration.left",
                 LineContaining(text, "calibration = {"),
                 "expected the id of a [[calibration]] for the left cell, found \"L-9\", which no "
                 "calibration has (known: \"R\")");
  }
  SECTION("wrong cell") {
    const std::string text =
        kManifestHeader + calibration + kTypedRun + "calibration = { left = \"R\" }\n";
    CheckRefused(folder, text, "run \"0.405\".calibration.left",
                 LineContaining(text, "calibration = {"),
                 "found \"R\", which calibrates the right cell");
  }
  SECTION("unknown cell in a calibration") {
    const std::string text = "format = 1\n" + calibration;
    std::string bad = text;
    bad.replace(bad.find("\"right\""), 7, "\"middle\"");
    CheckRefused(folder, bad, "calibration \"R\".cell", LineContaining(bad, "middle"),
                 "expected \"right\" or \"left\", found \"middle\"");
  }
}

TEST_CASE("manifest: fit_rebounds must be increasing and within the typed-in rebounds") {
  SessionFolder folder;
  SECTION("beyond the last rebound") {
    const std::string text = kManifestHeader + kTypedRun + "fit_rebounds = [0, 5]\n";
    CheckRefused(folder, text, "run \"0.405\".fit_rebounds", LineContaining(text, "fit_rebounds"),
                 "expected two rebound numbers [a, b] with 0 <= a < b < 5 (the run has 5 typed-in "
                 "rebounds, numbered 0 to 4), found [0, 5]");
  }
  SECTION("not increasing") {
    const std::string text = kManifestHeader + kTypedRun + "fit_rebounds = [1, 1]\n";
    CheckRefused(folder, text, "run \"0.405\".fit_rebounds", LineContaining(text, "fit_rebounds"),
                 "expected two rebound numbers [a, b] with 0 <= a < b, found [1, 1]");
  }
  SECTION("negative") {
    const std::string text = kManifestHeader + kTypedRun + "fit_rebounds = [-1, 1]\n";
    CheckRefused(folder, text, "run \"0.405\".fit_rebounds[0]",
                 LineContaining(text, "fit_rebounds"), "expected a rebound number >= 0, found -1");
  }
  SECTION("three numbers") {
    const std::string text = kManifestHeader + kTypedRun + "fit_rebounds = [0, 1, 2]\n";
    CheckRefused(folder, text, "run \"0.405\".fit_rebounds", LineContaining(text, "fit_rebounds"),
                 "found an array of 3 values");
  }
}

TEST_CASE("manifest: typed-in rebounds must be positive numbers") {
  SessionFolder folder;
  const std::string text = kManifestHeader + "[[run]]\nid = \"r\"\ninitial_displacement = 0.4\n" +
                           "rebounds = [0.29,\n  0.19,\n  -0.1]\n";
  CheckRefused(folder, text, "run \"r\".rebounds[2]", LineContaining(text, "-0.1"),
               "expected a positive rebound amplitude (in), found -0.1");
}

TEST_CASE("manifest: a run with nothing to reduce is refused") {
  SessionFolder folder;
  const std::string text =
      kManifestHeader + "\n[[run]]\nid = \"empty\"\ninitial_displacement = 0.4\n";
  CheckRefused(folder, text, "run \"empty\"", LineContaining(text, "[[run]]"),
               "the run has nothing to reduce; expected a `photo`, traces with `csv` files, or "
               "typed-in `rebounds`");
}

TEST_CASE("manifest: a photo trace in a run without a photo is refused") {
  SessionFolder folder;
  std::string text = kManifestHeader + kPhotoRun;
  text.erase(text.find("photo = "), std::string("photo = \"runs/0.234.jpg\"\n").size());
  CheckRefused(folder, text, "run \"0.234\".traces.right",
               LineContaining(text, "[run.traces.right]"),
               "expected `csv` in this trace or a `photo` in the run, found neither");
}

TEST_CASE("manifest: a photo trace needs its time and voltage scales") {
  SessionFolder folder;
  folder.Touch("runs/0.234.jpg");
  std::string text = kManifestHeader + kPhotoRun;
  text.erase(text.find("time_per_div = 0.5\n"), std::string("time_per_div = 0.5\n").size());
  CheckRefused(folder, text, "run \"0.234\".traces.right.time_per_div",
               LineContaining(text, "[run.traces.right]"),
               "required key is missing; expected a positive number of s/div (give it here or in "
               "[scope])");
}

TEST_CASE("manifest: a TOML syntax error gives the file and line") {
  SessionFolder folder;
  const std::string text = kManifestHeader + "\n[[run]]\nid = \"x\nrebounds = [0.1]\n";
  folder.Write(text);
  const Failure failure = ReadFailure(folder);
  CHECK(failure.where.file == folder.manifest());
  CHECK(failure.where.line == LineContaining(text, "id = \"x"));
  CHECK_THAT(failure.problem, Contains("TOML syntax error"));
  CHECK_THAT(failure.what, Contains(folder.manifest().string() + ":"));
}

TEST_CASE("manifest: [[run]] written as a single [run] table is refused") {
  SessionFolder folder;
  const std::string text = kManifestHeader + "[run]\nid = \"x\"\n";
  CheckRefused(folder, text, "run", LineContaining(text, "[run]"),
               "expected [[run]] tables (an array of tables), found a single [run] table");
}

TEST_CASE("manifest: divisions and impact must be whole numbers") {
  SessionFolder folder;
  SECTION("divisions") {
    const std::string text = "format = 1\n[scope]\ndivisions = [10.5, 8]\n";
    CheckRefused(folder, text, "scope.divisions[0]", 3,
                 "expected a positive whole number of divisions, found floating-point 10.5");
  }
  SECTION("impact 0") {
    folder.Touch("runs/0.234.jpg");
    const std::string text = kManifestHeader + kPhotoRun + "[run.traces.contact]\nimpact = 0\n";
    CheckRefused(folder, text, "run \"0.234\".traces.contact.impact",
                 LineContaining(text, "impact"), "expected an impact number >= 1, found 0");
  }
  SECTION("negative first_rebound") {
    const std::string text = kManifestHeader + kTypedRun + "first_rebound = -1\n";
    CheckRefused(folder, text, "run \"0.405\".first_rebound", LineContaining(text, "first_"),
                 "expected a rebound number >= 0, found -1");
  }
}

TEST_CASE("manifest: impactlab extension values are checked") {
  SessionFolder folder;
  SECTION("negative rebound uncertainty") {
    const std::string text = kManifestHeader + kTypedRun + "rebound_uncertainty = -0.001\n";
    CheckRefused(folder, text, "run \"0.405\".rebound_uncertainty",
                 LineContaining(text, "uncertainty"),
                 "expected a positive length (in), found -0.001");
  }
  SECTION("zero contact-time uncertainty") {
    const std::string text = kManifestHeader + kTypedRun + "contact_time_uncertainty = 0.0\n";
    CheckRefused(folder, text, "run \"0.405\".contact_time_uncertainty",
                 LineContaining(text, "uncertainty"), "expected a positive time (s), found 0");
  }
  SECTION("unknown stiffness mode") {
    const std::string text = kManifestHeader + "[reduction]\nstiffness = \"mean\"\n";
    CheckRefused(folder, text, "reduction.stiffness", LineContaining(text, "mean"),
                 "expected \"per-run\" or \"average\", found \"mean\"");
  }
  SECTION("a prediction from an unknown run") {
    const std::string text = kManifestHeader + kTypedRun +
                             "[[prediction]]\nsource_run = \"0.9\"\ntarget_run = \"0.405\"\n";
    CheckRefused(folder, text, "prediction #1.source_run", LineContaining(text, "source_run"),
                 "expected the id of a [[run]] with rebounds, found \"0.9\", which no run has");
  }
  SECTION("a prediction onto a run without rebounds") {
    folder.Touch("runs/0.234.jpg");
    const std::string text = kManifestHeader + kTypedRun +
                             kPhotoRun.substr(0, kPhotoRun.find("[run.")) +
                             "[run.traces.contact]\ntime_per_div = 1e-4\nvolts_per_div = 1\n" +
                             "[[prediction]]\nsource_run = \"0.405\"\ntarget_run = \"0.234\"\n";
    CheckRefused(
        folder, text, "prediction #1.target_run", LineContaining(text, "target_run"),
        "found \"0.234\", which has neither typed-in `rebounds` nor a right or left trace");
  }
  SECTION("a prediction starting beyond the target's rebounds") {
    const std::string text = kManifestHeader + kTypedRun +
                             "[[prediction]]\nsource_run = \"0.405\"\ntarget_run = \"0.405\"\n"
                             "start_rebound = 5\n";
    CheckRefused(folder, text, "prediction #1.start_rebound", LineContaining(text, "start_"),
                 "expected a rebound number below 5");
  }
}

TEST_CASE("manifest: a log channel is an encoder or an accelerometer, not both") {
  SessionFolder folder;
  folder.Touch("l.csv");
  const std::string text =
      "format = 1\n[[log]]\nid = \"L\"\nexperiment = \"l.csv\"\n"
      "[log.channels]\n"
      "q1 = { column = \"e\", counts_per_rev = 4096, sensitivity = 0.1 }\n";
  CheckRefused(folder, text, "log \"L\".channels.q1.sensitivity", 6,
               "expected `counts_per_rev` (an encoder) or `sensitivity` (an accelerometer), "
               "found both");
}

// ---------------------------------------------------------------------------
// Paths must stay inside the session folder and exist.

TEST_CASE("manifest: a photo path using .. is refused") {
  SessionFolder folder;
  std::string text = kManifestHeader + kPhotoRun;
  text.replace(text.find("runs/0.234.jpg"), 14, "runs/../../x.jpg");
  CheckRefused(folder, text, "run \"0.234\".photo", LineContaining(text, "photo"),
               "expected a path inside the session folder, found \"runs/../../x.jpg\", which uses "
               "'..'");
}

TEST_CASE("manifest: an absolute path is refused") {
  SessionFolder folder;
  folder.Touch("l.csv");
  const std::string text =
      "format = 1\n[[log]]\nid = \"L\"\nexperiment = \"l.csv\"\n"
      "simulation = \"/etc/passwd\"\n";
  CheckRefused(folder, text, "log \"L\".simulation", 5,
               "expected a path relative to the session folder, found the absolute path "
               "\"/etc/passwd\"");
}

TEST_CASE("manifest: a symbolic link leading out of the folder is refused") {
  SessionFolder folder;
  TempDir outside;
  std::ofstream(outside.path() / "secret.jpg") << "";
  SECTION("a linked file") {
    fs::create_directories(folder.path() / "runs");
    fs::create_symlink(outside.path() / "secret.jpg", folder.path() / "runs/0.234.jpg");
  }
  SECTION("a linked folder") {
    fs::create_directory_symlink(outside.path(), folder.path() / "runs");
    std::ofstream(outside.path() / "0.234.jpg") << "";
  }
  const std::string text = kManifestHeader + kPhotoRun;
  CheckRefused(folder, text, "run \"0.234\".photo", LineContaining(text, "photo"),
               "which leads outside it through a symbolic link");
}

TEST_CASE("manifest: a symbolic link inside the folder is accepted") {
  SessionFolder folder;
  folder.Touch("originals/0.234.jpg");
  fs::create_directories(folder.path() / "runs");
  fs::create_symlink("../originals/0.234.jpg", folder.path() / "runs/0.234.jpg");
  folder.Write(kManifestHeader + kPhotoRun);
  CHECK(folder.Read().session.runs.at(0).photo == folder.path() / "runs/0.234.jpg");
}

TEST_CASE("manifest: a referenced file that does not exist is refused") {
  SessionFolder folder;
  SECTION("a photo") {
    const std::string text = kManifestHeader + kPhotoRun;
    CheckRefused(folder, text, "run \"0.234\".photo", LineContaining(text, "photo"),
                 "expected an existing file, found no file at \"runs/0.234.jpg\"");
  }
  SECTION("a csv trace") {
    const std::string text =
        kManifestHeader + kTypedRun + "[run.traces.left]\ncsv = \"traces/missing.csv\"\n";
    CheckRefused(folder, text, "run \"0.405\".traces.left.csv", LineContaining(text, "csv ="),
                 "expected an existing file, found no file at \"traces/missing.csv\"");
  }
  SECTION("a log") {
    const std::string text = "format = 1\n[[log]]\nid = \"L\"\nexperiment = \"logs/l.csv\"\n";
    CheckRefused(folder, text, "log \"L\".experiment", 4,
                 "expected an existing file, found no file at \"logs/l.csv\"");
  }
  SECTION("a folder instead of a file") {
    fs::create_directories(folder.path() / "runs/0.234.jpg");
    const std::string text = kManifestHeader + kPhotoRun;
    CheckRefused(folder, text, "run \"0.234\".photo", LineContaining(text, "photo"),
                 "expected a file, found a folder");
  }
}

TEST_CASE("manifest: a file missing below a relative, missing folder is reported as missing") {
  const Session session =
      ParseManifest(kManifestHeader + kPhotoRun, "no-such-folder/session.toml").session;
  REQUIRE(session.rejected.size() == 1);
  CHECK(session.rejected[0].where.key == "run \"0.234\".photo");
  CHECK_THAT(session.rejected[0].problem, Contains("expected an existing file"));
}

TEST_CASE("manifest: a missing session folder or manifest is refused") {
  SessionFolder folder;
  SECTION("no manifest") {
    try {
      folder.Read();
      FAIL("accepted");
    } catch (const InputError& error) {
      CHECK(error.where().file == folder.manifest());
    }
  }
  SECTION("no folder") { CHECK_THROWS_AS(ReadManifest(folder.path() / "nowhere"), InputError); }
}

}  // namespace
}  // namespace impactlab
