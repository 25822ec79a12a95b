#include "calibration/photocell_calibration.h"

#include <cmath>
#include <functional>
#include <initializer_list>
#include <random>
#include <tuple>

#include <catch2/catch.hpp>

#include "tests/calibration/linear_cell.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using testing::kPendulum;

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
using testing::LinearCell;                 // inverted amplifier
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

// A sweep whose voltage errs smoothly along the trace, as a digitized photo's
// does (blur, the graticule's residual mapping) or a scope's quantised record:
// first-order autoregressive noise of rms `noise_v` and correlation time `tau`.
Trace CorrelatedSweep(double x0, double (*volts)(double x, double x0), double noise_v, double tau,
                      double dt, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double phi = std::exp(-dt / tau);
  const double kick = noise_v * std::sqrt(1.0 - phi * phi);
  Trace trace;
  const double end = 0.5 * HalfPeriod(kPendulum, x0);
  double e = noise_v * normal(rng);
  for (double t = 0.0; t <= end; t += dt) {
    trace.time_s.push_back(t);
    trace.volts.push_back(volts(ReleaseSwingDisplacement(kPendulum, x0, t), x0) + e);
    e = phi * e + kick * normal(rng);
  }
  return trace;
}

// The curve's error at a few displacements divided by its stated band, over
// many calibrations: the rms of these pulls is 1 when the band is honest.
double CurvePullRms(double noise_v, double tau, double* inflation) {
  const double x0 = 0.337;
  double sum = 0.0, sum_inflation = 0.0;
  int count = 0;
  const int sweeps = 40;
  for (int seed = 1; seed <= sweeps; ++seed) {
    const CalibrationResult c = CalibratePhotocell(
        CorrelatedSweep(x0, NonlinearCell, noise_v, tau, 1e-4, seed), kPendulum, x0, {});
    sum_inflation += c.correlation_inflation;
    for (double s : {0.1, 0.25, 0.5, 0.75, 0.9}) {
      const double x = s * x0;
      const double v = NonlinearCell(x, x0);
      const double pull = (c.curve.DisplacementFromVolts(v) - x) / c.curve.DisplacementSigma(v);
      sum += pull * pull;
      ++count;
    }
  }
  *inflation = sum_inflation / sweeps;
  return std::sqrt(sum / count);
}

TEST_CASE("photocell: the curve's band is honest when the trace's errors are correlated") {
  // Independent noise: the band as least squares gives it, barely inflated.
  double inflation = 0.0;
  const double white = CurvePullRms(0.005, 1e-9, &inflation);
  CHECK(inflation < 1.3);
  CHECK(white > 0.6);
  CHECK(white < 1.5);
  // Errors correlated over 5 ms (50 samples): counting every sample as an
  // independent reading understates the band tenfold (pull rms 10.8). The
  // autocorrelation sum, from ~75 correlation lengths, runs somewhat low
  // (56 for the true 99), so the pulls come out near 1.5, not 1.
  const double correlated = CurvePullRms(0.005, 5e-3, &inflation);
  CHECK(inflation > 20.0);
  CHECK(correlated > 0.6);
  CHECK(correlated < 2.0);
}

// The nonlinear cell's sweep (2 mV noise) with `misread(X / X0)` volts added
// to each sample.
Trace SweepMisreadBy(double x0, unsigned seed, const std::function<double(double)>& misread) {
  Trace trace = Sweep(x0, NonlinearCell, 0.002, 2e-4, seed);
  for (std::size_t i = 0; i < trace.time_s.size(); ++i) {
    trace.volts[i] += misread(ReleaseSwingDisplacement(kPendulum, x0, trace.time_s[i]) / x0);
  }
  return trace;
}

