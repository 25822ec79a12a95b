#include "calibration/displacement.h"

#include <cmath>
#include <numbers>

#include <catch2/catch.hpp>

#include "tests/calibration/linear_cell.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using testing::kPendulum;
using testing::LinearCell;

// A noiseless release swing of a linear cell: its calibration is exact.
CalibrationResult LinearCalibration(double x0) {
  Trace sweep;
  const double end = 0.5 * HalfPeriod(kPendulum, x0);
  for (double t = 0.0; t <= end; t += 2e-4) {
    sweep.time_s.push_back(t);
    sweep.volts.push_back(LinearCell(ReleaseSwingDisplacement(kPendulum, x0, t), x0));
  }
  return CalibratePhotocell(sweep, kPendulum, x0, CalibrationOptions{});
}

TEST_CASE("displacement: a run's volts read through its cell's curve, sigma from the slope") {
  const double x0 = 0.3;
  const CalibrationResult calibration = LinearCalibration(x0);
  Trace run;
  for (int i = 0; i <= 100; ++i) {
    run.time_s.push_back(0.01 * i);
    run.volts.push_back(LinearCell(x0 * (0.05 + 0.009 * i), x0));
    run.sigma_volts.push_back(0.017);  // 0.003 of X0 through the slope 1.7 / X0
  }
  const DisplacementConversion converted = DisplacementFromVolts(run, calibration);
  REQUIRE(converted.ok);
  CHECK(converted.reason.empty());
  const DisplacementHistory& h = converted.history;
  REQUIRE(h.displacement.size() == run.volts.size());
  for (std::size_t i = 0; i < h.displacement.size(); ++i) {
    CHECK(h.time_s[i] == run.time_s[i]);
    CHECK(h.displacement[i] == Approx(x0 * (0.05 + 0.009 * i)).margin(1e-9));
    // The noiseless curve adds nothing to the sample's own noise.
    CHECK(h.sigma[i] == Approx(0.01 * x0).epsilon(1e-3));
  }
}

TEST_CASE("displacement: samples just beyond the calibrated volts are dropped, too many refused") {
  const double x0 = 0.3;
  const CalibrationResult calibration = LinearCalibration(x0);
  Trace run;
  for (int i = 0; i < 100; ++i) {
    run.time_s.push_back(0.01 * i);
    run.volts.push_back(LinearCell(0.5 * x0, x0));
  }
  // 1.03 X0: 3 % of the calibrated span beyond it, where a run a little
  // longer than its calibration would read (the margin is 1 %).
  const double just_beyond = LinearCell(1.03 * x0, x0);
  run.volts[7] = just_beyond;  // one in a hundred outside: dropped
  const DisplacementConversion one = DisplacementFromVolts(run, calibration);
  CHECK(one.ok);
  CHECK(one.dropped == 1);
  CHECK(one.left_out == 0);
  CHECK(one.history.time_s.size() == 99);
  run.volts[30] = run.volts[60] =
      just_beyond;  // three in a hundred: the curve does not cover the run
  // Refused as a value, with what was converted kept beside the reason.
  const DisplacementConversion three = DisplacementFromVolts(run, calibration);
  CHECK_FALSE(three.ok);
  CHECK_THAT(three.reason, Catch::Contains("3 of 100 samples") &&
                               Catch::Contains("calibrated range") &&
                               Catch::Contains("does not cover what this run needs"));
  CHECK(three.dropped == 3);
  CHECK(three.history.time_s.size() == 97);
  const DisplacementConversion empty = DisplacementFromVolts(Trace{}, calibration);
  CHECK_FALSE(empty.ok);
  CHECK(empty.reason == "the trace has no samples");
}

// A bar's swing, as its trace reads it: X between 0.1 and 0.9 X0.
double SwingX(double t, double x0) {
  return x0 * (0.5 + 0.4 * std::sin(2.0 * std::numbers::pi * t));
}

// 401 samples over 1 s of the swing, 0.5 mV noise each (none drawn: the
// samples lie on the curve), with the samples from `from_s` to `to_s`
// following a straight line instead (a scratch), from the trace down to
// `end_volts`; the reading jumps back to the trace after it.
Trace SwingWithScratch(double x0, double from_s, double to_s, double end_volts) {
  Trace run;
  const double from_volts = LinearCell(SwingX(from_s, x0), x0);
  for (int i = 0; i <= 400; ++i) {
    const double t = 0.0025 * i;
    const bool scratch = t >= from_s - 1e-12 && t <= to_s + 1e-12;
    run.time_s.push_back(t);
    run.volts.push_back(scratch
                            ? from_volts + (end_volts - from_volts) * (t - from_s) / (to_s - from_s)
                            : LinearCell(SwingX(t, x0), x0));
    run.sigma_volts.push_back(5e-4);
  }
  return run;
}

