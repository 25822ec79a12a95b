#include "calibration/photocell_calibration.h"

#include <cmath>
#include <random>

#include <catch2/catch.hpp>

namespace impactlab {
namespace {

const Pendulum kPendulum{22.0, 385.644, PendulumConvention::kExact};

// A calibration sweep of a cell with a known curve, sampled every `dt` from
// release through a little past the equilibrium crossing, with noise.
Trace Sweep(double x0, double (*volts)(double x, double x0), double noise_v, double dt,
            unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_v);
  Trace trace;
  const double end = 0.5 * HalfPeriod(kPendulum, x0);
  for (double t = 0.0; t <= end * 1.02; t += dt) {
    // Past the crossing the other side of the swing does not belong to the fit.
    const double x = std::max(0.0, ReleaseSwingDisplacement(kPendulum, x0, std::min(t, end)));
    trace.time_s.push_back(t);
    trace.volts.push_back(volts(x, x0) + noise(rng));
  }
  return trace;
}

// Light falls as the bar shutters the lamp: a strongly nonlinear falling cell.
double NonlinearCell(double x, double x0) {
  const double s = x / x0;
  return 2.4 - 1.9 * s + 0.45 * s * s - 0.12 * s * s * s;
}
double LinearCell(double x, double x0) { return 0.3 + 1.7 * x / x0; }  // inverted amplifier
double FoldingCell(double x, double x0) {  // not monotone: saturates and turns back
  const double s = x / x0;
  return 2.0 - 3.0 * s + 2.0 * s * s;
}

TEST_CASE("photocell: a noiseless nonlinear cell is recovered to 1e-9 of X0") {
  const double x0 = 0.405;
  const CalibrationResult c = CalibratePhotocell(Sweep(x0, NonlinearCell, 0.0, 2e-4, 1), kPendulum,
                                                 x0, CalibrationOptions{});
  CHECK(c.curve.falling());
  CHECK(c.curve.order() >= 3);
  for (double s : {0.0, 0.1, 0.37, 0.8, 1.0}) {
    const double x = s * x0;
    CHECK(c.curve.DisplacementFromVolts(NonlinearCell(x, x0)) == Approx(x).margin(1e-9 * x0));
  }
}

TEST_CASE(
    "photocell: with noise, the error stays inside the reported band about as often as 1 sigma "
    "says") {
  const double x0 = 0.234;
  const CalibrationResult c = CalibratePhotocell(Sweep(x0, NonlinearCell, 0.01, 1e-4, 7), kPendulum,
                                                 x0, CalibrationOptions{});
  CHECK(c.residual_rms_volts == Approx(0.01).epsilon(0.1));
  int inside = 0, total = 0;
  for (int k = 1; k < 100; ++k) {
    const double x = x0 * k / 100.0;
    const double v = NonlinearCell(x, x0);
    const double error = std::abs(c.curve.DisplacementFromVolts(v) - x);
    inside += error <= c.curve.DisplacementSigma(v) ? 1 : 0;
    ++total;
    CHECK(error < 5e-3 * x0);  // thousands of samples average the noise down
  }
  // Points along one curve are correlated, so only a loose check of coverage.
  CHECK(inside > total / 3);
}

TEST_CASE("photocell: a rising (inverted) cell works the same way") {
  const double x0 = 1.519;
  const CalibrationResult c =
      CalibratePhotocell(Sweep(x0, LinearCell, 0.0, 5e-4, 1), kPendulum, x0, CalibrationOptions{});
  CHECK_FALSE(c.curve.falling());
  CHECK(c.curve.DisplacementFromVolts(LinearCell(0.5, x0)) == Approx(0.5).epsilon(1e-10));
}

TEST_CASE("photocell: a curve that is not monotone is refused, saying where") {
  const double x0 = 0.5;
  CHECK_THROWS_WITH(
      CalibratePhotocell(Sweep(x0, FoldingCell, 0.0, 5e-4, 1), kPendulum, x0, CalibrationOptions{}),
      Catch::Contains("not monotone") && Catch::Contains("X ="));
}

TEST_CASE("photocell: converting a voltage outside the calibrated range is refused") {
  const double x0 = 0.405;
  const CalibrationResult c = CalibratePhotocell(Sweep(x0, NonlinearCell, 0.0, 2e-4, 1), kPendulum,
                                                 x0, CalibrationOptions{});
  CHECK(c.curve.Covers(NonlinearCell(0.2, x0)));
  CHECK_FALSE(c.curve.Covers(NonlinearCell(0.0, x0) + 0.5));
  CHECK_THROWS_WITH(c.curve.DisplacementFromVolts(NonlinearCell(0.0, x0) + 0.5),
                    Catch::Contains("outside the calibrated range"));
}

TEST_CASE("photocell: too few samples in the first swing is a clear error") {
  Trace t;
  t.time_s = {0.0, 0.1, 0.2};
  t.volts = {2.0, 1.5, 1.0};
  CHECK_THROWS_WITH(CalibratePhotocell(t, kPendulum, 0.4, CalibrationOptions{}),
                    Catch::Contains("at least 8"));
}

}  // namespace
}  // namespace impactlab