// A sweep whose trace was misread over a stretch, as when the digitizer
// follows a hand mark or a grid line beside the trace for a division or so:
// the volts there bulge by up to `bulge` V (a smooth bump over X in
// [0.45, 0.6] X0), which a high order follows.
Trace MisreadSweep(double x0, double bulge, unsigned seed) {
  return SweepMisreadBy(x0, seed, [&](double s) {
    return s > 0.45 && s < 0.6 ? bulge * std::pow(std::sin(M_PI * (s - 0.45) / 0.15), 2) : 0.0;
  });
}

TEST_CASE(
    "photocell: a stretch of the trace misread widens the band there, by how much the curve "
    "depends on it") {
  // An order 8 follows the bump and leaves its residuals correlated only
  // over the stretch: least squares' band, even inflated for that, put the
  // curve about 5 sigma off in the middle of the stretch (the same model
  // fitted in numpy: error 0.0043 V, band 0.0008 V). Refitting without each
  // tenth of the trace shows how much the curve there depends on it (0.0042 V).
  const double x0 = 0.405;
  int within_two = 0, checked = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const CalibrationResult c =
        CalibratePhotocell(MisreadSweep(x0, 0.01, seed), kPendulum, x0, CalibrationOptions{});
    REQUIRE(c.ok);
    for (double s : {0.5, 0.525, 0.55}) {
      const double v = NonlinearCell(s * x0, x0);
      const double error = c.curve.DisplacementFromVolts(v) - s * x0;
      within_two += std::abs(error) < 2.0 * c.curve.DisplacementSigma(v);
      ++checked;
    }
  }
  INFO(within_two << " of " << checked << " within 2 sigma");
  CHECK(within_two >= 0.9 * checked);
}

TEST_CASE("photocell: an error every sample shares widens the band by itself, through the slope") {
  // A constant in volts (a photo's mapping error) is the T_0 coefficient's:
  // the band's variance at every X grows by (sigma / slope)^2 exactly.
  const double x0 = 0.405, shared = 0.004;
  const Trace sweep = Sweep(x0, NonlinearCell, 0.002, 2e-4, 3);
  const CalibrationResult plain = CalibratePhotocell(sweep, kPendulum, x0, {});
  const CalibrationResult with = CalibratePhotocell(sweep, kPendulum, x0, {}, shared);
  REQUIRE(with.ok);
  CHECK(with.curve.order() == plain.curve.order());
  for (double s : {0.05, 0.3, 0.7, 0.95}) {
    const double x = s * x0;
    const double slope = with.curve.SlopeAt(x);
    const double expected =
        std::hypot(plain.curve.DisplacementSigmaAt(x), shared / std::abs(slope));
    CHECK(with.curve.DisplacementSigmaAt(x) == Approx(expected).epsilon(1e-9));
    CHECK(with.curve.VoltsAt(x) == plain.curve.VoltsAt(x));
  }
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
  const CalibrationResult c =
      CalibratePhotocell(Sweep(x0, FoldingCell, 0.0, 5e-4, 1), kPendulum, x0, CalibrationOptions{});
  CHECK_FALSE(c.ok);
  CHECK_THAT(c.reason, Catch::Contains("not monotone") && Catch::Contains("X ="));
}

TEST_CASE("photocell: a refused curve says which part of the swing the samples leave unread") {
  const double x0 = 0.5;
  Trace part;  // only X > X0/2 was read: the fast half of the swing is missing
  const Trace sweep = Sweep(x0, FoldingCell, 0.0, 5e-4, 1);
  for (std::size_t i = 0; i < sweep.time_s.size(); ++i) {
    if (ReleaseSwingDisplacement(kPendulum, x0, sweep.time_s[i]) < 0.5 * x0) continue;
    part.time_s.push_back(sweep.time_s[i]);
    part.volts.push_back(sweep.volts[i]);
  }
  const CalibrationResult c = CalibratePhotocell(part, kPendulum, x0, CalibrationOptions{});
  CHECK_FALSE(c.ok);
  CHECK_THAT(c.reason, Catch::Contains("not monotone") && Catch::Contains("leave X = 0 .. 0.25") &&
                           Catch::Contains("(50 %"));
  // A whole swing has no such remark.
  const CalibrationResult whole = CalibratePhotocell(sweep, kPendulum, x0, CalibrationOptions{});
  CHECK_THAT(whole.reason, !Catch::Contains("unread"));
}

