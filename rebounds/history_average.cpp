// AverageHistories: the thesis averaged the right and left bars' displacements
// before reading the maxima; one bar's gap must not become the average's.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

#include <Eigen/Dense>

#include "rebounds/rebound_extraction.h"

namespace impactlab {
namespace {

// The curve across the gap between samples k - 1 and k of a history: the
// least-squares cubic through the samples within one gap's length either
// side, with its covariance. A chopped trace draws each bar only in its own
// dashes, so a sweep shared by two bars leaves each a gap in every other
// chopper slot; a chord across one cuts under a peak by X'' g^2 / 8 (a
// quarter percent of X for a 0.036 s gap on a 1.5 s pendulum), a cubic
// through both sides by about X (w g)^4 / 400, a millionth. Needs three
// samples on each side spanning a quarter of the gap, or there is no curve to
// carry across.
struct GapCubic {
  double centre = 0.0, gap = 1.0;  // u = (t - centre) / gap
  Eigen::Vector4d coefficients;    // of 1, u, u^2, u^3
  Eigen::Matrix4d covariance;      // theirs, the fit's scatter allowed for
};

std::optional<GapCubic> FitGap(const DisplacementHistory& h, std::size_t k) {
  const double before = h.time_s[k - 1], after = h.time_s[k], gap = after - before;
  const auto lo = static_cast<std::size_t>(
      std::lower_bound(h.time_s.begin(), h.time_s.begin() + k, before - gap) - h.time_s.begin());
  const auto hi = static_cast<std::size_t>(
      std::upper_bound(h.time_s.begin() + k, h.time_s.end(), after + gap) - h.time_s.begin());
  constexpr std::size_t kPerSide = 3;
  if (k - lo < kPerSide || hi - k < kPerSide) return std::nullopt;
  if (before - h.time_s[lo] < 0.25 * gap || h.time_s[hi - 1] - after < 0.25 * gap) {
    return std::nullopt;
  }
  // Powers of u = (t - centre) / gap: of order 1 across the window.
  GapCubic fit;
  fit.centre = 0.5 * (before + after);
  fit.gap = gap;
  const auto n = static_cast<Eigen::Index>(hi - lo);
  Eigen::MatrixXd design(n, 4);
  Eigen::VectorXd x(n), weight(n);
  const bool weighted = !h.sigma.empty();
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::size_t j = lo + static_cast<std::size_t>(i);
    const double u = (h.time_s[j] - fit.centre) / gap;
    design.row(i) << 1.0, u, u * u, u * u * u;
    x(i) = h.displacement[j];
    weight(i) = weighted && h.sigma[j] > 0.0 ? 1.0 / h.sigma[j] : 1.0;
  }
  const Eigen::MatrixXd a = weight.asDiagonal() * design;
  const Eigen::VectorXd b = weight.asDiagonal() * x;
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  if (qr.rank() < 4) return std::nullopt;
  fit.coefficients = qr.solve(b);
  const double dof = static_cast<double>(n - 4);
  const double chi2 = (a * fit.coefficients - b).squaredNorm();
  // No smooth curve runs through both sides (an impact's corner lies in the
  // gap, or a side is misread): four standard deviations of chi^2 beyond its
  // mean, and the gap stays a gap.
  if (weighted && dof > 0.0 && chi2 > dof + 4.0 * std::sqrt(2.0 * dof)) return std::nullopt;
  // (A^T A)^-1 from the samples' sigmas, widened by the fit's own scatter
  // where the samples scatter more than they say.
  const double scale = dof > 0.0 ? std::max(1.0, chi2 / dof) : 1.0;
  fit.covariance = scale * (a.transpose() * a).inverse();
  return fit;
}

// One history's gap fit, kept while the times asked for stay in that gap
// (every time the other bar was read at in it).
struct GapCache {
  std::size_t k = 0;  // 0: none yet (a gap ends at a sample k >= 1)
  std::optional<GapCubic> fit;
};

// x of history h at time t inside the gap between samples k - 1 and k, with
// its one-sigma: the least-squares cubic through the samples within one
// gap's length either side (FitGap).
std::optional<std::pair<double, double>> Bridge(const DisplacementHistory& h, std::size_t k,
                                                double t, GapCache& cache) {
  if (cache.k != k) cache = {k, FitGap(h, k)};
  if (!cache.fit) return std::nullopt;
  const GapCubic& fit = *cache.fit;
  const double u = (t - fit.centre) / fit.gap;
  const Eigen::Vector4d at(1.0, u, u * u, u * u * u);
  return std::pair{at.dot(fit.coefficients), std::sqrt(at.dot(fit.covariance * at))};
}

// x of history h at time t, if t lies between two of its samples no further
// apart than `max_span_s`, or bridged across a gap up to `max_bridge_s`
// wide, with its one-sigma. A cubic
// through the two samples either side where they are as close and evenly
// enough spaced, else a straight line: a chord cuts under a peak by
// X'' h^2 / 8, which across a slow sweep's chopper gaps is a tenth of a
// percent of the maximum.
std::optional<std::pair<double, double>> Interpolate(const DisplacementHistory& h, double t,
                                                     double max_span_s, double max_bridge_s,
                                                     GapCache& cache) {
  const auto it = std::lower_bound(h.time_s.begin(), h.time_s.end(), t);
  if (it == h.time_s.end()) return std::nullopt;
  const auto k = static_cast<std::size_t>(it - h.time_s.begin());
  const auto sigma_at = [&](std::size_t i) { return h.sigma.empty() ? 0.0 : h.sigma[i]; };
  if (*it == t) return std::pair{h.displacement[k], sigma_at(k)};
  const auto joined = [&](std::size_t i) { return h.time_s[i] - h.time_s[i - 1] <= max_span_s; };
  if (k == 0) return std::nullopt;
  if (!joined(k)) {
    if (h.time_s[k] - h.time_s[k - 1] > max_bridge_s) return std::nullopt;
    return Bridge(h, k, t, cache);
  }
  const double sigma = std::max(sigma_at(k - 1), sigma_at(k));
  if (k >= 2 && k + 1 < h.time_s.size() && joined(k - 1) && joined(k + 1)) {
    // Lagrange's cubic through samples k-2 .. k+1, unless its weights would
    // amplify the samples' noise (two samples read at almost the same time).
    std::array<double, 4> weight{1.0, 1.0, 1.0, 1.0};
    for (std::size_t i = 0; i < 4; ++i) {
      for (std::size_t j = 0; j < 4; ++j) {
        const double ti = h.time_s[k - 2 + i], tj = h.time_s[k - 2 + j];
        if (j != i) weight[i] *= (t - tj) / (ti - tj);
      }
    }
    // The noise gain, sqrt(sum of weights^2): under 1 on even spacing, 1.4
    // across a gap three samples wide, thousands for two samples 1e-5 apart.
    constexpr double kMaxNoiseGain = 2.0;
    double gain2 = 0.0, x = 0.0, variance = 0.0;
    for (std::size_t i = 0; i < 4; ++i) {
      gain2 += weight[i] * weight[i];
      x += weight[i] * h.displacement[k - 2 + i];
      variance += weight[i] * weight[i] * sigma_at(k - 2 + i) * sigma_at(k - 2 + i);
    }
    if (gain2 <= kMaxNoiseGain * kMaxNoiseGain) return std::pair{x, std::sqrt(variance)};
  }
  const double f = (t - h.time_s[k - 1]) / (h.time_s[k] - h.time_s[k - 1]);
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

DisplacementHistory AverageHistories(const DisplacementHistory& a, const DisplacementHistory& b,
                                     double max_bridge_s) {
  // On the union of both sample times: where one bar's trace has a gap (a
  // digitized photo may), the other still counts wherever both can be read.
  std::vector<double> times = a.time_s;
  times.insert(times.end(), b.time_s.begin(), b.time_s.end());
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  const double span_a = 4.0 * MedianStep(a.time_s), span_b = 4.0 * MedianStep(b.time_s);
  DisplacementHistory out;
  GapCache cache_a, cache_b;
  for (double t : times) {
    const auto xa = Interpolate(a, t, span_a, max_bridge_s, cache_a);
    const auto xb = Interpolate(b, t, span_b, max_bridge_s, cache_b);
    if (!xa || !xb) continue;
    out.time_s.push_back(t);
    out.displacement.push_back(0.5 * (xa->first + xb->first));
    if (!a.sigma.empty() && !b.sigma.empty())
      out.sigma.push_back(0.5 * std::hypot(xa->second, xb->second));
  }
  return out;
}

}  // namespace impactlab