TEST_CASE("displacement: a line followed far outside the calibrated volts is left out whole") {
  const double x0 = 0.3;
  const CalibrationResult calibration = LinearCalibration(x0);  // 0.3 .. 2.0 V
  // The reading leaves the trace as it rises to its peak, at 0.2 s, and
  // follows a scratch down to -0.3 V (35 % of the span below the range) by
  // 0.3 s: 41 samples, 29 of them inside the calibrated volts.
  const Trace run = SwingWithScratch(x0, 0.2, 0.3, -0.3);
  const DisplacementConversion converted = DisplacementFromVolts(run, calibration);
  REQUIRE(converted.ok);
  CHECK(converted.dropped == 0);
  REQUIRE(converted.left_out_s.size() == 1);
  CHECK(converted.left_out_s[0].first == Approx(0.2));
  CHECK(converted.left_out_s[0].second == Approx(0.3));
  CHECK(converted.left_out == 41);
  // What is kept is the trace, read exactly.
  const DisplacementHistory& h = converted.history;
  REQUIRE(h.time_s.size() == run.time_s.size() - 41);
  for (std::size_t i = 0; i < h.time_s.size(); ++i) {
    CHECK(h.displacement[i] == Approx(SwingX(h.time_s[i], x0)).margin(1e-9));
  }
}

TEST_CASE("displacement: a line far outside from the trace's start, or over much of it, refused") {
  const double x0 = 0.3;
  const CalibrationResult calibration = LinearCalibration(x0);
  // From the start beyond X0's end (2.6 V, 35 % of the span above the
  // range): the release, where a calibration may truly not reach.
  const DisplacementConversion start =
      DisplacementFromVolts(SwingWithScratch(x0, 0.0, 0.1, 2.6), calibration);
  CHECK_FALSE(start.ok);
  CHECK_THAT(start.reason,
             Catch::Contains("far outside at t = 0 .. 0.1 s") && Catch::Contains("from its start"));
  // Over 0.2 .. 0.6 s, 40 % of the trace: too little of the bar's own is left.
  const DisplacementConversion most =
      DisplacementFromVolts(SwingWithScratch(x0, 0.2, 0.6, -0.3), calibration);
  CHECK_FALSE(most.ok);
  CHECK_THAT(most.reason, Catch::Contains("far outside at t = 0.2 .. 0.6 s (40 % of the trace)") &&
                              Catch::Contains("not the bar's trace"));
}

TEST_CASE(
    "displacement: a line beyond X0's volts that ends before the release, the trace back "
    "within the calibrated volts after it, is left out, not refused") {
  const double x0 = 0.3;
  const CalibrationResult calibration = LinearCalibration(x0);  // 0.3 .. 2.0 V
  // The sweep begins 0.1 s before the release, the bar held at 0.9 X0; the
  // reading follows a line at 2.6 V (35 % of the span beyond X0's volts)
  // until 0.06 s before the release, then the trace (randomised seed 1018's
  // run 0.405: 4 samples 0.036 V beyond, before the release). Had the
  // calibration not reached the release, the samples beyond would run on
  // past it.
  Trace run;
  for (int i = -40; i <= 400; ++i) {
    const double t = 0.0025 * i;
    run.time_s.push_back(t);
    run.volts.push_back(t <= -0.06 + 1e-12 ? 2.6
                        : t < 0.0          ? LinearCell(0.9 * x0, x0)
                                           : LinearCell(SwingX(t, x0), x0));
    run.sigma_volts.push_back(5e-4);
  }
  const DisplacementConversion converted = DisplacementFromVolts(run, calibration);
  REQUIRE(converted.ok);
  REQUIRE(converted.left_out_s.size() == 1);
  CHECK(converted.left_out_s[0].first == Approx(-0.1));
  CHECK(converted.left_out_s[0].second == Approx(-0.06));
  CHECK(converted.left_out == 17);
  // The same line running on past the release is refused as before: there
  // the calibration may truly not reach.
  for (std::size_t i = 0; i < run.time_s.size() && run.time_s[i] <= 0.01; ++i) run.volts[i] = 2.6;
  const DisplacementConversion past = DisplacementFromVolts(run, calibration);
  CHECK_FALSE(past.ok);
  CHECK_THAT(past.reason, Catch::Contains("from its start"));
}

TEST_CASE("displacement: a line from the trace's start beyond X = 0 is left out, not refused") {
  const double x0 = 0.3;
  const CalibrationResult calibration = LinearCalibration(x0);  // 0.3 .. 2.0 V
  // The bar is at X0 when the sweep begins and never below X = 0 before its
  // first impact: a line read from the start down to -0.3 V (35 % of the
  // span below the volts of X = 0) is not the release, but a stroke the
  // reading followed (randomised seeds 2013's run 0.405, 2020's run 0.405).
  const Trace run = SwingWithScratch(x0, 0.0, 0.1, -0.3);
  const DisplacementConversion converted = DisplacementFromVolts(run, calibration);
  REQUIRE(converted.ok);
  REQUIRE(converted.left_out_s.size() == 1);
  CHECK(converted.left_out_s[0].first == Approx(0.0));
  CHECK(converted.left_out_s[0].second == Approx(0.1));
  CHECK(converted.left_out == 41);
  const DisplacementHistory& h = converted.history;
  REQUIRE(h.time_s.size() == run.time_s.size() - 41);
  for (std::size_t i = 0; i < h.time_s.size(); ++i) {
    CHECK(h.displacement[i] == Approx(SwingX(h.time_s[i], x0)).margin(1e-9));
  }
}

