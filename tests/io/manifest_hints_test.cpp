// Manual hints in the manifest (docs/manifest.md): `graticule_corners` on a
// photo-bearing [[run]] or [[calibration]], `points` in a trace table. Read
// into the session as photo pixels; a bad hint rejects its entry alone, with
// the file, the line and the key named.
#include <catch2/catch.hpp>

#include <fmt/format.h>

#include <string>

#include "io/manifest.h"
#include "tests/io/session_folder.h"

namespace impactlab {
namespace {

using Catch::Matchers::Contains;
using testing::SessionFolder;

// A photo run with `run_extra` after its photo and `trace_extra` in its left trace.
std::string HintedRun(const std::string& id, const std::string& run_extra,
                      const std::string& trace_extra) {
  return fmt::format(
      "\n[[run]]\nid = \"{}\"\ninitial_displacement = 0.234\nphoto = \"r.png\"\n{}\n"
      "[run.traces.left]\ntime_per_div = 0.5\nvolts_per_div = 0.2\n{}\n",
      id, run_extra, trace_extra);
}

const std::string kCorners =
    "graticule_corners = [[102, 80.5], [1890, 95], [1880, 1420], [98, 1410]]";

// Reads a good photo run and one with the bad hint; exactly the second is
// rejected, at `key`, with `expected` in its reason.
void CheckBadHint(const std::string& run_extra, const std::string& trace_extra,
                  const std::string& key, const std::string& expected) {
  SessionFolder folder;
  folder.Touch("r.png");
  const std::string text = testing::kManifestHeader + HintedRun("good", kCorners, "") +
                           HintedRun("bad", run_extra, trace_extra);
  folder.Write(text);
  const ManifestReadResult read = folder.Read();
  INFO(text);
  REQUIRE(read.session.runs.size() == 1);
  CHECK(read.session.runs[0].id == "good");
  REQUIRE(read.session.rejected.size() == 1);
  const RejectedEntry& entry = read.session.rejected[0];
  INFO(entry.Reason());
  CHECK(entry.id == "bad");
  CHECK(entry.where.key == key);
  CHECK(entry.where.line.has_value());
  CHECK_THAT(entry.problem, Contains(expected));
}

}  // namespace

TEST_CASE("manifest hints: graticule corners and trace points are read as photo pixels") {
  SessionFolder folder;
  folder.Touch("r.png");
  folder.Touch("c.png");
  folder.Write(testing::kManifestHeader + R"toml(
[[calibration]]
id = "R"
cell = "right"
initial_displacement = 0.2
photo = "c.png"
graticule_corners = [[10, 20], [610, 25], [605, 470], [12, 466]]
[calibration.trace]
time_per_div = 0.05
volts_per_div = 0.2
points = [[100, 200], [300.5, 150]]
)toml" + HintedRun("0.234", kCorners, "points = [[150, 900], [700, 1000], [1500.25, 950]]") +
               HintedRun("plain", "", ""));
  const ManifestReadResult read = folder.Read();
  const Session& session = read.session;
  CHECK(read.warnings.empty());
  REQUIRE(session.rejected.empty());
  REQUIRE(session.runs.size() == 2);
  const Run& run = session.runs[0];
  REQUIRE(run.graticule_corners_px.has_value());
  CHECK((*run.graticule_corners_px)[0] == std::array<double, 2>{102.0, 80.5});
  CHECK((*run.graticule_corners_px)[3] == std::array<double, 2>{98.0, 1410.0});
  const TraceSettings& left = run.traces.at("left");
  REQUIRE(left.points_px.size() == 3);
  CHECK(left.points_px[2] == std::array<double, 2>{1500.25, 950.0});
  CHECK_FALSE(session.runs[1].graticule_corners_px.has_value());
  CHECK(session.runs[1].traces.at("left").points_px.empty());
  REQUIRE(session.calibrations.size() == 1);
  REQUIRE(session.calibrations[0].graticule_corners_px.has_value());
  CHECK((*session.calibrations[0].graticule_corners_px)[1] == std::array<double, 2>{610.0, 25.0});
  CHECK(session.calibrations[0].trace.points_px.size() == 2);
}

