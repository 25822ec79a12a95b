#include "calibration/displacement.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace impactlab {
namespace {

// How far `volts` lies beyond the calibrated voltages: below (negative side)
// or above, 0 within them.
double BeyondRange(const PhotocellCurve& curve, double volts) {
  if (volts < curve.volts_min()) return curve.volts_min() - volts;
  if (volts > curve.volts_max()) return volts - curve.volts_max();
  return 0.0;
}

double MedianInterval(const std::vector<double>& time_s) {
  std::vector<double> steps;
  for (std::size_t i = 1; i < time_s.size(); ++i) steps.push_back(time_s[i] - time_s[i - 1]);
  if (steps.empty()) return 0.0;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return steps[steps.size() / 2];
}

// The samples of `trace` that belong to stretches far outside the calibrated
// voltages (MisreadLimits), each stretch as its first and last index.
std::vector<std::pair<std::size_t, std::size_t>> MisreadStretches(
    const Trace& trace, const CalibrationResult& calibration, const MisreadLimits& limits) {
  const PhotocellCurve& curve = calibration.curve;
  const std::vector<double>& v = trace.volts;
  const std::size_t n = v.size();
  const double far = limits.far_beyond_span * (curve.volts_max() - curve.volts_min());
  const double max_gap_s = limits.max_gap_intervals * MedianInterval(trace.time_s);
  const auto sigma = [&](std::size_t i) {
    return trace.sigma_volts.empty() ? calibration.residual_rms_volts : trace.sigma_volts[i];
  };
  // How far `volts` lies from the bound the stretch is beyond, on the
  // calibrated side (its distance into the calibrated voltages).
  const auto inward = [&](double volts, bool below) {
    return below ? volts - curve.volts_min() : curve.volts_max() - volts;
  };
  // Grows the stretch from sample `k` on, backwards or forwards in time: over the
  // samples that lead out to it or back, while the line read runs on close in
  // time and without a jump (a step of more than `far`: the reading went
  // back to the trace), and no sample falls back towards the bound by more
  // than 3 sigma from the furthest in reached (the line turns: a crest or a
  // trough of the trace). Returns the last sample taken.
  const auto grow = [&](std::size_t k, bool backwards, bool below) {
    double furthest = inward(v[k], below);
    for (;;) {
      if (backwards ? k == 0 : k + 1 == n) return k;
      const std::size_t j = backwards ? k - 1 : k + 1;
      if (std::abs(trace.time_s[j] - trace.time_s[k]) > max_gap_s) return k;
      if (std::abs(v[j] - v[k]) > far) return k;
      if (inward(v[j], below) < furthest - 3.0 * sigma(j)) return k;
      furthest = std::max(furthest, inward(v[j], below));
      k = j;
    }
  };
  std::vector<std::pair<std::size_t, std::size_t>> stretches;
  std::size_t i = 0;
  while (i < n) {
    if (curve.Covers(v[i])) {
      ++i;
      continue;
    }
    // A run of samples outside on one side, and how far it reaches.
    const bool below = v[i] < curve.volts_min();
    std::size_t last = i;
    double reach = BeyondRange(curve, v[i]);
    while (last + 1 < n && !curve.Covers(v[last + 1]) &&
           (v[last + 1] < curve.volts_min()) == below) {
      ++last;
      reach = std::max(reach, BeyondRange(curve, v[last]));
    }
    if (reach > far) {
      const std::size_t first = grow(i, true, below);
      last = grow(last, false, below);
      if (!stretches.empty() && first <= stretches.back().second) {
        stretches.back().second = std::max(stretches.back().second, last);
      } else {
        stretches.emplace_back(first, last);
      }
    }
    i = last + 1;
  }
  return stretches;
}

// Whether a stretch lies beyond the calibrated voltages on the side of the
// release, X0 (judged by its sample furthest out). The trace begins at the
// release, where a calibration from a smaller swing truly does not reach;
// beyond the other end, X = 0, the bar never is before its first impact, so
// a stretch there that begins the trace is a line followed instead of the
// release's (a pen stroke drawn in from the bezel, a grid line), like any
// other.
bool BeyondRelease(const Trace& trace, const PhotocellCurve& curve,
                   const std::pair<std::size_t, std::size_t>& stretch) {
  std::size_t furthest = stretch.first;
  for (std::size_t i = stretch.first; i <= stretch.second; ++i) {
    if (BeyondRange(curve, trace.volts[i]) > BeyondRange(curve, trace.volts[furthest])) {
      furthest = i;
    }
  }
  const bool release_above = curve.VoltsAt(curve.x_max()) > curve.VoltsAt(0.0);
  return (trace.volts[furthest] > curve.volts_max()) == release_above;
}

// Whether a stretch that begins the trace may be the release beyond the
// calibration: its last sample outside the calibrated volts is at the
// release (t = 0) or after it. Before the release the bar rests at X0 and
// reads the same volts just after it: where a calibration from a smaller
// swing truly does not reach, the samples beyond it run on past the release
// while the bar swings in (slowly: for tens of milliseconds); a stretch
// whose samples beyond all lie before the release, the trace read within
// the calibrated volts from there on, is a line followed in the sweep's part
// before the trigger, not the bar.
bool ReachesRelease(const Trace& trace, const PhotocellCurve& curve,
                    const std::pair<std::size_t, std::size_t>& stretch) {
  for (std::size_t i = stretch.second + 1; i-- > stretch.first;) {
    if (!curve.Covers(trace.volts[i])) return trace.time_s[i] >= 0.0;
  }
  return true;
}

}  // namespace

