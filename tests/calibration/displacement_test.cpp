#include "calibration/displacement.h"

#include <cmath>

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

TEST_CASE("displacement: samples beyond the calibrated volts are dropped, too many refused") {
  const double x0 = 0.3;
  const CalibrationResult calibration = LinearCalibration(x0);
  Trace run;
  for (int i = 0; i < 100; ++i) {
    run.time_s.push_back(0.01 * i);
    run.volts.push_back(LinearCell(0.5 * x0, x0));
  }
  run.volts[7] = 5.0;  // one in a hundred outside: dropped
  const DisplacementConversion one = DisplacementFromVolts(run, calibration);
  CHECK(one.ok);
  CHECK(one.dropped == 1);
  CHECK(one.history.time_s.size() == 99);
  run.volts[8] = run.volts[9] = 5.0;  // three in a hundred: the curve does not cover the run
  // Refused as a value, with what was converted kept beside the reason.
  const DisplacementConversion three = DisplacementFromVolts(run, calibration);
  CHECK_FALSE(three.ok);
  CHECK_THAT(three.reason,
             Catch::Contains("3 of 100 samples") && Catch::Contains("calibrated range"));
  CHECK(three.dropped == 3);
  CHECK(three.history.time_s.size() == 97);
  const DisplacementConversion empty = DisplacementFromVolts(Trace{}, calibration);
  CHECK_FALSE(empty.ok);
  CHECK(empty.reason == "the trace has no samples");
}

}  // namespace
}  // namespace impactlab
