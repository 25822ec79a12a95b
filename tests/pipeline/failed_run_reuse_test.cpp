// A run whose measurement fails after its rebounds were read (here at its
// contact pulse) keeps what it measured for the report, but not as a
// measurement to reuse: the next reduce over its results measures it again
// and fails again, rather than take the part it had for the whole.
#include <algorithm>
#include <filesystem>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "io/trace.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "synth/session_generator.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

TEST_CASE("failed run: one that fails at its contact pulse is measured again, not reused") {
  testing::TempDir dir;
  SynthOptions synth;
  synth.preset = "quick";
  synth.csv_run = true;
  GenerateSession(dir.path() / "session", synth);
  Session session = ReadManifest(dir.path() / "session").session;
  const auto csv_run = std::find_if(session.runs.begin(), session.runs.end(), [](const Run& r) {
    return r.traces.count("contact") && r.traces.at("contact").csv;
  });
  REQUIRE(csv_run != session.runs.end());
  // The contact trace flat: no pulse, after the rebounds were measured.
  const std::filesystem::path contact = *csv_run->traces.at("contact").csv;
  Trace flat = ReadTraceCsv(contact);
  std::fill(flat.volts.begin(), flat.volts.end(), 0.1);
  WriteTraceCsv(contact, flat);

  const SessionResult first = ReduceSession(session, {});
  const RunResult* failed = first.FindRun(csv_run->id);
  REQUIRE(failed != nullptr);
  CHECK_FALSE(failed->ok);
  CHECK_THAT(failed->reason, Catch::Contains("contact"));
  CHECK_FALSE(failed->measured.xmax.empty());  // measured before the failure, for the report
  const auto file = dir.path() / "results.h5";
  WriteResults(first, file);

  const SessionResult previous = ReadResults(file);
  ReduceOptions again;
  again.previous = &previous;
  const SessionResult second = ReduceSession(session, again);
  const RunResult* still = second.FindRun(csv_run->id);
  REQUIRE(still != nullptr);
  CHECK_FALSE(still->reused);
  CHECK_FALSE(still->ok);
  CHECK(still->reason == failed->reason);
}

}  // namespace
}  // namespace impactlab
