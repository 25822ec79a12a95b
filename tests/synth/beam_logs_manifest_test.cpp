// The flexible-arm log generator (synth/beam_logs.h) writes the manifest it
// planned: read back through io/manifest.h, every value is the planned one.
#include "synth/beam_logs.h"

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "tests/support/temp_dir.h"
#include "tests/synth/manifest_match.h"

namespace impactlab {
namespace {

TEST_CASE("synth: a generated log session's manifest reads back to the values planned") {
  testing::TempDir dir;
  BeamLogOptions options;
  options.seed = 5;
  options.duration_s = 3.0;  // the experiment's tip meets the wall at 2.03 s
  options.log_id = "arm";
  const BeamLogSummary summary = GenerateBeamLogs(dir.path() / "s", options);
  const ManifestReadResult read = ReadManifest(dir.path() / "s");
  CHECK(read.warnings.empty());
  testing::CheckReadsBack(summary.manifest, read.session);
  // The paper's channels, in its order, with the sensors' scales.
  REQUIRE(summary.manifest.logs.size() == 1);
  const Log& log = summary.manifest.logs[0];
  REQUIRE(log.channels.size() == 3);
  CHECK(log.channels[0].name == "q1");
  CHECK(log.channels[0].counts_per_rev == options.sensors.counts_per_rev);
  CHECK(log.channels[2].sensitivity == options.sensors.a2_sensitivity_v_per_g);
}

}  // namespace
}  // namespace impactlab
