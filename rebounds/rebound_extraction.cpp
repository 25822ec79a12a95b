#include "rebounds/rebound_extraction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Dense>

namespace impactlab {
namespace {

struct Segment {
  std::size_t first = 0, last = 0;  // samples above the threshold
  bool open_start = false, open_end = false;
};

// Stretches with X above `threshold`; a stretch ends only where X falls to a
// quarter of it, so noise around the threshold does not split a rebound. A
// digitized photo may have no samples at all near an impact (the beam moves
// fast there and is faint): a gap longer than `max_gap_s` with X below half
// a fifth of the stretch's maximum on both sides (near equilibrium, where an
// impact is) also ends a stretch.
std::vector<Segment> FindSegments(const std::vector<double>& t, const std::vector<double>& x,
                                  double threshold, double max_gap_s) {
  std::vector<Segment> segments;
  bool inside = false;
  double stretch_max = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const bool gap = inside && t[i] - t[i - 1] > max_gap_s && x[i - 1] < 0.2 * stretch_max &&
                     x[i] < 0.2 * stretch_max;
    if (gap) inside = false;
    stretch_max = inside ? std::max(stretch_max, x[i]) : x[i];
    if (!inside && x[i] > threshold) {
      segments.push_back({i, i, i == 0, false});
      inside = true;
    } else if (inside && x[i] > 0.25 * threshold) {
      segments.back().last = i;
    } else if (inside) {
      inside = false;
    }
  }
  if (inside) segments.back().open_end = true;
  return segments;
}

// A stretch much longer than a swing holds two rebounds whose impact left no
// sample near equilibrium (a faint part of a photo): split it where its
// samples have the widest gap, or else at its lowest interior sample, until
// every stretch lasts at most 1.3 half periods of its own amplitude.
void SplitMergedRebounds(const std::vector<double>& t, const std::vector<double>& x,
                         const Pendulum& pendulum, std::vector<Segment>& segments) {
  for (std::size_t s = 0; s < segments.size(); ++s) {
    Segment& seg = segments[s];
    if (seg.last <= seg.first + 2) continue;
    const double top = *std::max_element(x.begin() + seg.first, x.begin() + seg.last + 1);
    if (!(top > 0.0) || top >= pendulum.length) continue;
    if (t[seg.last] - t[seg.first] <= 1.3 * HalfPeriod(pendulum, top)) continue;
    // Search the interior, away from the stretch's own flanks.
    const std::size_t lo = seg.first + (seg.last - seg.first) / 10 + 1;
    const std::size_t hi = seg.last - (seg.last - seg.first) / 10 - 1;
    std::size_t cut = lo;
    double widest = 0.0;
    for (std::size_t i = lo; i <= hi; ++i) {
      if (t[i] - t[i - 1] > widest) widest = t[i] - t[i - 1], cut = i;
    }
    const double median_step = (t[seg.last] - t[seg.first]) / (seg.last - seg.first);
    if (widest < 5.0 * median_step) {  // no telling gap: the lowest sample instead
      cut = static_cast<std::size_t>(std::min_element(x.begin() + lo, x.begin() + hi + 1) -
                                     x.begin());
    }
    const Segment second{cut, seg.last, false, seg.open_end};
    seg.last = cut - 1;
    seg.open_end = false;
    segments.insert(segments.begin() + s + 1, second);
    --s;  // the first part may still hold two rebounds
  }
}

// Where a rebound's flank crosses 0. A contact lasts far less than a sample
// interval at slow sweeps, so samples near 0 cannot be told apart between the
// two rebounds meeting there; the flank's own samples between 5 % and 30 % of
// the amplitude are used instead, where asin((X - c)/A) runs linearly in time,
// and that line is extended to X = 0. `step` is +1 for the falling flank after
// the peak, -1 for the rising flank before it.
double FlankCrossing(const DisplacementHistory& h, std::size_t peak, int step, double amplitude,
                     double offset) {
  const auto& x = h.displacement;
  double st = 0, sy = 0, stt = 0, sty = 0;
  int n = 0;
  for (long long k = static_cast<long long>(peak); k >= 0 && k < static_cast<long long>(x.size());
       k += step) {
    const auto i = static_cast<std::size_t>(k);
    const double level = (x[i] - offset) / amplitude;
    if (level < 0.05) break;
    if (level > 0.30) continue;
    const double t = h.time_s[i] - h.time_s[peak], y = std::asin(level);
    st += t, sy += y, stt += t * t, sty += t * y;
    ++n;
  }
  if (n < 2) return std::numeric_limits<double>::quiet_NaN();  // the caller falls back
  const double slope = (n * sty - st * sy) / (n * stt - st * st);
  const double intercept = (sy - slope * st) / n;
  // y = asin(-offset/A) at X = 0.
  return h.time_s[peak] + (std::asin(-offset / amplitude) - intercept) / slope;
}

// The exact pendulum's rebound shape, symmetric about its peak: X at `tau`
// from the peak of a rebound of amplitude `amplitude`.
double PeakShape(const Pendulum& p, double amplitude, double tau) {
  const double half = 0.5 * HalfPeriod(p, amplitude);
  return ReboundDisplacement(p, SpeedFromAmplitude(p, amplitude), half + tau);
}

struct PeakFit {
  Estimate xmax, t_peak;
  double amplitude = 0.0, offset = 0.0;  // X = offset + amplitude-shaped swing
  double rms = 0.0;
};

// Linear start (sinusoid + offset), then Gauss-Newton on the exact shape with
// parameters (amplitude, peak time, offset).
PeakFit FitPeak(const DisplacementHistory& h, const Pendulum& p, std::size_t lo, std::size_t hi,
                std::size_t top) {
  const int n = static_cast<int>(hi - lo + 1);
  Eigen::VectorXd t(n), x(n), w(n);
  for (int k = 0; k < n; ++k) {
    t(k) = h.time_s[lo + k] - h.time_s[top];
    x(k) = h.displacement[lo + k];
    w(k) = h.sigma.empty() ? 1.0 : 1.0 / h.sigma[lo + k];
  }
  const double omega = std::numbers::pi / HalfPeriod(p, std::max(h.displacement[top], 1e-300));
  Eigen::MatrixXd a(n, 3);
  for (int k = 0; k < n; ++k) {
    a.row(k) << std::cos(omega * t(k)), std::sin(omega * t(k)), 1.0;
  }
  const Eigen::Vector3d lin = (w.asDiagonal() * a).colPivHouseholderQr().solve(w.cwiseProduct(x));
  Eigen::Vector3d q(std::hypot(lin(0), lin(1)), std::atan2(lin(1), lin(0)) / omega, lin(2));

  Eigen::MatrixXd jac(n, 3);
  Eigen::VectorXd r(n);
  const auto residuals = [&](const Eigen::Vector3d& params, Eigen::VectorXd& out) {
    for (int k = 0; k < n; ++k) {
      out(k) = w(k) * (params(2) + PeakShape(p, params(0), t(k) - params(1)) - x(k));
    }
  };
  for (int iteration = 0; iteration < 8; ++iteration) {
    residuals(q, r);
    for (int j = 0; j < 3; ++j) {
      const double step = j == 0 ? 1e-7 * q(0) : (j == 1 ? 1e-7 / omega : 1e-7 * q(0));
      Eigen::Vector3d up = q, down = q;
      up(j) += step;
      down(j) -= step;
      Eigen::VectorXd ru(n), rd(n);
      residuals(up, ru);
      residuals(down, rd);
      jac.col(j) = (ru - rd) / (2.0 * step);
    }
    const Eigen::Vector3d delta = jac.colPivHouseholderQr().solve(-r);
    q += delta;
    if (std::abs(delta(0)) < 1e-13 * q(0) && std::abs(delta(1)) * omega < 1e-13) break;
  }
  residuals(q, r);
  const double dof = std::max(1, n - 3);
  const double scatter = r.squaredNorm() / dof;
  const Eigen::Matrix3d cov = scatter * (jac.transpose() * jac).inverse();

  PeakFit fit;
  // X max = amplitude + offset.
  fit.xmax = {q(0) + q(2), std::sqrt(std::max(0.0, cov(0, 0) + cov(2, 2) + 2.0 * cov(0, 2)))};
  fit.t_peak = {h.time_s[top] + q(1), std::sqrt(std::max(0.0, cov(1, 1)))};
  fit.amplitude = q(0);
  fit.offset = q(2);
  double rss = 0.0;
  for (int k = 0; k < n; ++k) rss += std::pow(q(2) + PeakShape(p, q(0), t(k) - q(1)) - x(k), 2);
  fit.rms = std::sqrt(rss / n);
  return fit;
}

}  // namespace

