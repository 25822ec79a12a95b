// The data the two-link fit refuses (fit/two_link_fit.h) come back as a
// result that did not run, with the reason and what was read before it: a
// record too short, one whose time does not increase, one longer than the
// simulation logs a case, a channel whose sample count is not the record's,
// start parameters that cannot be simulated.
// Options and unknown keys, the caller's own mistakes, still throw.
#include <cmath>
#include <vector>

#include <catch2/catch.hpp>

#include "fit/two_link_fit.h"

namespace impactlab {
namespace {

// `n` samples at 1 kHz from t = 0; q1 steps once a sample by a count.
TwoLinkMeasurement Record(int n) {
  TwoLinkMeasurement m;
  m.encoder_a_step_rad = 1e-4;
  m.q1_rad.emplace();
  for (int i = 0; i < n; ++i) {
    m.time_s.push_back(1e-3 * i);
    m.q1_rad->push_back(1e-4 * i);
  }
  return m;
}

TwoLinkFitOptions FreeDelay() {
  TwoLinkFitOptions options;
  options.free = {"case1.start_delay_s"};
  return options;
}

TEST_CASE("A record of fewer than 10 samples is a refused fit, not an exception",
          "[two_link_fit][refusals]") {
  const TwoLinkFitResult fit =
      FitTwoLinkSimulation(TwoLinkParameters::Nominal(), Record(9), FreeDelay());
  CHECK_FALSE(fit.ok);
  CHECK(fit.refused == TwoLinkFitRefusal::kRecord);
  CHECK(fit.reason == "two-link fit: the record has fewer than 10 samples");
  // Nothing was read: no parameter freed, no channel measured, nothing simulated.
  CHECK(fit.parameters.empty());
  CHECK(fit.channels.empty());
  CHECK(fit.simulations == 0);
  CHECK(fit.measured_impact_s == -1.0);
}

TEST_CASE("A record whose time does not increase is a refused fit, saying its span",
          "[two_link_fit][refusals]") {
  TwoLinkMeasurement m;
  m.time_s.assign(11, 0.25);  // every row at the same time: no sample rate
  const TwoLinkFitResult fit = FitTwoLinkSimulation(TwoLinkParameters::Nominal(), m, FreeDelay());
  CHECK_FALSE(fit.ok);
  CHECK(fit.refused == TwoLinkFitRefusal::kRecord);
  CHECK(fit.reason ==
        "two-link fit: the record's time must increase (it runs from 0.25 s to 0.25 s)");
  CHECK(fit.parameters.empty());
}

// `n` samples 1/1024 s apart from t = 0 (a grid on which the rate, the
// duration and their product are exact), and no channel.
TwoLinkMeasurement Grid(int n) {
  TwoLinkMeasurement m;
  m.time_s.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) m.time_s[static_cast<std::size_t>(i)] = i / 1024.0;
  return m;
}

TEST_CASE(
    "A record longer than the simulation logs a case is a refused record, said with its "
    "length and the limit before anything is simulated",
    "[two_link_fit][refusals]") {
  // 2e6 + 1 sample intervals: one over kTwoLinkMaxSamples (rate x duration).
  const TwoLinkFitResult fit =
      FitTwoLinkSimulation(TwoLinkParameters::Nominal(), Grid(2'000'002), FreeDelay());
  CHECK_FALSE(fit.ok);
  CHECK(fit.refused == TwoLinkFitRefusal::kRecord);
  CHECK(fit.reason ==
        "two-link fit: the record is too long for the simulation: 2000002 samples over 1953.13 s "
        "at 1024 Hz (rate x duration 2000001), over its limit of 2e+06 per case");
  CHECK(fit.simulations == 0);
  CHECK(fit.parameters.empty());  // refused before anything else was read
  CHECK(fit.channels.empty());
  // At the limit the length passes, and the record is judged on (here a
  // channel cut short), still without simulating.
  TwoLinkMeasurement longest = Grid(2'000'001);
  longest.q1_rad = std::vector<double>(5, 0.0);
  const TwoLinkFitResult at_limit =
      FitTwoLinkSimulation(TwoLinkParameters::Nominal(), longest, FreeDelay());
  CHECK(at_limit.refused == TwoLinkFitRefusal::kRecord);
  CHECK(at_limit.reason == "two-link fit: channel q1 has 5 samples, not 2000001");
  CHECK(at_limit.simulations == 0);
}

TEST_CASE(
    "A channel whose sample count is not the record's is a refused fit, keeping what "
    "was read before it",
    "[two_link_fit][refusals]") {
  TwoLinkMeasurement m = Record(11);
  m.acceleration_m_s2[0] = std::vector<double>(7, 0.0);  // a1 cut short
  const TwoLinkFitResult fit = FitTwoLinkSimulation(TwoLinkParameters::Nominal(), m, FreeDelay());
  CHECK_FALSE(fit.ok);
  CHECK(fit.refused == TwoLinkFitRefusal::kRecord);
  CHECK(fit.reason == "two-link fit: channel a1 has 7 samples, not 11");
  // The free parameter, at its start and not determined.
  REQUIRE(fit.parameters.size() == 1);
  CHECK(fit.parameters[0].name == "case1.start_delay_s");
  CHECK(fit.parameters[0].start == TwoLinkParameters::Nominal().cases[0].start_delay_s);
  CHECK(fit.parameters[0].value.value == fit.parameters[0].start);
  CHECK(fit.parameters[0].value.sigma == 0.0);
  CHECK_FALSE(fit.parameters[0].determined);
  // q1, read before a1: its noise is at least a count / sqrt 12 (the record's
  // steps are exactly a count, so no more), and no misfit was simulated.
  REQUIRE(fit.channels.size() == 1);
  CHECK(fit.channels[0].channel == "q1");
  CHECK(fit.channels[0].samples == 11);
  CHECK(fit.channels[0].sigma == Approx(1e-4 / std::sqrt(12.0)));
  CHECK_FALSE(fit.channels[0].rms_start.has_value());  // nothing was simulated
  CHECK_FALSE(fit.channels[0].rms_fitted.has_value());
  CHECK(fit.simulations == 0);
}

TEST_CASE(
    "Start parameters that cannot be simulated are a refused fit, keeping the record's "
    "channels",
    "[two_link_fit][refusals]") {
  // A gearbox of ratio 1e5: its back-EMF braking is too fast for the
  // explicit integrator, refused before the motion starts.
  TwoLinkParameters stiff = TwoLinkParameters::Nominal();
  stiff.drive_a.gear_ratio = 1e5;
  TwoLinkMeasurement m = Record(20);
  m.acceleration_m_s2[2] = std::vector<double>(20, 0.0);
  const TwoLinkFitResult fit = FitTwoLinkSimulation(stiff, m, FreeDelay());
  CHECK_FALSE(fit.ok);
  CHECK(fit.refused == TwoLinkFitRefusal::kStartParameters);
  // The simulation's own reason follows: what it refused, and why.
  CHECK_THAT(fit.reason, Catch::StartsWith("two-link fit: the start parameters cannot be "
                                           "simulated: two-link: too stiff for the explicit "
                                           "integrator: "));
  CHECK_THAT(fit.reason, Catch::Contains("gear_ratio = 100000"));
  REQUIRE(fit.parameters.size() == 1);
  CHECK_FALSE(fit.parameters[0].determined);
  // Both channels were read, in the simulator's order; the fitted parameters
  // are the start's, on the record's grid.
  REQUIRE(fit.channels.size() == 2);
  CHECK(fit.channels[0].channel == "q1");
  CHECK(fit.channels[1].channel == "a3");
  CHECK(fit.channels[1].samples == 20);
  CHECK(fit.fitted.drive_a.gear_ratio == 1e5);
  CHECK(fit.fitted.sensors.sample_rate_hz == Approx(1000.0));
  CHECK(fit.fitted.cases[0].duration_s == Approx(0.019));
  CHECK(fit.measured_impact_s == -1.0);  // a flat record shows none
  CHECK(fit.iterations == 0);
}

// (An unknown key: two_link_fit_test.cpp.)
TEST_CASE("Options that free nothing, the caller's mistake, still throw",
          "[two_link_fit][refusals]") {
  TwoLinkFitOptions none;
  CHECK_THROWS_WITH(FitTwoLinkSimulation(TwoLinkParameters::Nominal(), Record(11), none),
                    Catch::Contains("name at least one parameter"));
}

}  // namespace
}  // namespace impactlab