DisplacementConversion DisplacementFromVolts(const Trace& trace,
                                             const CalibrationResult& calibration,
                                             const MisreadLimits& limits, double run_release_x) {
  DisplacementConversion out;
  if (trace.volts.empty()) {
    out.reason = "the trace has no samples";
    return out;
  }
  const PhotocellCurve& curve = calibration.curve;
  const auto stretches = MisreadStretches(trace, calibration, limits);
  std::vector<bool> misread(trace.volts.size(), false);
  double misread_s = 0.0;
  for (const auto& [first, last] : stretches) {
    std::fill(misread.begin() + first, misread.begin() + last + 1, true);
    out.left_out += last - first + 1;
    out.left_out_s.emplace_back(trace.time_s[first], trace.time_s[last]);
    misread_s += trace.time_s[last] - trace.time_s[first];
  }
  // A run released within its calibration's swing: the samples that begin
  // its trace beyond the release's end of the calibrated volts are its hold
  // at X0, read a little off where they lie near the bound (a bold trace's
  // edge, a grid line or a mark beside it; randomised seeds 3002's and
  // 2029's runs 0.405). No rebound is read there: they are left out
  // uncounted, and a stretch far beyond that begins the trace is left out as
  // any other line followed.
  const bool released_within =
      run_release_x > 0.0 && run_release_x <= (1.0 + limits.release_within) * curve.x_max();
  std::size_t hold = 0;
  if (released_within) {
    while (hold < trace.volts.size() && !curve.Covers(trace.volts[hold]) &&
           BeyondRelease(trace, curve, {hold, hold})) {
      ++hold;
    }
  }
  DisplacementHistory& h = out.history;
  double v_lo = trace.volts.front(), v_hi = trace.volts.front();
  std::size_t outside = 0;
  for (std::size_t i = 0; i < trace.volts.size(); ++i) {
    const double v = trace.volts[i];
    v_lo = std::min(v_lo, v);
    v_hi = std::max(v_hi, v);
    if (!curve.Covers(v)) ++outside;
    if (misread[i]) continue;
    if (i < hold) {
      ++out.hold_beyond;
      continue;
    }
    if (!curve.Covers(v)) {
      ++out.dropped;
      continue;
    }
    const double x = curve.DisplacementFromVolts(v);
    const double sigma_v =
        trace.sigma_volts.empty() ? calibration.residual_rms_volts : trace.sigma_volts[i];
    const double slope = std::abs(curve.SlopeAt(std::clamp(x, 0.0, curve.x_max())));
    h.time_s.push_back(trace.time_s[i]);
    h.displacement.push_back(x);
    h.sigma.push_back(std::hypot(curve.FitDisplacementSigma(v), sigma_v / slope));
  }
  const std::string outside_said = fmt::format(
      "{} of {} samples ({:.4g} .. {:.4g} V) lie outside the calibrated range {:.4g} .. {:.4g} V",
      outside, trace.volts.size(), v_lo, v_hi, curve.volts_min(), curve.volts_max());
  if (out.dropped > trace.volts.size() / 50) {
    out.reason = outside_said + ": the calibration does not cover what this run needs";
    return out;
  }
  const double span_s = trace.time_s.back() - trace.time_s.front();
  // A trace whose own voltages span no more than the calibration's could be
  // the bar's, shifted whole (a zero mistyped): its stretches far outside
  // then cannot be told from that, and none is left out.
  const double calibrated_v = curve.volts_max() - curve.volts_min();
  const bool shifted_whole = v_hi - v_lo <= (1.0 + limits.shift_fits_span) * calibrated_v;
  const bool from_start = !released_within && !stretches.empty() && stretches.front().first == 0 &&
                          BeyondRelease(trace, curve, stretches.front()) &&
                          ReachesRelease(trace, curve, stretches.front());
  if (!stretches.empty() &&
      (from_start || shifted_whole || misread_s > limits.max_span_fraction * span_s)) {
    // Where the trace begins (the release, at X0) a calibration may truly
    // not reach; and a line followed over much of the sweep leaves too
    // little of the bar's own trace to read it by.
    std::string where;
    for (const auto& [from, to] : out.left_out_s) {
      where += fmt::format("{}{:.4g} .. {:.4g} s", where.empty() ? "" : ", ", from, to);
    }
    out.reason = fmt::format(
        "{}, far outside at t = {} ({:.0f} % of the trace{}): the line read there is not the "
        "bar's trace, or the calibration does not cover what this run needs{}",
        outside_said, where, 100.0 * misread_s / span_s, from_start ? ", from its start" : "",
        shifted_whole ? " (its volts span no more than the calibration's: a zero_div mistyped?)"
                      : "");
    return out;
  }
  out.ok = true;
  return out;
}

}  // namespace impactlab