bool ReboundExtractionOptions::Check(std::string* error) const {
  if (!(threshold_fraction > 0.0 && threshold_fraction < 0.5) ||
      !(peak_window_fraction > 0.0 && peak_window_fraction <= 0.5) || min_samples_per_peak < 4) {
    *error =
        "threshold_fraction must be in (0, 0.5), peak_window_fraction in (0, 0.5] and "
        "min_samples_per_peak >= 4";
    return false;
  }
  return true;
}

ReboundExtraction ExtractRebounds(const DisplacementHistory& h, const Pendulum& pendulum,
                                  const ReboundExtractionOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw std::invalid_argument(error);
  if (h.time_s.size() != h.displacement.size() || h.time_s.size() < 16) {
    throw std::invalid_argument("a displacement history needs at least 16 samples");
  }
  const double largest = *std::max_element(h.displacement.begin(), h.displacement.end());
  if (!(largest > 0.0)) throw std::invalid_argument("the displacement history never leaves 0");
  // A gap of 2 % of a swing cannot hide a rebound's peak, but can hide an impact.
  const double max_gap_s = 0.02 * HalfPeriod(pendulum, largest);
  std::vector<Segment> segments =
      FindSegments(h.time_s, h.displacement, options.threshold_fraction * largest, max_gap_s);
  SplitMergedRebounds(h.time_s, h.displacement, pendulum, segments);

  ReboundExtraction out;
  // Where a flank crosses 0, or the model's half period from the peak when the
  // flank has too few samples to say.
  const auto crossing = [&](std::size_t top, int step, double amplitude, double offset,
                            double t_peak) {
    const double t = FlankCrossing(h, top, step, amplitude, offset);
    return std::isfinite(t) ? t : t_peak + step * 0.5 * HalfPeriod(pendulum, amplitude);
  };
  const auto top_of = [&](const Segment& seg) {
    return static_cast<std::size_t>(std::max_element(h.displacement.begin() + seg.first,
                                                     h.displacement.begin() + seg.last + 1) -
                                    h.displacement.begin());
  };
  // Segment 0 is the release swing (its peak is the release itself); every
  // later complete segment is a rebound.
  if (!segments.empty()) {
    const std::size_t top = top_of(segments[0]);
    out.impact_times.push_back(crossing(top, +1, h.displacement[top], 0.0, h.time_s[top]));
  }
  for (std::size_t s = 1; s < segments.size(); ++s) {
    const Segment& seg = segments[s];
    if (seg.open_end) break;
    const std::size_t top = top_of(seg);
    const double expected_duration = HalfPeriod(pendulum, h.displacement[top]);
    const double half_window = options.peak_window_fraction * expected_duration;
    std::size_t lo = top, hi = top;
    while (lo > seg.first && h.time_s[top] - h.time_s[lo - 1] <= half_window) --lo;
    while (hi < seg.last && h.time_s[hi + 1] - h.time_s[top] <= half_window) ++hi;
    ExtractedRebound rebound;
    rebound.number = static_cast<int>(s);
    rebound.samples_in_fit = static_cast<int>(hi - lo + 1);
    if (rebound.samples_in_fit < options.min_samples_per_peak) {
      throw std::invalid_argument(
          fmt::format("rebound {} has only {} samples near its peak (at least {} are needed)", s,
                      rebound.samples_in_fit, options.min_samples_per_peak));
    }
    const PeakFit fit = FitPeak(h, pendulum, lo, hi, top);
    rebound.xmax = fit.xmax;
    rebound.t_peak = fit.t_peak;
    rebound.fit_rms = fit.rms;
    rebound.start_s = crossing(top, -1, fit.amplitude, fit.offset, fit.t_peak.value);
    rebound.end_s = crossing(top, +1, fit.amplitude, fit.offset, fit.t_peak.value);
    const double dt = h.time_s[top + 1] - h.time_s[top];
    rebound.duration = {rebound.end_s - rebound.start_s, dt / std::sqrt(6.0)};
    out.rebounds.push_back(rebound);
    out.impact_times.push_back(rebound.end_s);
  }
  return out;
}

