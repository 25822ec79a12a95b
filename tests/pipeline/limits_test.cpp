// Issue 14, item 3: finite inputs, bounded memory. A time axis off by a unit
// or a typo (time_per_div = 1e8 or 1e300 on a photo's trace, a CSV's time
// column in ns) once grew the rebounds' walk with the span until bad_alloc.
// Now the run is refused before any work that grows with the span, quickly,
// naming the file and key and saying why; the session's other runs reduce.
#include <algorithm>
#include <chrono>
#include <string>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "io/trace.h"
#include "pipeline/reduce.h"
#include "synth/session_generator.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

// A quick generated session: photo runs, a CSV-trace run and a typed-in run.
Session QuickMixedSession(const std::filesystem::path& folder) {
  SynthOptions synth;
  synth.preset = "quick";
  synth.csv_run = true;
  synth.typed_run = true;
  GenerateSession(folder, synth);
  return ReadManifest(folder).session;
}

Run& FirstRun(Session& session, bool (*which)(const Run&)) {
  const auto run = std::find_if(session.runs.begin(), session.runs.end(), which);
  REQUIRE(run != session.runs.end());
  return *run;
}

bool IsPhotoRun(const Run& r) { return r.photo.has_value() && !r.traces.at("right").csv; }
bool IsCsvRun(const Run& r) { return r.traces.count("right") && r.traces.at("right").csv; }

TEST_CASE("limits: time_per_div = 1e8 or 1e300, a CSV's time in ns: those runs fail alone, fast") {
  testing::TempDir dir;
  for (const double time_per_div : {1e8, 1e300}) {
    Session session =
        QuickMixedSession(dir.path() / (time_per_div < 1e100 ? "small-typo" : "large-typo"));
    Run& photo_run = FirstRun(session, IsPhotoRun);
    photo_run.traces.at("right").time_per_div = time_per_div;
    Run& csv_run = FirstRun(session, IsCsvRun);
    // The CSV's time column in nanoseconds.
    const std::filesystem::path csv = *csv_run.traces.at("right").csv;
    Trace trace = ReadTraceCsv(csv);
    for (double& t : trace.time_s) t *= 1e9;
    WriteTraceCsv(csv, trace);

    const auto start = std::chrono::steady_clock::now();
    const SessionResult result = ReduceSession(session, {});
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    INFO("time_per_div = " << time_per_div << ", " << seconds << " s");
    CHECK(seconds < /*max_seconds=*/60.0);  // the whole session, its good runs reduced
    int ok = 0;
    for (const RunResult& run : result.runs) {
      INFO("run " << run.id << ": " << run.Status());
      if (run.id == photo_run.id) {
        CHECK_FALSE(run.ok);
        CHECK_THAT(run.reason, Catch::Contains("traces.right.time_per_div") &&
                                   Catch::Contains("swings out and back of this pendulum") &&
                                   Catch::Contains("at most 1000 are expected"));
      } else if (run.id == csv_run.id) {
        CHECK_FALSE(run.ok);
        CHECK_THAT(run.reason, Catch::Contains(csv.filename().string()) &&
                                   Catch::Contains("swings out and back of this pendulum"));
      } else {
        CHECK(run.ok);
        ok += run.ok;
      }
    }
    CHECK(ok == static_cast<int>(result.runs.size()) - 2);
    CHECK(ok >= 2);
  }
}

TEST_CASE("limits: a calibration photo's time_per_div of 1e300 fails the runs using it") {
  testing::TempDir dir;
  Session session = QuickMixedSession(dir.path() / "s");
  const Run& photo_run = FirstRun(session, IsPhotoRun);
  const std::string id = photo_run.calibration.at("right");
  const auto calibration = std::find_if(session.calibrations.begin(), session.calibrations.end(),
                                        [&](const Calibration& c) { return c.id == id; });
  REQUIRE(calibration != session.calibrations.end());
  REQUIRE(calibration->photo);
  calibration->trace.time_per_div = 1e300;
  const SessionResult result = ReduceSession(session, {});
  const RunResult* run = result.FindRun(photo_run.id);
  REQUIRE(run != nullptr);
  CHECK_FALSE(run->ok);
  CHECK_THAT(run->reason, Catch::Contains("calibration \"" + id + "\".trace.time_per_div") &&
                              Catch::Contains("swings"));
}

TEST_CASE(
    "limits: first_rebound = 2e8 with a restitution near 1 is refused before the model runs") {
  // The fit's model figures simulate every rebound from the release: this
  // once took 50 s and ended in bad_alloc under a 4 GB limit.
  const auto folder = std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "thesis-1969";
  Session session = ReadManifest(folder).session;
  session.runs[0].first_rebound = 200000000;
  session.runs[0].rebounds = {0.068, 0.06799999999};
  const auto start = std::chrono::steady_clock::now();
  const SessionResult result = ReduceSession(session, {});
  CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() <
        /*max_seconds=*/5.0);
  CHECK_FALSE(result.runs[0].ok);
  CHECK_THAT(result.runs[0].reason,
             Catch::Contains("first_rebound = 200000000") && Catch::Contains("at most 1000"));
  CHECK_THAT(result.runs[0].reason, Catch::StartsWith(session.manifest.string() + ": run \"" +
                                                      session.runs[0].id + "\".first_rebound: "));
  CHECK(result.FailedRuns() == 1);
  // Refused as a value: what was measured stays beside the reason.
  CHECK(result.runs[0].measured.xmax == session.runs[0].rebounds);
}

}  // namespace
}  // namespace impactlab
