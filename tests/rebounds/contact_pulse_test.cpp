#include <algorithm>
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "rebounds/rebound_extraction.h"

namespace impactlab {
namespace {

// A digitized photo's contact trace about its edges: samples 11 us apart,
// each edge a step anywhere between two of them, and the sample after each
// step on the beam's blurred corner, 94 % of the way to its level (so 9
// noise off it: no sample "at its level"). The straight line through the
// two samples about the step is no measure of where in the interval the
// step lies, and the width's sigma must say so.
Trace CornerTrace(double rise, double width, std::mt19937& random) {
  std::normal_distribution<double> noise(0.0, 0.015);
  constexpr double kLow = 0.16, kHigh = 2.57, kDt = 11e-6;
  Trace trace;
  bool after_rise = false, after_fall = false;
  for (double t = 0.0; t < 1e-3; t += kDt) {
    const bool high = t >= rise && t < rise + width;
    double v = high ? kHigh : kLow;
    if (high && !after_rise) v = kLow + 0.94 * (kHigh - kLow), after_rise = true;
    if (!high && t >= rise + width && !after_fall) {
      v = kHigh - 0.94 * (kHigh - kLow), after_fall = true;
    }
    trace.time_s.push_back(t);
    trace.volts.push_back(v + noise(random));
  }
  return trace;
}

TEST_CASE("contact_pulse: a step between two samples, one on its corner, states the interval") {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  double sum2 = 0.0;
  const int n = 200;
  for (int k = 0; k < n; ++k) {
    const double rise = 100e-6 + 11e-6 * uniform(random);
    const double width = 353e-6 + 11e-6 * uniform(random);
    const ContactPulseMeasurement m = MeasureContactPulse(CornerTrace(rise, width, random));
    REQUIRE(m.ok);
    const double pull = (m.pulse.width_s.value - width) / m.pulse.width_s.sigma;
    sum2 += pull * pull;
  }
  // Honest: about 1 (it was 17 with the slope's sigma).
  CHECK(std::sqrt(sum2 / n) == Approx(1.0).margin(0.35));
}

TEST_CASE("contact_pulse: a ramp the samples follow keeps the slope's sigma") {
  // A 5 us ramp at 1 us samples: no interval makes most of the step.
  Trace trace;
  const double rise = 123.4e-6, width = 353.35e-6;
  for (double t = 0.0; t < 1e-3; t += 1e-6) {
    const auto step = [](double s) { return std::clamp(s / 5e-6 + 0.5, 0.0, 1.0); };
    trace.time_s.push_back(t);
    trace.volts.push_back(0.1 + 2.4 * (step(t - rise) - step(t - rise - width)) +
                          1e-3 * std::sin(1e7 * t));
  }
  const ContactPulseMeasurement m = MeasureContactPulse(trace);
  REQUIRE(m.ok);
  CHECK(m.pulse.width_s.sigma < 0.05e-6);
  CHECK(m.pulse.width_s.value == Approx(width).margin(0.05e-6));
}

TEST_CASE("contact_pulse: two samples on an edge across a gap in the trace state the gap") {
  // A trace read in 1 us samples, lost for 50 us about the fall (the beam
  // lost to the tracking): two samples half way down the step, on a trace
  // misread 4 us before the true fall, cross half the step there.
  const double rise = 100e-6, width = 353e-6, fall = rise + width;
  Trace trace;
  for (double t = 0.0; t < 1e-3; t += 1e-6) {
    if (t > fall - 50e-6 && t < fall + 2e-6) continue;  // the gap
    trace.time_s.push_back(t);
    trace.volts.push_back(t >= rise && t < fall ? 2.5 : 0.1);
  }
  // The two samples on the misread edge, within the gap.
  const auto at =
      std::lower_bound(trace.time_s.begin(), trace.time_s.end(), fall) - trace.time_s.begin();
  trace.time_s.insert(trace.time_s.begin() + at, {fall - 5.5e-6, fall - 5.2e-6});
  trace.volts.insert(trace.volts.begin() + at, {1.7, 0.8});
  const ContactPulseMeasurement m = MeasureContactPulse(trace);
  REQUIRE(m.ok);
  // Some 5 us short (the rise is timed to its 1 us interval): the sigma
  // spans the gap either side of the two samples.
  CHECK(m.pulse.width_s.value == Approx(width - 5.4e-6).margin(1e-6));
  CHECK(m.pulse.fall_s.sigma > 40e-6 / std::sqrt(12.0));
  CHECK(std::abs(m.pulse.width_s.value - width) < m.pulse.width_s.sigma);
  // The rise, where the trace is followed, keeps its interval's sigma.
  CHECK(m.pulse.rise_s.sigma < 1e-6);
}

}  // namespace
}  // namespace impactlab