namespace {

// x of history h at time t by linear interpolation, if t lies between two of
// its samples no further apart than `max_span_s` (never across a gap).
std::optional<std::pair<double, double>> Interpolate(const DisplacementHistory& h, double t,
                                                     double max_span_s) {
  const auto it = std::lower_bound(h.time_s.begin(), h.time_s.end(), t);
  if (it == h.time_s.end()) return std::nullopt;
  const auto k = static_cast<std::size_t>(it - h.time_s.begin());
  const double sigma_k = h.sigma.empty() ? 0.0 : h.sigma[k];
  if (*it == t) return std::pair{h.displacement[k], sigma_k};
  if (k == 0 || h.time_s[k] - h.time_s[k - 1] > max_span_s) return std::nullopt;
  const double f = (t - h.time_s[k - 1]) / (h.time_s[k] - h.time_s[k - 1]);
  const double sigma = h.sigma.empty() ? 0.0 : std::max(h.sigma[k - 1], sigma_k);
  return std::pair{h.displacement[k - 1] + f * (h.displacement[k] - h.displacement[k - 1]), sigma};
}

double MedianStep(const std::vector<double>& t) {
  std::vector<double> steps;
  for (std::size_t i = 1; i < t.size(); ++i) steps.push_back(t[i] - t[i - 1]);
  if (steps.empty()) return 0.0;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return steps[steps.size() / 2];
}

}  // namespace

