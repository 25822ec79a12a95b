// `impactlab fit two-link` as a pipeline function (pipeline/two_link_fit_run.h):
// a log's channels become the fit's measurement by their names, and a hidden
// start delay written into a session's experiment log comes back, with the
// fitted case simulated.
#include "pipeline/two_link_fit_run.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "io/manifest.h"
#include "synth/two_link_logs.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

TEST_CASE("A log's channels become the two-link fit's measurement by name, in SI from t = 0",
          "[two_link_fit_run]") {
  Log log;
  auto channel = [](const char* name) {
    LogChannel c;
    c.name = name;
    return c;
  };
  LogChannel q4 = channel("q4");
  q4.counts_per_rev = 1024.0;
  q4.gear_ratio = 50.0;
  LogChannel a3 = channel("a3");
  a3.sensitivity = 0.1;
  log.channels = {channel("force"), q4, a3};
  LogSeries series;
  series.time_s = {2.0, 2.001, 2.002};
  series.values = {{7.0, 7.0, 7.0}, {0.1, 0.2, 0.3}, {-1.0, 0.0, 1.0}};
  const TwoLinkMeasurement m = TwoLinkMeasurementOfLog(log, series);
  REQUIRE(m.time_s.size() == 3);
  CHECK(m.time_s[0] == 0.0);
  CHECK(m.time_s[2] == Approx(0.002).margin(1e-15));
  CHECK_FALSE(m.q1_rad);
  REQUIRE(m.q4_rad);
  CHECK(*m.q4_rad == series.values[1]);
  CHECK(m.encoder_b_step_rad == Approx(2.0 * std::numbers::pi / (1024.0 * 50.0)));
  CHECK(m.encoder_a_step_rad == 0.0);
  REQUIRE(m.acceleration_m_s2[2]);
  CHECK(*m.acceleration_m_s2[2] == series.values[2]);
  for (int a : {0, 1, 3}) CHECK_FALSE(m.acceleration_m_s2[a]);
}

TEST_CASE("A hidden start delay in a session's log comes back, and its case is simulated",
          "[two_link_fit_run]") {
  testing::TempDir dir;
  TwoLinkLogOptions session;
  session.simulation.cases[0].duration_s = 2.5;
  session.experiment = session.simulation;
  session.experiment.cases[0].start_delay_s = 0.15;  // the nominal 0.1 s, +50 ms
  session.write_state = false;
  WriteTwoLinkSession(dir.path() / "s", session);
  const Log log = ReadManifest(dir.path() / "s").session.logs.at(0);
  const LogSeries experiment =
      ReadLogSeries(log.experiment, log.time_column, log.channels, LogSource::kExperiment);

  TwoLinkFitOptions options;
  options.free = {"case1.start_delay_s"};
  const TwoLinkFitRun run = FitTwoLinkToLog(session.simulation, log, experiment, options);
  INFO(run.fit.Summary());
  REQUIRE(run.fit.parameters.size() == 1);
  const FittedParameter& delay = run.fit.parameters[0];
  CHECK(delay.determined);
  CHECK(std::abs(delay.value.value - 0.15) <= 4.0 * delay.value.sigma);
  CHECK(run.fit.fitted.cases[0].start_delay_s == delay.value.value);
  // The session's simulation log: the fitted parameters' case 1, whole.
  CHECK(run.fitted_simulation.time_s.size() == experiment.time_s.size());
  CHECK(run.fitted_simulation.FirstImpact() == Approx(run.fit.fitted_impact_s).margin(1e-6));
}

}  // namespace
}  // namespace impactlab