// A cell whose output flattens towards the release (its slope falls to a
// hundredth there): noise lets a high order's slope change sign near it.
double FlatteningCell(double x, double x0) {
  const double s = x / x0;
  return 2.0 - 1.9 * s + 0.94 * s * s;
}

// How many of `cell`'s voltages at the `fractions` of X0 `curve` converts to
// within `sigmas` of its band of their displacement.
int WithinBand(const PhotocellCurve& curve, double (*cell)(double x, double x0), double x0,
               std::initializer_list<double> fractions, double sigmas) {
  int within = 0;
  for (const double s : fractions) {
    const double v = cell(s * x0, x0);
    within +=
        std::abs(curve.DisplacementFromVolts(v) - s * x0) < sigmas * curve.DisplacementSigma(v);
  }
  return within;
}

TEST_CASE(
    "photocell: where the best order's curve is not monotone, a monotone order that fits as well "
    "is taken, with an honest band") {
  // Sweeps with a gap of a third of the swing (the trace lost behind a mark)
  // and noise: over 40 seeds, every one calibrates, and the curve's error
  // at X0/2 and near the release stays within its 1-sigma band at least
  // 60 % of the time (68 % expected: the band is not over-confident).
  const double x0 = 0.405;
  int taken_lower = 0, within = 0, checked = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    Trace sweep = Sweep(x0, FlatteningCell, 0.001, 4e-4, seed);
    Trace gapped;
    for (std::size_t i = 0; i < sweep.time_s.size(); ++i) {
      const double x = ReleaseSwingDisplacement(kPendulum, x0, sweep.time_s[i]);
      if (x > 0.34 * x0 && x < 0.66 * x0) continue;
      gapped.time_s.push_back(sweep.time_s[i]);
      // The digitized centre's slow wobble (grid crossings, grain): correlated.
      gapped.volts.push_back(sweep.volts[i] +
                             0.004 * std::sin(2.0 * M_PI * sweep.time_s[i] / 0.04 + seed));
    }
    const CalibrationResult c = CalibratePhotocell(gapped, kPendulum, x0, CalibrationOptions{});
    const auto best = std::min_element(c.bic.begin(), c.bic.end()) - c.bic.begin() + 1;
    taken_lower += c.curve.order() < best;
    within += WithinBand(c.curve, FlatteningCell, x0, {0.5, 0.9}, 1.0);
    checked += 2;
  }
  // The BIC's own order was refused on 19 of the 40 (each refused whole
  // before); 73 of the 80 errors lie within 1 sigma.
  CHECK(taken_lower >= 10);
  CHECK(within >= 0.6 * checked);
}

// A sweep whose tracking left the trace for a stretch and followed a mark:
// the samples with X in [from, to] X0 read `offset` V off the cell's curve,
// with the trace's own noise.
Trace SweepOnAMark(double x0, double from, double to, double offset, unsigned seed) {
  return SweepMisreadBy(x0, seed, [&](double s) { return s >= from && s <= to ? offset : 0.0; });
}

