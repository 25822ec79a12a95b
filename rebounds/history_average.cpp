// AverageHistories: the thesis averaged the right and left bars' displacements
// before reading the maxima; one bar's gap must not become the average's.
#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "rebounds/rebound_extraction.h"

namespace impactlab {
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

}  // namespace impactlab
