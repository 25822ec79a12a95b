// A run measured in part keeps what it measured, but not as a measurement
// to reuse: the next reduce over its results measures it again, rather than
// take the part it had for the whole. Here its contact trace shows no pulse
// after its rebounds were read: the run stands without a contact time
// (pipeline/trace_run.h), and the next reduce measures it again and says why
// again.
#include <algorithm>
#include <filesystem>
#include <string>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "io/trace.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "synth/session_generator.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

TEST_CASE("failed run: one measured without its contact pulse is measured again, not reused") {
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
  const std::string key = "run \"" + csv_run->id + "\".traces.contact";
  const auto warned = [&](const SessionResult& result) {
    return std::count_if(result.warnings.begin(), result.warnings.end(), [&](const std::string& w) {
      return w.find(key) != std::string::npos && w.find("no step") != std::string::npos;
    });
  };

  const SessionResult first = ReduceSession(session, {});
  const RunResult* part = first.FindRun(csv_run->id);
  REQUIRE(part != nullptr);
  CHECK(part->ok);
  CHECK_FALSE(part->measured.xmax.empty());
  CHECK_FALSE(part->measured.contact_time.has_value());
  CHECK(warned(first) == 1);
  const auto file = dir.path() / "results.h5";
  WriteResults(first, file);

  const SessionResult previous = ReadResults(file);
  ReduceOptions again;
  again.previous = &previous;
  const SessionResult second = ReduceSession(session, again);
  const RunResult* still = second.FindRun(csv_run->id);
  REQUIRE(still != nullptr);
  CHECK_FALSE(still->reused);
  CHECK(still->ok);
  CHECK(still->measured.xmax == part->measured.xmax);
  CHECK(warned(second) == 1);
  // The session's other runs, measured whole, are reused.
  for (const RunResult& run : second.runs) {
    if (run.ok && run.id != csv_run->id && !run.measured.source.empty() &&
        run.measured.source != "typed-in") {
      CHECK(run.reused);
    }
  }
}

}  // namespace
}  // namespace impactlab