TEST_CASE("manifest hints: a bad hint rejects its entry alone, naming the key") {
  const std::string corners = "run \"bad\".graticule_corners";
  // Not four corners, not pixels, not numbers, not finite, negative.
  CheckBadHint("graticule_corners = [[1, 2], [300, 2], [300, 200]]", "", corners,
               "found an array of 3 values");
  CheckBadHint("graticule_corners = [[1, 2], [300, 2], [300, 200], 4]", "", corners + "[3]",
               "expected a pixel [x, y], found integer 4");
  CheckBadHint("graticule_corners = [[1, 2], [300, 2], [300, 200], [1, 2, 3]]", "", corners + "[3]",
               "found an array of 3 values");
  CheckBadHint("graticule_corners = [[1, 2], [300, \"2\"], [300, 200], [1, 200]]", "",
               corners + "[1][1]", "found string \"2\"");
  CheckBadHint("graticule_corners = [[1, 2], [300, 2], [300, nan], [1, 200]]", "",
               corners + "[2][1]", "not a finite number");
  CheckBadHint("graticule_corners = [[-3, 2], [300, 2], [300, 200], [1, 200]]", "",
               corners + "[0][0]", "a pixel coordinate >= 0");
  // Not in the order top-left, top-right, bottom-right, bottom-left: mirrored,
  // folded (a bow tie), or three corners in a line, or a tiny screen.
  CheckBadHint("graticule_corners = [[1, 2], [1, 200], [300, 200], [300, 2]]", "", corners,
               "turns the other way");
  CheckBadHint("graticule_corners = [[1, 2], [300, 200], [300, 2], [1, 200]]", "", corners,
               "turns the other way");
  CheckBadHint("graticule_corners = [[0, 0], [150, 0], [300, 0], [150, 200]]", "", corners,
               "is almost straight");
  CheckBadHint("graticule_corners = [[1, 2], [10, 2], [10, 9], [1, 9]]", "", corners,
               "at least 20 px long");
  // Trace points: at least two, pixels, no repeats.
  const std::string points = "run \"bad\".traces.left.points";
  CheckBadHint("", "points = [[100, 200]]", points, "found an array of 1 values");
  CheckBadHint("", "points = [[100, 200], [100, inf]]", points + "[1][1]", "not a finite number");
  CheckBadHint("", "points = [[100, 200], 7]", points + "[1]", "expected a pixel [x, y]");
  CheckBadHint("", "points = [[100, 200], [150, 210], [100, 200]]", points,
               "found the pixel [100, 200] twice");
}

TEST_CASE("manifest hints: a hint without a photo to apply to is ignored with a warning") {
  SessionFolder folder;
  folder.Touch("t.csv");
  folder.Write(testing::kManifestHeader + R"toml(
[[run]]
id = "csv"
initial_displacement = 0.234
graticule_corners = [[10, 20], [610, 25], [605, 470], [12, 466]]
[run.traces.left]
csv = "t.csv"
points = [[100, 200], [300, 150]]
)toml");
  const ManifestReadResult read = folder.Read();
  REQUIRE(read.session.runs.size() == 1);
  CHECK_FALSE(read.session.runs[0].graticule_corners_px.has_value());
  CHECK(read.session.runs[0].traces.at("left").points_px.empty());
  REQUIRE(read.warnings.size() == 2);
  std::string all;
  for (const ManifestWarning& w : read.warnings) all += w.where.key + ": " + w.message + "\n";
  CHECK_THAT(all,
             Contains("run \"csv\".graticule_corners: 'graticule_corners' applies to a photo"));
  CHECK_THAT(all, Contains("run \"csv\".traces.left.points: 'points' applies only to a trace read "
                           "from the photo"));
}

}  // namespace impactlab