DisplacementHistory AverageHistories(const DisplacementHistory& a, const DisplacementHistory& b) {
  // On the union of both sample times: where one bar's trace has a gap (a
  // digitized photo may), the other still counts wherever both can be read.
  std::vector<double> times = a.time_s;
  times.insert(times.end(), b.time_s.begin(), b.time_s.end());
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  const double span_a = 4.0 * MedianStep(a.time_s), span_b = 4.0 * MedianStep(b.time_s);
  DisplacementHistory out;
  for (double t : times) {
    const auto xa = Interpolate(a, t, span_a), xb = Interpolate(b, t, span_b);
    if (!xa || !xb) continue;
    out.time_s.push_back(t);
    out.displacement.push_back(0.5 * (xa->first + xb->first));
    if (!a.sigma.empty() && !b.sigma.empty())
      out.sigma.push_back(0.5 * std::hypot(xa->second, xb->second));
  }
  return out;
}

ContactPulse MeasureContactPulse(const Trace& trace) {
  const std::size_t n = trace.volts.size();
  if (n < 8) throw std::invalid_argument("a contact trace needs at least 8 samples");
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
  std::nth_element(low_state.begin(), low_state.begin() + low_state.size() / 2, low_state.end());
  const double noise = 1.4826 * low_state[low_state.size() / 2];
  if (!(pulse.high_volts - pulse.low_volts > 6.0 * noise) || pulse.high_volts == pulse.low_volts) {
    throw std::invalid_argument("the contact trace shows no step above its noise");
  }

  // Crossing of `mid` between samples i and i + 1, with its uncertainty: the
  // noise over the slope, or, for an edge within one sample, the sample
  // interval's uniform spread.
  const auto edge = [&](std::size_t i) {
    const double t0 = trace.time_s[i], t1 = trace.time_s[i + 1];
    const double v0 = trace.volts[i], v1 = trace.volts[i + 1];
    const double t = t0 + (t1 - t0) * (mid - v0) / (v1 - v0);
    const double slope = std::abs(v1 - v0) / (t1 - t0);
    const double resolved_sigma = noise / slope;
    const bool one_sample_jump = std::min(v0, v1) < pulse.low_volts + 3.0 * noise &&
                                 std::max(v0, v1) > pulse.high_volts - 3.0 * noise;
    return Estimate{t, one_sample_jump ? (t1 - t0) / std::sqrt(12.0) : resolved_sigma};
  };
  std::size_t i = 0;
  while (i + 1 < n && !(trace.volts[i] < mid && trace.volts[i + 1] >= mid)) ++i;
  if (i + 1 >= n) throw std::invalid_argument("the contact trace has no rising edge");
  pulse.rise_s = edge(i);
  std::size_t j = i + 1;
  while (j + 1 < n && !(trace.volts[j] >= mid && trace.volts[j + 1] < mid)) ++j;
  if (j + 1 >= n) throw std::invalid_argument("the contact pulse does not end within the trace");
  pulse.fall_s = edge(j);
  pulse.width_s = {pulse.fall_s.value - pulse.rise_s.value,
                   std::hypot(pulse.rise_s.sigma, pulse.fall_s.sigma)};
  return pulse;
}

}  // namespace impactlab