// On ten seeds, a mark followed over X in [from, to] X0 (`offset` volts off
// the trace) is left out as one stretch, to within 0.5 ms at each end, and the
// curve through the rest holds the truth within 2 sigma at nine places in ten.
void CheckMarkLeftOutAndCurveHonest(double from, double to, double offset) {
  const double x0 = 0.405;
  int within_two = 0, checked = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const Trace trace = SweepOnAMark(x0, from, to, offset, seed);
    const CalibrationResult c = CalibratePhotocell(trace, kPendulum, x0, CalibrationOptions{});
    INFO("seed " << seed << ": " << c.reason);
    REQUIRE(c.ok);
    REQUIRE(c.left_out_s.size() == 1);
    double t_from = 1e9, t_to = -1e9;
    for (const double t : trace.time_s) {
      const double s = ReleaseSwingDisplacement(kPendulum, x0, t) / x0;
      if (s < from || s > to) continue;
      t_from = std::min(t_from, t);
      t_to = std::max(t_to, t);
    }
    CHECK(c.left_out_s.front()[0] == Approx(t_from).margin(5e-4));
    CHECK(c.left_out_s.front()[1] == Approx(t_to).margin(5e-4));
    CHECK(c.samples_used < static_cast<int>(trace.time_s.size()));
    for (double s : {0.2, 0.5, 0.8, 0.99}) {
      const double v = NonlinearCell(s * x0, x0);
      within_two +=
          std::abs(c.curve.DisplacementFromVolts(v) - s * x0) < 2.0 * c.curve.DisplacementSigma(v);
      ++checked;
    }
  }
  INFO(within_two << " of " << checked << " within 2 sigma");
  CHECK(within_two >= 0.9 * checked);
}

TEST_CASE(
    "photocell: a stretch read off a mark that leaves no monotone curve is left out, recorded, "
    "and the curve through the rest is honest") {
  // Near the release the bar is slow, so a mark followed for a few
  // milliseconds is many samples at one place: a high order bends to them
  // and turns back (the whole calibration was refused before).
  CheckMarkLeftOutAndCurveHonest(0.05, 0.12, 0.15);
}

TEST_CASE(
    "photocell: a stretch read off a mark that the whole curve rings about is found by leaving "
    "runs of samples out, and the curve through the rest is honest") {
  // A trace followed onto a mark far off it (0.4 V, a fifth of the cell's
  // range) over a tenth of the swing: every order bends or rings about the
  // step, the residuals' robust scale grows with it, and no sample stands
  // out of the curve through all (the calibration was refused before).
  CheckMarkLeftOutAndCurveHonest(0.55, 0.65, -0.4);
}

TEST_CASE(
    "photocell: a hand mark followed over more than a seventh of the samples, plainly another "
    "line, is left out, and the curve through the rest is honest") {
  // X in [0.3, 0.55] X0 holds 18 % of the swing's samples, read a quarter of
  // the cell's swing off the trace (the calibration was refused before: at
  // most 15 % of the samples could be left out).
  CheckMarkLeftOutAndCurveHonest(0.3, 0.55, -0.4);
}

TEST_CASE(
    "photocell: a long stretch only slightly off, or at the end of the swing, is not left out") {
  // The same share of the samples read 0.05 V off (3 % of the cell's swing:
  // the trace's own reading error, not another line), and a mark over the
  // last 18 % of the samples (X below 0.28 X0: the curve there would be the
  // fit's extrapolation): whatever the calibration does, it leaves out no
  // more than 15 % of the samples.
  const double x0 = 0.405;
  for (unsigned seed = 1; seed <= 2; ++seed) {
    for (const auto& [from, to, offset] :
         {std::tuple{0.3, 0.55, 0.05}, std::tuple{0.0, 0.28, -0.4}}) {
      const Trace trace = SweepOnAMark(x0, from, to, offset, seed);
      const CalibrationResult c = CalibratePhotocell(trace, kPendulum, x0, CalibrationOptions{});
      int swing = 0;
      for (const double t : trace.time_s) swing += t <= 0.5 * HalfPeriod(kPendulum, x0);
      INFO("seed " << seed << " from " << from << ": " << c.reason);
      if (c.ok) CHECK(c.samples_used >= 0.85 * swing);
    }
  }
}

