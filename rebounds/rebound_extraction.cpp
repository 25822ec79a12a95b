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

#include "model/estimate.h"

namespace impactlab {
namespace {

// Where a rebound's flank crosses X = 0, with its standard error. A contact
// lasts far less than a sample interval at slow sweeps, and a digitized
// trace often loses the last tens of milliseconds before and after an
// impact (the two bars' traces meet there), so the crossing is read from
// the flank above: its samples between 5 % and 50 % of the amplitude (none
// there: all up to 95 %), each giving the crossing through the swing's sine
// at the pendulum's own frequency, X = A sin(w (t - t0)), weighted by its
// timing precision (the flank's slope there, cos^2 of its phase). The
// frequency is the pendulum's, not fitted: a straight line in phase through
// a few samples, extended over the gap, multiplied every sample's error by
// the lever and read durations 2.25 ms (0.3 % of a half swing) off where
// this reads 0.95 ms (medians, the external sessions' 175 rebounds); the
// samples nearest X = 0 carry most of the weight, so a swing whose period
// differs from the pendulum's is still read as it is.
// Its standard error: each sample's X error over the flank's speed A w,
// at the larger of the peak fit's scatter and the flank's own, widened for
// the residuals' correlation along the trace, and the fitted amplitude's
// error carried through each sample's phase (the cell curve's error at
// X = 0, shared by both crossings, is added by AddCurveSigma). Only samples
// from the peak outwards, no further than half a swing, are read, so the
// neighbouring rebound's are never taken for this one's.
struct Crossing {
  double time = std::numeric_limits<double>::quiet_NaN();
  double sigma = 0.0;
};
Crossing FlankCrossing(const DisplacementHistory& h, std::size_t peak, double t_peak, int step,
                       double amplitude, double offset, double half_period, double sample_sigma,
                       double amplitude_sigma) {
  const auto& x = h.displacement;
  const double omega = std::numbers::pi / half_period;
  std::vector<double> all_time, all_weight, all_tan, low_time, low_weight, low_tan;
  for (long long k = static_cast<long long>(peak); k >= 0 && k < static_cast<long long>(x.size());
       k += step) {
    const auto i = static_cast<std::size_t>(k);
    if (std::abs(h.time_s[i] - t_peak) > 0.5 * half_period) break;
    const double level = (x[i] - offset) / amplitude;
    if (level < 0.05) break;
    if (level > 0.95) continue;
    // The sample's phase above X = 0, not above the peak fit's centre line:
    // the offset c is fitted with the swing's shape at the pendulum's
    // frequency, and crossing c returns that shape's crossing, not the
    // data's (a trace on a time axis 2 % long read the model's durations to
    // 0.05 %; crossing X = 0 reads 2.3 % longer).
    // A sample at or beyond the amplitude (a fit whose offset is well below
    // zero) has no phase on the swing: it says nothing of when the flank
    // crosses, and its weight cos^2(pi/2) ~ 1e-33 would state that crossing's
    // error as 1e13 s where it is the only one.
    if (std::abs(x[i]) >= 0.99 * amplitude) continue;
    const double phase = std::asin(x[i] / amplitude);
    const double weight = std::cos(phase) * std::cos(phase);
    all_time.push_back(h.time_s[i] + step * phase / omega);
    all_weight.push_back(weight);
    all_tan.push_back(std::tan(phase));
    if (level > 0.50) continue;
    low_time.push_back(all_time.back());
    low_weight.push_back(weight);
    low_tan.push_back(all_tan.back());
  }
  const std::vector<double>& time = low_time.empty() ? all_time : low_time;
  const std::vector<double>& weight = low_time.empty() ? all_weight : low_weight;
  const std::vector<double>& tan = low_time.empty() ? all_tan : low_tan;
  if (time.empty()) return {};
  double sum_w = 0.0, sum_wt = 0.0, sum_w_tan = 0.0;
  for (std::size_t k = 0; k < time.size(); ++k) {
    sum_w += weight[k], sum_wt += weight[k] * time[k], sum_w_tan += weight[k] * tan[k];
  }
  const double crossing = sum_wt / sum_w;
  const double speed = amplitude * omega;  // the flank's speed at X = 0
  // Each sample's miss in X (its crossing's miss times its own speed).
  std::vector<double> miss;
  double miss2 = 0.0;
  for (std::size_t k = 0; k < time.size(); ++k) {
    miss.push_back((time[k] - crossing) * speed * std::sqrt(weight[k]));
    miss2 += miss.back() * miss.back();
  }
  double scatter2 = sample_sigma * sample_sigma;
  double inflation = 1.0;
  if (miss.size() >= 3) {
    scatter2 = std::max(scatter2, miss2 / static_cast<double>(miss.size() - 1));
    inflation = CorrelationInflation(miss);
  }
  // The amplitude's own error moves every sample's phase together, by
  // tan(phase) dA / A: it is no scatter and averages out of nothing.
  const double from_amplitude = amplitude_sigma * sum_w_tan / sum_w / speed;
  return {crossing, std::hypot(std::sqrt(inflation * scatter2 / sum_w) / speed, from_amplitude)};
}

// The exact pendulum's rebound shape, symmetric about its peak: X at `tau`
// from the peak of a rebound of amplitude `amplitude`. What depends on the
// amplitude alone (a complete elliptic integral, the exit speed) is worked
// out once, not once a sample: a peak fit evaluates the shape thousands of
// times at a few amplitudes.
class PeakShape {
 public:
  PeakShape(const Pendulum& p, double amplitude)
      : pendulum_(p),
        half_(0.5 * HalfPeriod(p, amplitude)),
        speed_(SpeedFromAmplitude(p, amplitude)) {}

