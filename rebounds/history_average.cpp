// AverageHistories: the thesis averaged the right and left bars' displacements
// before reading the maxima; one bar's gap must not become the average's.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

#include "rebounds/rebound_extraction.h"

namespace impactlab {
namespace {

// x of history h at time t, if t lies between two of its samples no further
// apart than `max_span_s` (never across a gap), with its one-sigma. A cubic
// through the two samples either side where they are as close and evenly
// enough spaced, else a straight line: a chord cuts under a peak by
// X'' h^2 / 8, which across a slow sweep's chopper gaps is a tenth of a
// percent of the maximum.
std::optional<std::pair<double, double>> Interpolate(const DisplacementHistory& h, double t,
                                                     double max_span_s) {
  const auto it = std::lower_bound(h.time_s.begin(), h.time_s.end(), t);
  if (it == h.time_s.end()) return std::nullopt;
  const auto k = static_cast<std::size_t>(it - h.time_s.begin());
  const auto sigma_at = [&](std::size_t i) { return h.sigma.empty() ? 0.0 : h.sigma[i]; };
  if (*it == t) return std::pair{h.displacement[k], sigma_at(k)};
  const auto joined = [&](std::size_t i) { return h.time_s[i] - h.time_s[i - 1] <= max_span_s; };
  if (k == 0 || !joined(k)) return std::nullopt;
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

}  // namespace impactlab
