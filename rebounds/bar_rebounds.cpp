#include "rebounds/bar_rebounds.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

namespace impactlab {

namespace {

// A bar read back from a results file has no duration sigmas: 0 (unknown).
double SigmaAt(const std::vector<double>& sigma, std::size_t n) {
  return n < sigma.size() ? sigma[n] : 0.0;
}

// The standard error of the mean of two readings of one quantity (the bars
// meet at every impact: their rebounds last equally long): their errors
// combined, and where the two disagree beyond those, scaled by how far
// (sqrt of chi^2 with one degree of freedom, the Birge ratio of two), so
// that a reading one bar's trace got wrong does not pass at the other's
// precision. Unknown (0) if either is.
double MeanOfTwoSigma(double a, double sigma_a, double b, double sigma_b) {
  if (!(sigma_a > 0.0) || !(sigma_b > 0.0)) return 0.0;
  const double combined = std::hypot(sigma_a, sigma_b);
  return 0.5 * std::max(combined, std::abs(a - b));
}

}  // namespace

BarRebounds InSessionNumbering(const ReboundExtraction& extraction, int first_rebound) {
  BarRebounds out;
  for (const ExtractedRebound& r : extraction.rebounds) {
    const int n = r.number - first_rebound;
    if (n < 0) continue;
    if (n != static_cast<int>(out.xmax.size())) break;  // keep the sequence gap-free
    out.xmax.push_back(r.xmax.value);
    out.xmax_sigma.push_back(r.xmax.sigma);
    out.t_peak.push_back(r.t_peak.value);
    out.t_peak_sigma.push_back(r.t_peak.sigma);
    out.duration.push_back(r.duration.value);
    out.duration_sigma.push_back(r.duration.sigma);
  }
  out.release = extraction.release;
  return out;
}

void AddCurveSigma(BarRebounds& bar, const std::function<double(double)>& curve_sigma_at) {
  for (std::size_t n = 0; n < bar.xmax.size(); ++n) {
    bar.xmax_sigma[n] = std::hypot(bar.xmax_sigma[n], curve_sigma_at(bar.xmax[n]));
  }
  // A duration's crossings of X = 0 read through the curve at 0: its error
  // there moves both outwards (or both inwards), by that error over the
  // flank's speed, pi Xmax / duration for the swing's sine.
  const double at_zero = curve_sigma_at(0.0);
  for (std::size_t n = 0; n < bar.duration.size() && n < bar.xmax.size(); ++n) {
    if (!(bar.xmax[n] > 0.0) || n >= bar.duration_sigma.size()) continue;
    const double speed = std::numbers::pi * bar.xmax[n] / bar.duration[n];
    bar.duration_sigma[n] = std::hypot(bar.duration_sigma[n], 2.0 * at_zero / speed);
  }
  if (bar.release.value > 0.0 && bar.release.sigma > 0.0) {
    bar.release.sigma = std::hypot(bar.release.sigma, curve_sigma_at(bar.release.value));
  }
}

std::optional<BarDisagreement> FirstDisagreement(const BarRebounds& right,
                                                 const BarRebounds& left) {
  constexpr double kPeakShareOfDuration = 0.1;
  const std::size_t both = std::min(right.xmax.size(), left.xmax.size());
  for (std::size_t n = 0; n < both; ++n) {
    const double duration = 0.5 * (right.duration[n] + left.duration[n]);
    const double apart_s = std::abs(right.t_peak[n] - left.t_peak[n]);
    if (apart_s > kPeakShareOfDuration * duration) {
      return BarDisagreement{
          n, fmt::format("the bars' rebound {} peaks {:.4g} s apart (right at {:.4g} s, left at "
                         "{:.4g} s), more than a tenth of its duration: one bar's trace was "
                         "misread and its rebounds slipped",
                         n, apart_s, right.t_peak[n], left.t_peak[n])};
    }
  }
  return std::nullopt;
}

BarRebounds MeanOfBars(const BarRebounds& right, const BarRebounds& left,
                       const BarRebounds& averaged) {
  BarRebounds out;
  const std::optional<BarDisagreement> disagreement = FirstDisagreement(right, left);
  const std::size_t both =
      disagreement ? disagreement->rebound : std::min(right.xmax.size(), left.xmax.size());
  for (std::size_t n = 0; n < both; ++n) {
    out.xmax.push_back(0.5 * (right.xmax[n] + left.xmax[n]));
    out.xmax_sigma.push_back(0.5 * std::hypot(right.xmax_sigma[n], left.xmax_sigma[n]));
    out.t_peak.push_back(0.5 * (right.t_peak[n] + left.t_peak[n]));
    out.t_peak_sigma.push_back(0.5 * std::hypot(right.t_peak_sigma[n], left.t_peak_sigma[n]));
    out.duration.push_back(0.5 * (right.duration[n] + left.duration[n]));
    out.duration_sigma.push_back(MeanOfTwoSigma(right.duration[n], SigmaAt(right.duration_sigma, n),
                                                left.duration[n], SigmaAt(left.duration_sigma, n)));
  }
  // Each bar's own release; the averaged history's where a bar's is not
  // known.
  out.release = right.release.sigma > 0.0 && left.release.sigma > 0.0
                    ? Estimate{0.5 * (right.release.value + left.release.value),
                               0.5 * std::hypot(right.release.sigma, left.release.sigma)}
                    : averaged.release;
  if (disagreement) return out;
  for (std::size_t n = both; n < averaged.xmax.size(); ++n) {
    out.xmax.push_back(averaged.xmax[n]);
    out.xmax_sigma.push_back(averaged.xmax_sigma[n]);
    out.t_peak.push_back(averaged.t_peak[n]);
    out.t_peak_sigma.push_back(averaged.t_peak_sigma[n]);
    out.duration.push_back(averaged.duration[n]);
    out.duration_sigma.push_back(SigmaAt(averaged.duration_sigma, n));
  }
  return out;
}

}  // namespace impactlab