  // X and dX/dtau.
  SwingState At(double tau) const { return ReboundState(pendulum_, speed_, half_ + tau); }

 private:
  const Pendulum& pendulum_;
  double half_, speed_;
};

// The longest lag, in samples, at which a peak fit's errors' autocovariance
// is estimated (a quarter of the window where that is less): a digitized
// trace's errors decorrelate within a few samples of blur, and every lag
// more costs the estimate precision.
constexpr int kPeakFitMaxLag = 20;

struct PeakFit {
  Estimate xmax, t_peak;
  double amplitude = 0.0, offset = 0.0;  // X = offset + amplitude-shaped swing
  double rms = 0.0;
};

// Linear start (sinusoid + offset), then Gauss-Newton on the exact shape with
// parameters (amplitude, peak time, offset).
PeakFit FitPeak(const DisplacementHistory& h, const Pendulum& p, std::size_t lo, std::size_t hi,
                std::size_t top, double amplitude_guess) {
  const int n = static_cast<int>(hi - lo + 1);
  Eigen::VectorXd t(n), x(n), w(n);
  for (int k = 0; k < n; ++k) {
    t(k) = h.time_s[lo + k] - h.time_s[top];
    x(k) = h.displacement[lo + k];
    w(k) = h.sigma.empty() ? 1.0 : 1.0 / h.sigma[lo + k];
  }
  const double omega = std::numbers::pi / HalfPeriod(p, amplitude_guess);
  Eigen::MatrixXd a(n, 3);
  for (int k = 0; k < n; ++k) {
    a.row(k) << std::cos(omega * t(k)), std::sin(omega * t(k)), 1.0;
  }
  const Eigen::Vector3d lin = (w.asDiagonal() * a).colPivHouseholderQr().solve(w.cwiseProduct(x));
  Eigen::Vector3d q(std::hypot(lin(0), lin(1)), std::atan2(lin(1), lin(0)) / omega, lin(2));

  // Gauss-Newton. The Jacobian: the peak time's column from the shape's
  // slope, the offset's from the weights (it enters linearly), the
  // amplitude's by a forward difference. Two shape evaluations a sample an
  // iteration; the difference's error (~1e-7 of the column) slows convergence
  // and moves the solution far less than its uncertainty. The steps stall at
  // about 1e-11 of the amplitude (the shape's own rounding through the
  // difference), so the fit stops at 1e-10: five orders below any peak's
  // uncertainty, and three iterations instead of eight.
  Eigen::MatrixXd jac(n, 3);
  Eigen::VectorXd r(n), r_up(n);
  const auto residuals = [&](const Eigen::Vector3d& params, Eigen::VectorXd& out,
                             Eigen::MatrixXd* jacobian) {
    const PeakShape shape(p, params(0));
    for (int k = 0; k < n; ++k) {
      const SwingState state = shape.At(t(k) - params(1));
      out(k) = w(k) * (params(2) + state.displacement - x(k));
      if (jacobian) (*jacobian)(k, 1) = -w(k) * state.velocity;
    }
  };
  for (int iteration = 0; iteration < 8; ++iteration) {
    residuals(q, r, &jac);
    const double step = 1e-7 * q(0);
    residuals(q + Eigen::Vector3d(step, 0.0, 0.0), r_up, nullptr);
    jac.col(0) = (r_up - r) / step;
    jac.col(2) = w;
    const Eigen::Vector3d delta = jac.colPivHouseholderQr().solve(-r);
    q += delta;
    if (std::abs(delta(0)) < 1e-10 * q(0) && std::abs(delta(1)) * omega < 1e-10) break;
  }
  residuals(q, r, nullptr);
  const double dof = std::max(1, n - 3);
  const double scatter = r.squaredNorm() / dof;
  // The residuals err together over neighbouring samples (a digitized
  // trace's blur and dashes, a scope's runs of equal codes): the fit holds
  // fewer independent readings than samples.
  const double inflation = CorrelationInflation({r.data(), static_cast<std::size_t>(n)});
  const Eigen::Matrix3d normal_inverse = (jac.transpose() * jac).inverse();
  const Eigen::Matrix3d cov = inflation * scatter * normal_inverse;
  // But the fit follows part of the errors' slow wander, so its residuals'
  // correlation falls off early and the inflation is short. The errors'
  // autocovariance, with the fit's absorption undone, gives the maximum's
  // and the peak time's variance through their weights on the samples; the
  // larger of the two estimates is kept, since a short window tells a long
  // correlation only in part.
  const std::vector<double> autocovariance = FitErrorAutocovariance(
      {r.data(), static_cast<std::size_t>(n)}, {jac.data(), static_cast<std::size_t>(jac.size())},
      3, std::min(n / 4, kPeakFitMaxLag));
  const auto variance_of = [&](const Eigen::Vector3d& gradient) {
    const double linear = gradient.dot(cov * gradient);
    if (autocovariance.empty()) return std::max(0.0, linear);
    const Eigen::VectorXd weights = jac * (normal_inverse * gradient);
    return std::max(linear,
                    CorrelatedVariance(autocovariance,
                                       {weights.data(), static_cast<std::size_t>(weights.size())}));
  };

  PeakFit fit;
  // X max = amplitude + offset.
  fit.xmax = {q(0) + q(2), std::sqrt(variance_of({1.0, 0.0, 1.0}))};
  fit.t_peak = {h.time_s[top] + q(1), std::sqrt(variance_of({0.0, 1.0, 0.0}))};
  fit.amplitude = q(0);
  fit.offset = q(2);
  // The unweighted residuals, from the weighted ones at the solution.
  fit.rms = std::sqrt(r.cwiseQuotient(w).squaredNorm() / n);
  return fit;
}

}  // namespace

bool TraceSpanLimits::Check(std::string* error) const {
  if (!(max_half_swings >= 1.0 && max_half_swings <= 1e7) ||
      !(max_samples >= 1.0 && max_samples <= 1e10) ||
      !(min_samples_per_half_swing >= 0.0 && min_samples_per_half_swing <= 1e6)) {
    *error =
        "max_half_swings must be in [1, 1e7], max_samples in [1, 1e10] and "
        "min_samples_per_half_swing in [0, 1e6]";
    return false;
  }
  return true;
}

std::string TraceSpanProblem(double span_s, double sample_interval_s, std::size_t samples,
                             const Pendulum& pendulum, const TraceSpanLimits& limits) {
  if (!std::isfinite(span_s) || span_s < 0.0) {
    return fmt::format("the trace spans {} s, not a finite time", span_s);
  }
  const double half_swing = HalfPeriod(pendulum, 0.0);
  const double half_swings = span_s / half_swing;
  if (!(half_swings <= limits.max_half_swings)) {
    return fmt::format(
        "the trace spans {:.4g} s, which is {:.4g} swings out and back of this pendulum ({:.4g} s "
        "each); at most {:.4g} are expected (a wrong time unit or time_per_div?)",
        span_s, half_swings, half_swing, limits.max_half_swings);
  }
  if (sample_interval_s > 0.0 && !(span_s / sample_interval_s <= limits.max_samples)) {
    return fmt::format(
        "the trace spans {:.4g} s at {:.4g} s a sample, which would need {:.4g} samples, more "
        "than the limit {:.4g}",
        span_s, sample_interval_s, span_s / sample_interval_s, limits.max_samples);
  }
  if (samples > 0 && half_swings >= 1.0 &&
      static_cast<double>(samples) < limits.min_samples_per_half_swing * half_swings) {
    return fmt::format(
        "the trace's {} samples over {:.4g} s ({:.4g} swings out and back of this pendulum) "
        "leave {:.3g} a swing; a rebound needs at least {:.4g} (too coarse a resolution, or a "
        "wrong time unit or time_per_div?)",
        samples, span_s, half_swings, static_cast<double>(samples) / half_swings,
        limits.min_samples_per_half_swing);
  }
  return {};
}

bool ReboundExtractionOptions::Check(std::string* error) const {
  if (!limits.Check(error)) return false;
  if (!(threshold_fraction > 0.0 && threshold_fraction < 0.5) ||
      !(peak_window_fraction > 0.0 && peak_window_fraction <= 0.5) || min_samples_per_peak < 4) {
    *error =
        "threshold_fraction must be in (0, 0.5), peak_window_fraction in (0, 0.5] and "
        "min_samples_per_peak >= 4";
    return false;
  }
  return true;
}

namespace {

std::size_t NearestSample(const std::vector<double>& t, double at) {
  const auto it = std::lower_bound(t.begin(), t.end(), at);
  if (it == t.end()) return t.size() - 1;
  const auto k = static_cast<std::size_t>(it - t.begin());
  return k > 0 && at - t[k - 1] < t[k] - at ? k - 1 : k;
}

double MedianSpacing(const std::vector<double>& t, std::size_t lo, std::size_t end) {
  std::vector<double> steps;
  for (std::size_t i = lo + 1; i < end; ++i) steps.push_back(t[i] - t[i - 1]);
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return steps[steps.size() / 2];
}

// A step longer than this fraction of a half swing is a gap in the trace,
// across which the fall is checked for the impact it may hide.
constexpr double kLongStepOfHalfSwing = 0.05;

// Whether the history, falling from `top` to sample `last` (by more than 5 %
// of the top), falls across the gap to sample `next` at less than half its
// average speed so far. A falling bar only speeds up until it meets the
// other; a sample past a gap that is reached so slowly lies beyond the
// impact the gap hides, on the next rebound's rise (randomised seed 1034's run 0.405: the right
// trace's fall read from 72 % of X0 down to 41 %, 0.23 s of gap over the impact, then 32 % on the
// rise, which the release's fit took for the fall's end, and X0 came out half its size).
bool SlowsAcross(const DisplacementHistory& h, std::size_t top, std::size_t last,
                 std::size_t next) {
  const auto& x = h.displacement;
  const auto& t = h.time_s;
  const double so_far = (x[top] - x[last]) / (t[last] - t[top]);
  const double across = (x[last] - x[next]) / (t[next] - t[last]);
  // Only once the fall has begun beyond a reading's noise (a hold's
  // samples scatter about X0 with no speed to compare).
  return x[top] - x[last] > 0.05 * x[top] && across < 0.5 * so_far;
}

// How well the release's time is known, as a share of a half period: the
// magnet lets go within about a millisecond, and a photo's time origin
// (t0_div) is read through the graticule's mapping to a tenth of a pixel, a
// millisecond or so on a slow sweep (0.2 % of the thesis pendulum's 0.75 s
// half period is 1.5 ms). Over some 400 bars of randomised seeds
// 1001-4034 and eight of 5001-6034, a free phase read X0 with a median
// error of 0.33 % of X0, 35 bars more than 3 % off, pull RMS 2.86; this
// prior, 0.27 %, 21 and 1.53 (a prior of 1 % of the half period: 0.32 %, 28; 0.5 %: 0.31 %, 26,
// 2.11; the phase held at t = 0: 0.18 %, 13, but 17 bars read worse by
// more than 0.3 % of X0, a misread fall forced through t = 0).
constexpr double kReleaseTimeShare = 0.002;

// The release swing: the bar, held at X0, is let go at t_release and falls
// as X0 cos(w (t - t_release)) to the first impact a half period later.
struct ReleaseSwing {
  double amplitude = 0.0;         // X0 as the history shows it
  double amplitude_sigma = 0.0;   // its standard error from the fall's fit (0: not fitted)
  double t_release = 0.0;         // s
  std::size_t first_falling = 0;  // the first sample after t_release
};

// From the samples falling from the history's first stretch above the
// threshold: its top, then on while X keeps falling (a rise of 5 % of the
// top means the next rebound has begun, even where a gap hides the impact).
// A digitized photo may miss the hold at X0 and the top of the fall, so the
// fall's shape, not its largest sample, gives X0 and the release time: a
// linear fit of a cos(w t) + b sin(w t) to the samples between 40 % and 98 %
// of the top (below 40 % the next rebound's rise could hide in a gap; above
// 98 % lies the hold), no later than a half period after the hold.
ReleaseSwing FindReleaseSwing(const DisplacementHistory& h, const Pendulum& pendulum,
                              double threshold) {
  const auto& x = h.displacement;
  const auto& t = h.time_s;
  std::size_t top = 0;
  while (top < x.size() && x[top] <= threshold) ++top;
  top = std::min(top, x.size() - 1);
  std::size_t end = top;
  const double long_step = kLongStepOfHalfSwing * HalfPeriod(pendulum, x[top]);
  for (double lowest = x[top]; end < x.size() && x[end] > 0.25 * threshold; ++end) {
    if (x[end] > x[top] && lowest >= 0.95 * x[top]) top = end, lowest = x[end];
    if (x[end] > lowest + 0.05 * x[top]) break;
    if (end > top + 1 && t[end] - t[end - 1] > long_step && SlowsAcross(h, top, end - 1, end)) {
      break;
    }
    lowest = std::min(lowest, x[end]);
  }
  // The fall lasts a half period from the release, which is no earlier than
  // the last sample of the hold.
  std::size_t last_hold = top;
  for (std::size_t i = top; i < end; ++i) {
    if (x[i] >= 0.98 * x[top]) last_hold = i;
  }
  const double fall_ends = t[last_hold] + 0.5 * HalfPeriod(pendulum, x[top]);
  std::vector<std::size_t> fall;
  for (std::size_t i = top; i < end && t[i] <= fall_ends; ++i) {
    if (x[i] >= 0.4 * x[top] && x[i] <= 0.98 * x[top]) fall.push_back(i);
  }
  ReleaseSwing swing;
  swing.amplitude = x[top];
  swing.t_release = t[top];
  // A stray sample (the next rebound's, past a gap) misses the fitted fall
  // by far more than the others: it is dropped and the fall fitted again.
  for (int pass = 0; pass < 3 && fall.size() >= 3; ++pass) {
    const double omega = std::numbers::pi / HalfPeriod(pendulum, swing.amplitude);
    const auto basis = [&](std::size_t i) {
      return Eigen::Vector2d(std::cos(omega * (t[i] - t[top])), std::sin(omega * (t[i] - t[top])));
    };
    Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
    Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
    for (const std::size_t i : fall) {
      normal += basis(i) * basis(i).transpose();
      rhs += x[i] * basis(i);
    }
    Eigen::Vector2d ab = normal.ldlt().solve(rhs);
    // The release is at t = 0, the traces' time origin (the session's
    // contract: the sweep starts at the release), to within the magnet's
    // letting go and the origin's reading, kReleaseTimeShare of a half
    // period: a prior on the fall's phase, which holds the fit where the
    // trace shows only a short arc of the fall (its hold and the fall's
    // start lost), whose amplitude and phase the arc alone hardly tell
    // apart. Linearised about the phase at t = 0, it adds to the normal
    // equations the information on (a, b) across that direction.
    if (const double free_amplitude = std::hypot(ab(0), ab(1));
        fall.size() > 2 && free_amplitude > 0.0) {
      double rss = 0.0;
      for (const std::size_t i : fall) rss += std::pow(x[i] - basis(i).dot(ab), 2);
      const double scatter = rss / static_cast<double>(fall.size() - 2);
      const double phase_at_zero = -omega * t[top];
      const Eigen::Vector2d across(-std::sin(phase_at_zero), std::cos(phase_at_zero));
      const double phase_sigma = omega * kReleaseTimeShare * HalfPeriod(pendulum, free_amplitude);
      normal += scatter / std::pow(free_amplitude * phase_sigma, 2) * across * across.transpose();
      ab = normal.ldlt().solve(rhs);
    }
    const double amplitude = std::hypot(ab(0), ab(1));
    if (!(amplitude > 0.0) || ab(0) <= 0.0) break;  // no fall to fit: the top is the release
    swing.amplitude = amplitude;
    swing.t_release = t[top] + std::atan2(ab(1), ab(0)) / omega;
    std::vector<double> misses;
    for (const std::size_t i : fall) misses.push_back(std::abs(x[i] - basis(i).dot(ab)));
    std::vector<double> sorted = misses;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double limit = std::max(6.0 * 1.4826 * sorted[sorted.size() / 2], 1e-3 * amplitude);
    std::vector<std::size_t> kept;
    for (std::size_t k = 0; k < fall.size(); ++k) {
      if (misses[k] <= limit) kept.push_back(fall[k]);
    }
    if (kept.size() == fall.size()) {
      // The amplitude's standard error: the fit's covariance at the
      // residuals' scatter (inflated for their correlation along the trace),
      // carried through amplitude = |(a, b)|.
      if (fall.size() > 2) {
        std::vector<double> residual;
        for (const std::size_t i : fall) residual.push_back(x[i] - basis(i).dot(ab));
        double rr = 0.0;
        for (double r : residual) rr += r * r;
        const double scatter = rr / static_cast<double>(fall.size() - 2);
        const Eigen::Matrix2d cov = CorrelationInflation(residual) * scatter * normal.inverse();
        const Eigen::Vector2d gradient = ab / amplitude;
        double variance = gradient.dot(cov * gradient);
        // As a peak's (FitPeak): the fit follows part of the errors' slow
        // wander, so its residuals' correlation falls off early; the errors'
        // autocovariance, the fit's absorption undone, gives the amplitude's
        // variance through its weights on the samples, and the larger of
        // the two estimates is kept.
        const std::size_t m = fall.size();
        std::vector<double> jacobian(2 * m);
        for (std::size_t k = 0; k < m; ++k) {
          const Eigen::Vector2d row = basis(fall[k]);
          jacobian[k] = row(0);
          jacobian[m + k] = row(1);
        }
        const std::vector<double> autocovariance = FitErrorAutocovariance(
            residual, jacobian, 2, std::min(static_cast<int>(m) / 4, kPeakFitMaxLag));
        if (!autocovariance.empty()) {
          const Eigen::Vector2d through = normal.inverse() * gradient;
          std::vector<double> weights(m);
          for (std::size_t k = 0; k < m; ++k) weights[k] = basis(fall[k]).dot(through);
          variance = std::max(variance, CorrelatedVariance(autocovariance, weights));
        }
        swing.amplitude_sigma = std::sqrt(std::max(0.0, variance));
      }
      break;
    }
    fall = std::move(kept);
  }
  swing.first_falling =
      static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), swing.t_release) - t.begin());
  swing.first_falling = std::min(swing.first_falling, x.size() - 1);
  return swing;
}

