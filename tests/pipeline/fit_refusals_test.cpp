// Failure as a value (issue 33, item 4): the fit's and the model's refusals
// of a run's data reach reduce as values. The run keeps its measurement
// beside the reason; a session-level fit the runs cannot inform keeps its
// reason; a prediction or a damping line the runs cannot give is left out
// with its warning, or without (the table stands alone).
#include <algorithm>
#include <filesystem>
#include <string>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"

namespace impactlab {
namespace {

Session Thesis1969() {
  return ReadManifest(std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "thesis-1969")
      .session;
}

TEST_CASE("fit_refusals: a run whose model would swing past the horizontal fails, kept measured") {
  // e = 1/2 per impact, 30 impacts back to the release: the model's first
  // swing would be 2^29 times as fast as rebound 0's.
  Session session = Thesis1969();
  Run& run = session.runs[0];
  run.first_rebound = 30;
  run.rebounds = {0.3, 0.15};
  const SessionResult result = ReduceSession(session, {});
  const RunResult& refused = result.runs[0];
  CHECK_FALSE(refused.ok);
  CHECK_THAT(refused.reason,
             Catch::StartsWith(session.manifest.string() + ": run \"" + run.id + "\": ") &&
                 Catch::Contains("would pass the horizontal"));
  CHECK(refused.measured.xmax == run.rebounds);
  CHECK_FALSE(refused.fits.kelvin_voigt.has_value());
  CHECK(result.FailedRuns() == 1);
}

TEST_CASE("fit_refusals: without a contact time Poynting-Thomson says why it did not run") {
  Session session = Thesis1969();
  session.reduction.contact_time.reset();
  const SessionResult result = ReduceSession(session, {});
  for (const RunResult& run : result.runs) {
    INFO("run " << run.id);
    REQUIRE(run.ok);
    REQUIRE(run.fits.poynting_thomson.has_value());
    CHECK_FALSE(run.fits.poynting_thomson->ok);
    CHECK_FALSE(run.fits.poynting_thomson->status.Ran());
    CHECK_THAT(run.fits.poynting_thomson->reason, Catch::Contains("do not fix a time scale"));
    // Kelvin-Voigt needs no time scale for e and zeta.
    CHECK(run.fits.kelvin_voigt_least_squares->ok);
  }
  REQUIRE(result.joint_fits.size() == 1);
  CHECK_THAT(result.joint_fits[0].reason, Catch::Contains("do not fix a time scale"));
}

TEST_CASE("fit_refusals: a prediction from a rebound the target did not measure is skipped") {
  Session session = Thesis1969();
  REQUIRE_FALSE(session.predictions.empty());
  Prediction& p = session.predictions[0];
  p.start_rebound = 9;
  const SessionResult result = ReduceSession(session, {});
  const std::string warning = session.manifest.string() + ": prediction of run \"" + p.target_run +
                              "\" from run \"" + p.source_run +
                              "\" skipped: start_rebound 9 is not a measured rebound of run " +
                              p.target_run + " (0..4)";
  CHECK(std::count(result.warnings.begin(), result.warnings.end(), warning) == 1);
  CHECK(result.predictions.size() == session.predictions.size() - 1);
}

TEST_CASE("fit_refusals: runs of one restitution give no damping line, the table stands") {
  Session session = Thesis1969();
  session.runs.resize(2);
  session.predictions.clear();
  REQUIRE(ReduceSession(session, {}).kelvin_voigt->damping_line.has_value());
  session.runs[1].rebounds = session.runs[0].rebounds;
  const SessionResult result = ReduceSession(session, {});
  REQUIRE(result.kelvin_voigt.has_value());
  CHECK(result.kelvin_voigt->run_ids.size() == 2);
  CHECK(result.kelvin_voigt->sqrt_restitution[0] == result.kelvin_voigt->sqrt_restitution[1]);
  CHECK_FALSE(result.kelvin_voigt->damping_line.has_value());
}

}  // namespace
}  // namespace impactlab
