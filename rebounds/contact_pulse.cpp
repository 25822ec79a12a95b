// MeasureContactPulse: the contact circuit's step pulse from a sampled trace
// (a CSV trace; photos measure the edges on the image itself, digitize/).
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "rebounds/rebound_extraction.h"

namespace impactlab {

ContactPulseMeasurement MeasureContactPulse(const Trace& trace) {
  const auto refused = [](std::string reason) {
    return ContactPulseMeasurement{false, std::move(reason), {}};
  };
  const std::size_t n = trace.volts.size();
  if (n < 8) return refused("a contact trace needs at least 8 samples");
  std::vector<double> sorted = trace.volts;
  std::sort(sorted.begin(), sorted.end());
  ContactPulse pulse;
  pulse.low_volts = sorted[n / 10];
  pulse.high_volts = sorted[n - 1 - n / 10];
  // Noise from the low state's spread (median absolute deviation).
  std::vector<double> low_state;
  const double mid = 0.5 * (pulse.low_volts + pulse.high_volts);
  for (double v : trace.volts) {
    if (v < mid) low_state.push_back(std::abs(v - pulse.low_volts));
  }
  // A flat trace (or one at two levels only in its extreme tenths) has no
  // low state below the midpoint to measure the noise on.
  if (low_state.empty()) return refused("the contact trace shows no step above its noise");
  std::nth_element(low_state.begin(), low_state.begin() + low_state.size() / 2, low_state.end());
  const double noise = 1.4826 * low_state[low_state.size() / 2];
  if (!(pulse.high_volts - pulse.low_volts > 6.0 * noise) || pulse.high_volts == pulse.low_volts) {
    return refused("the contact trace shows no step above its noise");
  }

  // Crossing of `mid` between samples i and i + 1, with its uncertainty: the
  // noise over the slope where the samples resolve the edge, else the sample
  // interval's uniform spread.
  //
  // The straight line through the two samples is the edge only where the
  // edge is a ramp the samples follow, more than one interval long. Where
  // one interval makes most of the step, at most one sample lies on the
  // edge, and nothing tells a ramp through it from a step anywhere in the
  // interval with that sample on the beam's blurred corner (a digitized
  // photo's samples beside a contact edge are the trace's glow, not the
  // edge). Only both samples within 3 noise of their levels was asked
  // before: randomised seed 2025's run 0.405, its samples 11 us apart about
  // the rise, the later one at 94 % of the step, 9 noise below its level,
  // stated the rise to 0.08 us, 4.4 us off (contact pull 47.6).
  const double step = pulse.high_volts - pulse.low_volts;
  // The samples' usual spacing, for telling a gap in them.
  std::vector<double> spacings;
  for (std::size_t k = 0; k + 1 < n; ++k) spacings.push_back(trace.time_s[k + 1] - trace.time_s[k]);
  std::nth_element(spacings.begin(), spacings.begin() + spacings.size() / 2, spacings.end());
  const double usual_spacing = spacings[spacings.size() / 2];
  // Two samples on the edge resolve it only where the trace is followed
  // about them: across a gap beside them (the beam lost to the tracking, a
  // stretch of a sampled trace missing) nothing says they lie on the edge
  // rather than on a trace misread beside it, and the edge lies anywhere
  // between the samples either side of the two. (Randomised seed 3024's run
  // 0.713, its contact trace read in 36 samples: two samples 3.3 us apart
  // crossed half the step 45 us after the last sample at the pulse's level,
  // and stated the fall to 0.5 us, 4.3 us early: contact pull -5.7.)
  constexpr double kGapSpacings = 4.0;
  const auto bracket_sigma = [&](std::size_t i) {
    const std::size_t before = i > 0 ? i - 1 : i, after = std::min(i + 2, n - 1);
    const double t_before = trace.time_s[before], t_after = trace.time_s[after];
    const bool gap = trace.time_s[i] - t_before > kGapSpacings * usual_spacing ||
                     t_after - trace.time_s[i + 1] > kGapSpacings * usual_spacing;
    return gap ? (t_after - t_before) / std::sqrt(12.0) : 0.0;
  };
  const auto edge = [&](std::size_t i) {
    const double t0 = trace.time_s[i], t1 = trace.time_s[i + 1];
    const double v0 = trace.volts[i], v1 = trace.volts[i + 1];
    const double t = t0 + (t1 - t0) * (mid - v0) / (v1 - v0);
    const double slope = std::abs(v1 - v0) / (t1 - t0);
    const double resolved_sigma = noise / slope;
    const bool one_sample_jump = std::min(v0, v1) < pulse.low_volts + 3.0 * noise &&
                                 std::max(v0, v1) > pulse.high_volts - 3.0 * noise;
    const bool most_of_step = std::abs(v1 - v0) > 0.5 * step;
    const double interval_sigma = (t1 - t0) / std::sqrt(12.0);
    const double sigma =
        one_sample_jump || most_of_step ? std::max(interval_sigma, resolved_sigma) : resolved_sigma;
    return Estimate{t, std::max(sigma, bracket_sigma(i))};
  };
  // Every pulse: a rising crossing of `mid` and the falling one after it.
  struct Crossings {
    std::size_t rise = 0, fall = 0;  // the samples before each crossing
    std::ptrdiff_t at_level = 0;     // samples at the pulse's level between them
  };
  std::vector<Crossings> pulses;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const bool rising = trace.volts[k] < mid && trace.volts[k + 1] >= mid;
    const bool falling = trace.volts[k] >= mid && trace.volts[k + 1] < mid;
    if (rising) pulses.push_back({k, n, 0});
    if (falling && !pulses.empty() && pulses.back().fall == n) pulses.back().fall = k;
  }
  if (pulses.empty()) return refused("the contact trace has no rising edge");
  if (pulses.back().fall == n) {
    if (pulses.size() == 1) return refused("the contact pulse does not end within the trace");
    pulses.pop_back();
  }
  // The bars touch once in a sweep: the pulse is the one holding most of the
  // samples at the pulse's level, or what it times is something else (a
  // label across the trace read as a pulse of its own, before the contact's
  // or after it, is passed over; a trace misread is refused).
  for (Crossings& p : pulses) {
    p.at_level = std::count_if(trace.volts.begin() + static_cast<std::ptrdiff_t>(p.rise + 1),
                               trace.volts.begin() + static_cast<std::ptrdiff_t>(p.fall + 1),
                               [&](double v) { return v >= mid; });
  }
  const Crossings& chosen = *std::max_element(
      pulses.begin(), pulses.end(),
      [](const Crossings& a, const Crossings& b) { return a.at_level < b.at_level; });
  const auto high =
      std::count_if(trace.volts.begin(), trace.volts.end(), [&](double v) { return v >= mid; });
  if (2 * chosen.at_level < high) {
    return refused(
        fmt::format("the contact trace is at its pulse level in more than one stretch: the "
                    "longest pulse holds {} of its {} samples there",
                    chosen.at_level, high));
  }
  const std::size_t i = chosen.rise, j = chosen.fall;
  pulse.rise_s = edge(i);
  pulse.fall_s = edge(j);
  pulse.width_s = {pulse.fall_s.value - pulse.rise_s.value,
                   std::hypot(pulse.rise_s.sigma, pulse.fall_s.sigma)};
  return {true, "", pulse};
}

}  // namespace impactlab
