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

}  // namespace
}  // namespace impactlab
