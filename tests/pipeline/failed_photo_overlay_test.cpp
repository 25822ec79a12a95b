// A run whose photo is not read keeps the photo's overlay: the report and
// the results file show what the digitizer found and why it stopped.
#include <algorithm>
#include <filesystem>

#include <catch2/catch.hpp>
#include <opencv2/core.hpp>

#include "digitize/digitize.h"
#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "synth/session_generator.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

TEST_CASE("failed photo: a run whose photo shows no graticule keeps its overlay and says why") {
  testing::TempDir dir;
  SynthOptions synth;
  synth.preset = "quick";
  GenerateSession(dir.path() / "session", synth);
  const Session session = ReadManifest(dir.path() / "session").session;
  const auto photo_run = std::find_if(session.runs.begin(), session.runs.end(),
                                      [](const Run& r) { return r.photo.has_value(); });
  REQUIRE(photo_run != session.runs.end());
  // A blank frame in place of the run's photo: nothing to find.
  WriteImage(*photo_run->photo, cv::Mat(600, 800, CV_8UC3, cv::Scalar(30, 30, 30)));

  const SessionResult result = ReduceSession(session, {});
  const RunResult* failed = result.FindRun(photo_run->id);
  REQUIRE(failed != nullptr);
  CHECK_FALSE(failed->ok);
  CHECK_THAT(failed->reason, Catch::Contains(photo_run->photo->filename().string()) &&
                                 Catch::Contains("graticule of 10 x 8 divisions not found"));
  REQUIRE(failed->measured.overlays.size() == 1);
  CHECK_FALSE(failed->measured.overlays.front().jpeg.empty());

  const auto file = dir.path() / "results.h5";
  WriteResults(result, file);
  const SessionResult read_back = ReadResults(file);  // kept: `read` points into it
  const RunResult* read = read_back.FindRun(photo_run->id);
  REQUIRE(read != nullptr);
  REQUIRE(read->measured.overlays.size() == 1);
  CHECK(read->measured.overlays.front().jpeg == failed->measured.overlays.front().jpeg);
}

}  // namespace
}  // namespace impactlab
