// A log the two-link fit refuses, through the pipeline
// (pipeline/two_link_fit_run.h): the run says why, keeps what was read, and
// has no fitted simulation to write; nothing is thrown.
#include <catch2/catch.hpp>

#include "pipeline/two_link_fit_run.h"

namespace impactlab {
namespace {

Log EncoderLog() {
  LogChannel q1;
  q1.name = "q1";
  q1.counts_per_rev = 1024.0;
  q1.gear_ratio = 50.0;
  Log log;
  log.id = "case1";
  log.channels = {q1};
  return log;
}

// `rows` rows at 1 kHz from t = 3 s, the encoder still.
LogSeries Still(int rows) {
  LogSeries series;
  series.values.resize(1);
  for (int i = 0; i < rows; ++i) {
    series.time_s.push_back(3.0 + 1e-3 * i);
    series.values[0].push_back(0.0);
  }
  return series;
}

TwoLinkFitOptions FreeDelay() {
  TwoLinkFitOptions options;
  options.free = {"case1.start_delay_s"};
  return options;
}

TEST_CASE("A log of five rows is a refused fit run with its reason and no fitted simulation",
          "[two_link_fit_run][refusals]") {
  const TwoLinkFitRun run =
      FitTwoLinkToLog(TwoLinkParameters::Nominal(), EncoderLog(), Still(5), FreeDelay());
  CHECK_FALSE(run.fit.ok);
  CHECK(run.fit.refused == TwoLinkFitRefusal::kRecord);
  CHECK(run.fit.reason == "two-link fit: the record has fewer than 10 samples");
  CHECK_FALSE(run.fitted_simulation.ok);
  CHECK(run.fitted_simulation.reason ==
        "not simulated: two-link fit: the record has fewer than 10 samples");
  CHECK(run.fitted_simulation.time_s.empty());
}

TEST_CASE(
    "A log whose start parameters cannot be simulated is a refused fit run keeping its "
    "channel",
    "[two_link_fit_run][refusals]") {
  TwoLinkParameters stiff = TwoLinkParameters::Nominal();
  stiff.drive_a.gear_ratio = 1e5;  // too fast for the explicit integrator
  const TwoLinkFitRun run = FitTwoLinkToLog(stiff, EncoderLog(), Still(20), FreeDelay());
  CHECK_FALSE(run.fit.ok);
  CHECK(run.fit.refused == TwoLinkFitRefusal::kStartParameters);
  CHECK_THAT(run.fit.reason, Catch::StartsWith("two-link fit: the start parameters cannot be "
                                               "simulated: two-link: too stiff"));
  REQUIRE(run.fit.channels.size() == 1);
  CHECK(run.fit.channels[0].channel == "q1");
  CHECK(run.fit.channels[0].samples == 20);
  CHECK(run.fit.channels[0].sigma > 0.0);  // at least a count / sqrt 12
  CHECK_FALSE(run.fitted_simulation.ok);
  CHECK(run.fitted_simulation.time_s.empty());
}

TEST_CASE(
    "A log whose start the integrator cannot carry is a refused fit run saying where the "
    "step collapsed, keeping its channel",
    "[two_link_fit_run][refusals]") {
  // A tolerance no double meets: the arm rests until its motors start at
  // 0.1 s (a still state's steps have no error), and there the first step
  // collapses. The integrator says so as a value, the simulation as its
  // record's reason, the fit as its own; the log's measurement stands.
  TwoLinkFitOptions options = FreeDelay();
  options.tolerance = 1e-300;
  const TwoLinkFitRun run =
      FitTwoLinkToLog(TwoLinkParameters::Nominal(), EncoderLog(), Still(200), options);
  CHECK_FALSE(run.fit.ok);
  CHECK(run.fit.refused == TwoLinkFitRefusal::kStartParameters);
  CHECK_THAT(run.fit.reason,
             Catch::StartsWith("two-link fit: the start parameters cannot be simulated: "
                               "two-link, free motion at t = 0.100000 s: "));
  CHECK_THAT(run.fit.reason, Catch::Contains("ODE step size collapsed at t = 0.1 s"));
  REQUIRE(run.fit.channels.size() == 1);
  CHECK(run.fit.channels[0].samples == 200);
  CHECK(run.fit.channels[0].sigma > 0.0);
  CHECK(run.fit.simulations == 0);
  CHECK_FALSE(run.fitted_simulation.ok);
  CHECK(run.fitted_simulation.reason == "not simulated: " + run.fit.reason);
}

}  // namespace
}  // namespace impactlab