// When the history first rises above `threshold`, s.
double FirstAbove(const DisplacementHistory& h, double threshold) {
  for (std::size_t i = 0; i < h.displacement.size(); ++i) {
    if (h.displacement[i] > threshold) return h.time_s[i];
  }
  return h.time_s.back();
}

// Samples of the history within [from, to] s.
std::pair<std::size_t, std::size_t> SamplesWithin(const DisplacementHistory& h, double from,
                                                  double to) {
  const auto lo = std::lower_bound(h.time_s.begin(), h.time_s.end(), from);
  const auto hi = std::upper_bound(h.time_s.begin(), h.time_s.end(), to);
  return {static_cast<std::size_t>(lo - h.time_s.begin()),
          static_cast<std::size_t>(hi - h.time_s.begin())};
}

}  // namespace

ReboundExtraction ExtractRebounds(const DisplacementHistory& h, const Pendulum& pendulum,
                                  const ReboundExtractionOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw std::invalid_argument(error);
  ReboundExtraction out;
  const auto refused = [&](std::string reason) {
    out.reason = std::move(reason);
    return out;
  };
  if (h.time_s.size() != h.displacement.size() || h.time_s.size() < kMinHistorySamples) {
    return refused(
        fmt::format("a displacement history needs at least {} samples", kMinHistorySamples));
  }
  const double largest = *std::max_element(h.displacement.begin(), h.displacement.end());
  if (!(largest > 0.0)) return refused("the displacement history never leaves 0");
  const double threshold = options.threshold_fraction * largest;
  // The walk below takes a step of at least a part of a half swing per
  // rebound: the span, bounded here, bounds its steps and the impacts kept.
  const double span = h.time_s.back() - h.time_s.front();
  if (std::string problem = TraceSpanProblem(span, MedianSpacing(h.time_s, 0, h.time_s.size()), 0,
                                             pendulum, options.limits);
      !problem.empty()) {
    return refused(std::move(problem));
  }
  // A step is a half swing or a measured rebound, whose peak lies at least
  // 0.05 of a half swing past its impact: the walk ends within span /
  // min_step steps whatever the rounding.
  const double min_step = 0.05 * HalfPeriod(pendulum, 0.0);
  const auto max_steps = static_cast<long long>(std::ceil(span / min_step)) + 16;

  // The bars meet at the equilibrium position once every half period of the
  // pendulum (a contact lasts microseconds), so each rebound is the stretch
  // between one impact and the next, about a half period later. Walking the
  // history by that clock, refined at every impact by the rebound's own
  // falling flank, keeps the numbering right where a digitized trace has gaps
  // at a peak, at an impact or over a whole rebound: a gap can neither merge
  // two rebounds nor split one.
  const auto crossing = [&](std::size_t top, double t_peak, int step, double amplitude,
                            double offset, double half, double sample_sigma = 0.0,
                            double amplitude_sigma = 0.0) {
    const Crossing c =
        FlankCrossing(h, top, t_peak, step, amplitude, offset, half, sample_sigma, amplitude_sigma);
    return std::isfinite(c.time) ? c : Crossing{t_peak + step * 0.5 * half, 0.25 * half};
  };
  // The sweep is triggered at the release (t = 0), whose fall reaches X = 0
  // at the first impact, a quarter period later. A history whose first
  // stretch above the threshold begins only after that does not show the
  // release (its start lost in a gap, under a mark, or left out as a line
  // followed instead of the trace): that stretch is a later rebound, and
  // taken for the release it would number every rebound after it one or
  // more too low. The walk then starts at the first impact the clock puts
  // after t = 0, and X0 is not known from this history.
  double half_period = HalfPeriod(pendulum, largest);
  const double first_impact_due = 0.5 * half_period;
  double impact = first_impact_due;
  if (FirstAbove(h, threshold) <= first_impact_due) {
    const ReleaseSwing release = FindReleaseSwing(h, pendulum, threshold);
    out.release = {release.amplitude, release.amplitude_sigma};
    half_period = HalfPeriod(pendulum, release.amplitude);
    impact =
        crossing(release.first_falling, release.t_release, +1, release.amplitude, 0.0, half_period)
            .time;
  }
  out.impact_times.push_back(impact);

  for (int number = 1;; ++number) {
    // Rebound `number` lies between `impact` and the next impact. It is
    // measured wherever its peak and enough of both flanks for the fit are on
    // the history (checked below): the record may end on its falling flank.
    // A record ending before the peak the clock predicts ends the walk.
    if (h.time_s.back() < impact + 0.5 * half_period) break;
    // Times so large that a half swing no longer moves them (1e300 s), or a
    // walk that no longer advances: stop rather than loop.
    if (number > max_steps || !(impact + half_period > impact)) {
      out.rebounds.clear();
      out.impact_times.clear();
      return refused(
          fmt::format("the rebounds' walk stopped advancing at t = {:.6g} s after {} step(s)",
                      impact, number - 1));
    }
    const auto [first, end] = SamplesWithin(h, impact, impact + half_period);
    double top_x = 0.0;
    for (std::size_t i = first; i < end; ++i) top_x = std::max(top_x, h.displacement[i]);
    if (end - first < static_cast<std::size_t>(options.min_samples_per_peak)) {
      impact += half_period;  // a whole rebound lost in a gap: the clock carries on
      out.impact_times.push_back(impact);
      continue;
    }
    if (top_x < threshold) break;  // the rebounds have died out
    half_period = HalfPeriod(pendulum, top_x);
    const double predicted_peak = impact + 0.5 * half_period;
    const double half_window = options.peak_window_fraction * half_period;
    const auto [lo, hi_end] =
        SamplesWithin(h, predicted_peak - half_window, predicted_peak + half_window);
    const std::size_t centre = NearestSample(h.time_s, predicted_peak);
    const auto below = static_cast<int>(
        std::lower_bound(h.time_s.begin() + lo, h.time_s.begin() + hi_end, predicted_peak) -
        (h.time_s.begin() + lo));
    const int samples = static_cast<int>(hi_end - lo);
    // The record ends inside this rebound's peak window: nothing later can
    // be measured, so a rebound refused here ends the walk.
    const bool record_ends = h.time_s.back() < predicted_peak + half_window;
    if (samples < options.min_samples_per_peak || below < 2 || samples - below < 2) {
      // Too little of this rebound survives near its peak to measure it;
      // the clock carries on to the next one.
      if (record_ends) break;
      impact += half_period;
      out.impact_times.push_back(impact);
      continue;
    }
    const PeakFit fit = FitPeak(h, pendulum, lo, hi_end - 1, centre, top_x);
    // Both flanks of the fitted peak, not only of the predicted one, must
    // hold samples: a record ending at the peak leaves the shape past it to
    // extrapolation.
    const auto before_fitted = static_cast<int>(
        std::upper_bound(h.time_s.begin() + lo, h.time_s.begin() + hi_end, fit.t_peak.value) -
        (h.time_s.begin() + lo));
    const bool plausible = fit.xmax.value > 0.0 && fit.xmax.value < 1.5 * top_x &&
                           std::abs(fit.t_peak.value - predicted_peak) < half_window &&
                           before_fitted >= 2 && samples - before_fitted >= 2;
    if (!plausible) {
      if (record_ends) break;
      impact += half_period;
      out.impact_times.push_back(impact);
      continue;
    }
    ExtractedRebound rebound;
    rebound.number = number;
    rebound.samples_in_fit = samples;
    rebound.xmax = fit.xmax;
    rebound.t_peak = fit.t_peak;
    rebound.fit_rms = fit.rms;
    const std::size_t top = NearestSample(h.time_s, fit.t_peak.value);
    const Crossing rising = crossing(top, fit.t_peak.value, -1, fit.amplitude, fit.offset,
                                     half_period, fit.rms, fit.xmax.sigma);
    const Crossing falling = crossing(top, fit.t_peak.value, +1, fit.amplitude, fit.offset,
                                      half_period, fit.rms, fit.xmax.sigma);
    rebound.start_s = rising.time;
    rebound.end_s = falling.time;
    rebound.duration = {rebound.end_s - rebound.start_s, std::hypot(rising.sigma, falling.sigma)};
    out.rebounds.push_back(rebound);
    impact = rebound.end_s;
    out.impact_times.push_back(impact);
  }
  out.ok = true;
  return out;
}

}  // namespace impactlab
