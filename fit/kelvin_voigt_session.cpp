#include "fit/kelvin_voigt_session.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

namespace impactlab {
namespace {

double Mean(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

}  // namespace

StiffnessSpread SpreadOf(const std::vector<double>& stiffness) {
  if (stiffness.empty()) throw std::invalid_argument("no stiffness values to average");
  StiffnessSpread out;
  out.average = Mean(stiffness);
  for (double k : stiffness) {
    out.deviation.push_back(k - out.average);
    out.pct_variation.push_back(100.0 * std::abs(k - out.average) / out.average);
  }
  return out;
}

AverageStiffness AverageStiffnessOf(const std::vector<const KelvinVoigtTwoPointFit*>& fits,
                                    double mass) {
  std::vector<double> stiffness;
  double variance_sum = 0.0;
  for (const KelvinVoigtTwoPointFit* fit : fits) {
    stiffness.push_back(fit->stiffness->value);
    variance_sum += std::pow(fit->stiffness->sigma, 2);
  }
  AverageStiffness out;
  const double average = SpreadOf(stiffness).average;
  const double average_sigma = std::sqrt(variance_sum) / static_cast<double>(stiffness.size());
  out.stiffness = {average, average_sigma};
  for (const KelvinVoigtTwoPointFit* fit : fits) {
    const double zeta = fit->damping_ratio.value;
    const double damping = 2.0 * zeta * std::sqrt(average * mass);
    const double damping_sigma =
        damping * std::hypot(fit->damping_ratio.sigma / std::max(zeta, 1e-300),
                             0.5 * average_sigma / average);
    out.damping.push_back({damping, damping_sigma});
  }
  return out;
}

DampingLineFit FitDampingLine(const std::vector<double>& s, const std::vector<double>& c) {
  const std::size_t n = s.size();
  if (c.size() != n) {
    throw std::invalid_argument(
        fmt::format("the damping line needs one C per sqrt(xi), got {} and {}", c.size(), n));
  }
  DampingLineFit out;
  DampingLine& line = out.line;
  line.points = static_cast<int>(n);
  if (n < 2) {
    out.reason =
        fmt::format("the damping line needs at least two runs with both sqrt(xi) and C, got {}", n);
    return out;
  }
  // Centred sums: no cancellation when sqrt(xi) clusters near 0.85.
  const double s_mean = Mean(s), c_mean = Mean(c);
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sxx += (s[i] - s_mean) * (s[i] - s_mean);
    sxy += (s[i] - s_mean) * (c[i] - c_mean);
  }
  if (!(sxx > 0.0)) {
    out.reason = "the damping line needs runs of different restitution";
    return out;
  }
  const double beta = sxy / sxx;
  const double alpha = c_mean - beta * s_mean;
  double rss = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = c[i] - (alpha + beta * s[i]);
    rss += r * r;
  }
  const double scatter = n > 2 ? rss / static_cast<double>(n - 2) : 0.0;
  const double var_beta = scatter / sxx;
  const double var_alpha = scatter * (1.0 / static_cast<double>(n) + s_mean * s_mean / sxx);
  const double cov_alpha_beta = -s_mean * scatter / sxx;

  line.rms_residual = std::sqrt(rss / static_cast<double>(n));
  line.a = {alpha, std::sqrt(var_alpha)};
  const double b = -beta / alpha;
  // b = -beta/alpha: gradient (beta/alpha^2, -1/alpha).
  const double db_dalpha = beta / (alpha * alpha), db_dbeta = -1.0 / alpha;
  const double var_b = db_dalpha * db_dalpha * var_alpha + db_dbeta * db_dbeta * var_beta +
                       2.0 * db_dalpha * db_dbeta * cov_alpha_beta;
  const double cov_ab = db_dalpha * var_alpha + db_dbeta * cov_alpha_beta;
  line.b = {b, std::sqrt(std::max(var_b, 0.0))};
  line.correlation_ab =
      (var_alpha > 0.0 && var_b > 0.0) ? cov_ab / std::sqrt(var_alpha * var_b) : 0.0;
  out.ok = true;
  return out;
}

PredictedRun PredictRun(const Pendulum& pendulum, const std::string& source_run,
                        const KelvinVoigtTwoPointFit& source_fit, const std::string& target_run,
                        const std::vector<double>& target_xmax,
                        const KelvinVoigtTwoPointFit& target_fit, int start_rebound) {
  PredictedRun result;
  RunPrediction& out = result.prediction;
  out.source_run = source_run;
  out.target_run = target_run;
  out.start_rebound = start_rebound;
  if (!source_fit.ok || !target_fit.ok) {
    result.reason = fmt::format("cannot predict run {} from run {}: {} has no Kelvin-Voigt fit",
                                target_run, source_run, source_fit.ok ? target_run : source_run);
    return result;
  }
  const int count = static_cast<int>(target_xmax.size());
  if (start_rebound < 0 || start_rebound >= count) {
    result.reason = fmt::format("start_rebound {} is not a measured rebound of run {} (0..{})",
                                start_rebound, target_run, count - 1);
    return result;
  }
  out.start_xmax = target_xmax[start_rebound];
  for (int n = start_rebound; n < count; ++n) {
    const double predicted = PredictMaximum(pendulum, out.start_xmax, start_rebound, n,
                                            source_fit.log_restitution.value);
    const double calculated = target_fit.predicted_xmax[n].value;
    const double deviation = calculated - predicted;
    out.predicted.push_back(predicted);
    out.calculated.push_back(calculated);
    out.deviation.push_back(deviation);
    out.pct_peak.push_back(100.0 * deviation / calculated);
    out.pct_start.push_back(100.0 * deviation / out.start_xmax);
  }
  result.ok = true;
  return result;
}

}  // namespace impactlab
