#include "rebounds/rebound_anomalies.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <boost/math/special_functions/erf.hpp>

namespace impactlab {
namespace {

double At(const std::vector<double>& v, std::size_t n) { return n < v.size() ? v[n] : 0.0; }

}  // namespace

int CountReboundTests(const std::vector<double>& xmax, const std::vector<double>& duration,
                      const std::vector<double>& duration_sigma) {
  int tests = 0;
  for (std::size_t n = 1; n < xmax.size(); ++n) {
    tests += std::isfinite(xmax[n]) && std::isfinite(xmax[n - 1]);
  }
  for (std::size_t n = 0; n < duration.size() && n < xmax.size(); ++n) {
    tests += At(duration_sigma, n) > 0.0 && std::isfinite(duration[n]) && xmax[n] > 0.0;
  }
  return tests;
}

double AnomalyThreshold(double false_alarm_rate, int tests) {
  const double each = std::clamp(false_alarm_rate, 1e-12, 1.0) / std::max(1, tests);
  // P(|z| > t) = erfc(t / sqrt 2) = each.
  return std::sqrt(2.0) * boost::math::erfc_inv(each);
}

std::vector<ReboundAnomaly> FindReboundAnomalies(const Pendulum& pendulum,
                                                 const std::vector<double>& xmax,
                                                 const std::vector<double>& xmax_sigma,
                                                 const std::vector<double>& duration,
                                                 const std::vector<double>& duration_sigma,
                                                 const ReboundAnomalyOptions& options) {
  std::vector<ReboundAnomaly> out;
  for (std::size_t n = 1; n < xmax.size(); ++n) {
    if (!std::isfinite(xmax[n]) || !std::isfinite(xmax[n - 1])) continue;
    const double rise = xmax[n] - xmax[n - 1];
    const double sigma = std::hypot(At(xmax_sigma, n), At(xmax_sigma, n - 1));
    if (rise > options.sigmas * sigma && rise > 0.0) {
      out.push_back({static_cast<int>(n),
                     sigma > 0.0
                         ? fmt::format("rebound {} ({:.4g}) exceeds rebound {} ({:.4g}) by {:.2g} "
                                       "sigma: an impact cannot add energy",
                                       n, xmax[n], n - 1, xmax[n - 1], rise / sigma)
                         : fmt::format("rebound {} ({:.4g}) exceeds rebound {} ({:.4g}): an "
                                       "impact cannot add energy",
                                       n, xmax[n], n - 1, xmax[n - 1])});
    }
  }
  for (std::size_t n = 0; n < duration.size() && n < xmax.size(); ++n) {
    const double d = duration[n], sd = At(duration_sigma, n);
    if (!(sd > 0.0) || !std::isfinite(d) || !(xmax[n] > 0.0)) continue;
    double expected = 0.0, slope = 0.0;
    try {
      expected = HalfPeriod(pendulum, xmax[n]);
      // The half period's own uncertainty through its amplitude (a central
      // difference: HalfPeriod is smooth and this is no fit).
      const double h = 1e-4 * xmax[n];
      slope = (HalfPeriod(pendulum, xmax[n] + h) - HalfPeriod(pendulum, xmax[n] - h)) / (2.0 * h);
    } catch (const std::domain_error&) {
      continue;  // past the horizontal: the maximum itself is the problem
    }
    const double sigma = std::hypot(sd, slope * At(xmax_sigma, n));
    const double apart = (d - expected) / sigma;
    if (std::abs(apart) > options.sigmas) {
      out.push_back(
          {static_cast<int>(n),
           fmt::format("rebound {} lasts {:.5g} s; the pendulum's half period at its "
                       "amplitude is {:.5g} s: {:.2g} sigma {} (a disturbed swing, or its zero "
                       "crossings misread)",
                       n, d, expected, std::abs(apart), apart > 0 ? "longer" : "shorter")});
    }
  }
  return out;
}

}  // namespace impactlab
