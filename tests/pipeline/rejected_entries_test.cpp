// A manifest entry that cannot be read fails alone: the session still
// reduces, the rejected run or log stands in the results at its place with
// its reason, and the results file keeps it.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>

#include "io/errors.h"
#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;

const fs::path kThesis = fs::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "thesis-1969";

// The thesis session with `extra` inserted before its first [[run]], in a
// temporary folder.
fs::path ThesisWith(const testing::TempDir& dir, const std::string& extra) {
  std::ifstream in(kThesis / "session.toml");
  std::stringstream text;
  text << in.rdbuf();
  std::string manifest = text.str();
  manifest.insert(manifest.find("[[run]]"), extra);
  std::ofstream(dir.path() / "session.toml") << manifest;
  return dir.path();
}

TEST_CASE("rejected entries: a bad run fails alone, at its place, and the others reduce") {
  testing::TempDir dir;
  const fs::path folder = ThesisWith(dir,
                                     "[[run]]\nid = \"bad\"\ninitial_displacement = \"abc\"\n"
                                     "rebounds = [0.1, 0.05]\n\n"
                                     "[[run]]\nid = \"../escape\"\ninitial_displacement = 0.2\n"
                                     "rebounds = [0.1, 0.05]\n\n");
  const SessionResult result = ReduceSession(ReadManifest(folder).session, {});
  REQUIRE(result.runs.size() == 10);
  CHECK(result.runs[0].id == "bad");
  CHECK_FALSE(result.runs[0].ok);
  CHECK_THAT(result.runs[0].reason, Contains("session.toml"));
  CHECK_THAT(result.runs[0].reason, Contains("run \"bad\".initial_displacement"));
  CHECK_THAT(result.runs[0].reason, Contains("found string \"abc\""));
  CHECK(result.runs[1].id == "#2");
  CHECK_THAT(result.runs[1].reason, Contains("expected a run id (a string) of 1 to 64 letters"));
  CHECK(result.FailedRuns() == 2);
  for (std::size_t i = 2; i < result.runs.size(); ++i) CHECK(result.runs[i].ok);
  // Table 4's prediction still follows from the good runs.
  CHECK(result.predictions.size() == 1);

  // The results file keeps the failures, and what reads it sees them.
  const fs::path out = dir.path() / "out.h5";
  WriteResults(result, out);
  const SessionResult back = ReadResults(out);
  REQUIRE(back.runs.size() == 10);
  CHECK(back.runs[1].id == "#2");
  CHECK_FALSE(back.runs[1].ok);
  CHECK(back.runs[1].reason == result.runs[1].reason);
}

TEST_CASE("rejected entries: a calibration no run needs is reported as a warning") {
  testing::TempDir dir;
  const fs::path folder =
      ThesisWith(dir,
                 "[[calibration]]\nid = \"R\"\ncell = \"up\"\ninitial_displacement = 0.2\n"
                 "[calibration.trace]\ncsv = \"r.csv\"\n\n");
  const Session session = ReadManifest(folder).session;
  const SessionResult result = ReduceSession(session, {});
  CHECK(result.FailedRuns() == 0);
  REQUIRE_FALSE(result.warnings.empty());
  CHECK_THAT(result.warnings.back(), Contains("calibration R skipped"));
  CHECK_THAT(result.warnings.back(), Contains("calibration \"R\".cell"));
}

TEST_CASE("rejected entries: a bad log fails alone beside a good one") {
  testing::TempDir dir;
  const fs::path logs = fs::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "logs-two-link";
  fs::copy(logs, dir.path(), fs::copy_options::recursive);
  std::ofstream(dir.path() / "session.toml", std::ios::app)
      << "\n[[log]]\nid = \"broken\"\nexperiment = \"logs/case1-experiment.csv\"\n"
         "[log.channels]\nq1 = { column = \"enc1\", counts_per_rev = 4096, sensitivity = 1 }\n";
  const SessionResult result = ReduceSession(ReadManifest(dir.path()).session, {});
  REQUIRE(result.logs.size() == 2);
  CHECK(result.logs[0].ok);
  CHECK_FALSE(result.logs[1].ok);
  CHECK(result.logs[1].id == "broken");
  CHECK_THAT(result.logs[1].reason, Contains("found both"));
}

// A session built in memory (not from a manifest, which refuses it first)
// with runs and no apparatus is bad input, named by its manifest and table:
// the CLI's exit 3, not a bad command line.
TEST_CASE("rejected entries: a session with runs but no apparatus is an input error") {
  Session session = ReadManifest(kThesis).session;
  session.apparatus.reset();
  try {
    ReduceSession(session, {});
    FAIL("the session was reduced without an apparatus");
  } catch (const InputError& e) {
    CHECK(e.where().file == session.manifest);
    CHECK(e.where().key == "apparatus");
    CHECK_THAT(e.what(), Contains("[apparatus] is required"));
  }
}

}  // namespace
}  // namespace impactlab