TEST_CASE(
    "photocell: a mark plainly another line and a short misreading at the swing's end are left "
    "out together, and the curve through the rest is honest") {
  // The first 2 % of the samples (X above 0.9995 X0, at the release) read
  // 1 V off, a stroke the reading began on, and X in [0.3, 0.55] X0 (18 %)
  // a hand mark 0.4 V off: together more than 15 % and reaching the swing's
  // end, each judged by itself (randomised seed 3026's: 3 samples
  // at the release and a mark over 28 % of the samples, refused before).
  const double x0 = 0.405;
  int within_two = 0, checked = 0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Trace trace = SweepMisreadBy(
        x0, seed, [](double s) { return s > 0.9995 ? 1.0 : (s >= 0.3 && s <= 0.55 ? -0.4 : 0.0); });
    const CalibrationResult c = CalibratePhotocell(trace, kPendulum, x0, CalibrationOptions{});
    INFO("seed " << seed << ": " << c.reason);
    REQUIRE(c.ok);
    CHECK(c.left_out_s.size() == 2);
    for (double s : {0.2, 0.5, 0.8, 0.99}) {
      const double v = NonlinearCell(s * x0, x0);
      within_two +=
          std::abs(c.curve.DisplacementFromVolts(v) - s * x0) < 2.0 * c.curve.DisplacementSigma(v);
      ++checked;
    }
  }
  INFO(within_two << " of " << checked << " within 2 sigma");
  CHECK(within_two >= 0.9 * checked);
}

TEST_CASE("photocell: a clean trace has nothing left out, a folding cell is still refused") {
  const double x0 = 0.405;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const CalibrationResult c =
        CalibratePhotocell(Sweep(x0, NonlinearCell, 0.002, 2e-4, seed), kPendulum, x0, {});
    REQUIRE(c.ok);
    CHECK(c.left_out_s.empty());
    const CalibrationResult folding =
        CalibratePhotocell(Sweep(x0, FoldingCell, 0.002, 2e-4, seed), kPendulum, x0, {});
    CHECK_FALSE(folding.ok);
  }
}

// A cell that saturates gently towards the release (the generator's tanh
// law, randomised seed 2029's left cell).
double SaturatingCell(double x, double /*x0*/) {
  return 0.1436 - 0.714 * std::tanh(0.918 * (x + 0.186)) / 0.918;
}

TEST_CASE(
    "photocell: where the best order bends through the reading's own systematic errors, a "
    "monotone order near as close is taken, with an honest band") {
  // Sweeps each sample of which states 1 mV of scatter, read a few mV off
  // in steps where the trace crosses grid lines near the release (a printed
  // figure's bold trace pulled by a line's dots; randomised seed 2029's
  // calibration L-0.713: 10 mV low before the crossing at 2 divisions,
  // 10 mV high after it): the BIC takes the steps for the cell's shape and
  // its order turns over. A monotone order misses the samples by little
  // more and is taken, its band widened to cover the best order: all 40
  // calibrate (32 before), and the curve is within 2 sigma of the cell's at
  // 112 of 160 points (before, 96 of the 128 calibrated). Steps like these
  // are not noise the band is made from: it holds them at 70 %, not 95 %.
  const double x0 = 0.7154;
  int taken = 0, within = 0, checked = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    Trace sweep = Sweep(x0, SaturatingCell, 0.001, 1e-3, seed);
    for (std::size_t i = 0; i < sweep.time_s.size(); ++i) {
      const double t = sweep.time_s[i];
      sweep.volts[i] += t < 0.09 ? -0.01 : (t < 0.15 ? 0.01 : 0.0);
    }
    const CalibrationResult c = CalibratePhotocell(sweep, kPendulum, x0, CalibrationOptions{});
    if (!c.ok) continue;
    ++taken;
    within += WithinBand(c.curve, SaturatingCell, x0, {0.2, 0.5, 0.8, 0.95}, 2.0);
    checked += 4;
  }
  INFO(taken << " of 40 calibrated, " << within << " of " << checked << " within 2 sigma");
  CHECK(taken == 40);
  CHECK(within >= 0.65 * checked);
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
  const CalibrationResult c = CalibratePhotocell(t, kPendulum, 0.4, CalibrationOptions{});
  CHECK_FALSE(c.ok);
  CHECK_THAT(c.reason, Catch::Contains("at least 8"));
}

}  // namespace
}  // namespace impactlab