TEST_CASE("displacement: a trace shifted whole (a zero mistyped) is refused, not left out") {
  const double x0 = 0.3;
  const CalibrationResult calibration = LinearCalibration(x0);  // 0.3 .. 2.0 V
  // The bar's swings, released from X0, its volts all 0.3 V low: at every
  // impact far below the volts of X = 0, while its own span is the
  // calibration's. Which of its stretches are the bar's cannot be told.
  Trace run;
  for (int i = 0; i <= 800; ++i) {
    const double t = 0.0025 * i;
    run.time_s.push_back(t);
    run.volts.push_back(LinearCell(x0 * std::abs(std::cos(std::numbers::pi * t)), x0) - 0.3);
    run.sigma_volts.push_back(5e-4);
  }
  const DisplacementConversion shifted = DisplacementFromVolts(run, calibration);
  CHECK_FALSE(shifted.ok);
  CHECK_THAT(shifted.reason,
             Catch::Contains("far outside") && Catch::Contains("a zero_div mistyped?"));
}

// The sweep from 0.1 s before the release: the bar held at X0, then its fall
// to X = 0 a quarter period later, the hold read `hold_offset_volts` off
// (a bold trace's edge, a grid line beside it) up to 0.02 s after the
// release, where the reading comes back to the trace.
Trace ReleaseReadOff(double x0, double hold_offset_volts) {
  Trace run;
  const double quarter = 0.25 * 2.0 * HalfPeriod(kPendulum, x0);
  for (int i = -40; i <= 400; ++i) {
    const double t = 0.0025 * i;
    const double x = t < 0.0 ? x0 : ReleaseSwingDisplacement(kPendulum, x0, std::min(t, quarter));
    run.time_s.push_back(t);
    run.volts.push_back(LinearCell(x, x0) + (t <= 0.02 + 1e-12 ? hold_offset_volts : 0.0));
    run.sigma_volts.push_back(5e-4);
  }
  return run;
}

TEST_CASE(
    "displacement: a run released within its calibration's swing has its hold read beyond X0's "
    "volts left out, not refused; released beyond it, refused") {
  const double x0 = 0.3;
  const CalibrationResult calibration = LinearCalibration(x0);  // 0.3 .. 2.0 V
  // 49 samples (11 % of the trace) 0.03 V beyond X0's volts (1.8 % of the
  // span, past the 1 % margin): too many to drop, near enough to be the
  // hold read off (randomised seed 3002's run 0.405).
  const Trace near = ReleaseReadOff(x0, 0.03);
  CHECK_FALSE(DisplacementFromVolts(near, calibration).ok);  // X0 not known
  const DisplacementConversion within = DisplacementFromVolts(near, calibration, {}, x0);
  REQUIRE(within.ok);
  CHECK(within.hold_beyond == 49);
  CHECK(within.dropped == 0);
  CHECK(within.left_out == 0);
  CHECK(within.history.time_s.front() == Approx(0.0225));
  for (std::size_t i = 0; i < within.history.time_s.size(); ++i) {
    CHECK(within.history.displacement[i] ==
          Approx(std::min(x0, ReleaseSwingDisplacement(kPendulum, x0,
                                                       std::min(within.history.time_s[i],
                                                                0.5 * HalfPeriod(kPendulum, x0)))))
              .margin(1e-9));
  }
  // 0.2 V beyond (12 % of the span): far, a line followed from the trace's
  // start (randomised seed 4028's run 0.405, an arrow drawn at the trace's
  // start): left out as misread.
  const DisplacementConversion far =
      DisplacementFromVolts(ReleaseReadOff(x0, 0.2), calibration, {}, x0);
  REQUIRE(far.ok);
  REQUIRE(far.left_out_s.size() == 1);
  CHECK(far.left_out_s[0].first == Approx(-0.1));
  // A run let go 3 % further out than its calibration's swing: the
  // calibration truly may not reach its release, and says so.
  const DisplacementConversion beyond =
      DisplacementFromVolts(ReleaseReadOff(x0, 0.2), calibration, {}, 1.03 * x0);
  CHECK_FALSE(beyond.ok);
  CHECK_THAT(beyond.reason, Catch::Contains("from its start"));
}

}  // namespace
}  // namespace impactlab
