#include "rebounds/bar_rebounds.h"

#include <algorithm>
#include <array>
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

// The bars' common swing at rebound 0 (session numbering), from the
// rebounds [0, both) both bars read: the pair's centre of mass swings on
// through every impact (the impact exchanges momentum between the bars, not
// its sum), half a period per rebound, so each bar's maximum is the mean of
// the two plus this length with alternating sign: right_n = mean_n +
// (-1)^n c, left_n = mean_n - (-1)^n c. Estimated as the weighted mean of
// (-1)^n (right_n - left_n) / 2, with its standard error widened by the
// scatter about it (a Birge ratio) where two or more rebounds give it;
// rebound `skip` left out (none by default).
Estimate CommonSwing(const BarRebounds& right, const BarRebounds& left, std::size_t both,
                     std::size_t skip = static_cast<std::size_t>(-1)) {
  double sum_w = 0.0, sum_wc = 0.0;
  std::vector<std::array<double, 2>> readings;  // c_n and its sigma
  for (std::size_t n = 0; n < both; ++n) {
    if (n == skip) continue;
    const double sign = n % 2 == 0 ? 1.0 : -1.0;
    const double c = sign * 0.5 * (right.xmax[n] - left.xmax[n]);
    const double sigma = 0.5 * std::hypot(right.xmax_sigma[n], left.xmax_sigma[n]);
    if (!(sigma > 0.0)) continue;
    readings.push_back({c, sigma});
    sum_w += 1.0 / (sigma * sigma);
    sum_wc += c / (sigma * sigma);
  }
  if (readings.empty()) return {0.0, 0.0};
  const double mean = sum_wc / sum_w;
  double chi2 = 0.0;
  for (const auto& [c, sigma] : readings) chi2 += std::pow((c - mean) / sigma, 2);
  const double birge =
      readings.size() > 1 ? std::max(1.0, std::sqrt(chi2 / (readings.size() - 1.0))) : 1.0;
  return {mean, birge / std::sqrt(sum_w)};
}

// Rebound n's maximum of the pair, mean_n = (right_n + left_n) / 2, from
// both bars' readings. Each bar alone gives it through the common swing c
// (right_n - (-1)^n c, left_n + (-1)^n c), c from the other rebounds. Where
// the two agree within kBarsAgreeSigmas of their combined error (about 95 %
// of clean rebounds) and the bars were read about as well, the plain mean,
// which needs no c. Where they do not, or where the plain mean's sigma is
// more than kPlainSigmaShare times the least-variance weighting's (one bar's
// sigma some 3.5 times the other's: its crest under a mark or misread), the
// two are weighted for the least variance, so the bad bar gives way to the
// other instead of pulling the mean by half its error; the standard error is
// scaled by how far they disagree (the Birge ratio of two), as
// MeanOfTwoSigma does. No c known: the plain mean.
constexpr double kBarsAgreeSigmas = 2.0;
constexpr double kPlainSigmaShare = 2.0;

Estimate MaximumOfPair(const BarRebounds& right, const BarRebounds& left, std::size_t n,
                       const Estimate& common) {
  const double r = right.xmax[n], l = left.xmax[n];
  const double sr = right.xmax_sigma[n], sl = left.xmax_sigma[n];
  if (!(sr > 0.0) || !(sl > 0.0) || !(common.sigma > 0.0)) {
    return {0.5 * (r + l), 0.5 * std::hypot(sr, sl)};
  }
  const double sign = n % 2 == 0 ? 1.0 : -1.0;
  const double from_right = r - sign * common.value, from_left = l + sign * common.value;
  const double vr = sr * sr, vl = sl * sl, vc = common.sigma * common.sigma;
  // Var(a from_right + (1 - a) from_left), c shared with opposite signs, is
  // least at this a; 1/2 when the bars' sigmas are equal.
  const double a = (vl + 2.0 * vc) / (vr + vl + 4.0 * vc);
  const double variance = a * a * vr + (1.0 - a) * (1.0 - a) * vl + std::pow(1.0 - 2.0 * a, 2) * vc;
  const Estimate plain{0.5 * (r + l), 0.5 * std::hypot(sr, sl)};
  const double apart = std::abs(from_right - from_left) / std::sqrt(vr + vl + 4.0 * vc);
  if (apart <= kBarsAgreeSigmas && plain.sigma <= kPlainSigmaShare * std::sqrt(variance)) {
    return plain;
  }
  return {a * from_right + (1.0 - a) * from_left, std::sqrt(variance) * std::max(1.0, apart)};
}

// Whether rebound n's peaks in `a` and `b` lie more than a tenth of its
// duration (`duration`) apart: the bars meet at every impact, so the same
// rebound peaks within a millisecond in both bars and in their average.
bool PeaksApart(const BarRebounds& a, const BarRebounds& b, std::size_t n, double duration) {
  constexpr double kPeakShareOfDuration = 0.1;
  return std::abs(a.t_peak[n] - b.t_peak[n]) > kPeakShareOfDuration * duration;
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
  const std::size_t both = std::min(right.xmax.size(), left.xmax.size());
  for (std::size_t n = 0; n < both; ++n) {
    const double apart_s = std::abs(right.t_peak[n] - left.t_peak[n]);
    if (PeaksApart(right, left, n, 0.5 * (right.duration[n] + left.duration[n]))) {
      return BarDisagreement{
          n, fmt::format("the bars' rebound {} peaks {:.4g} s apart (right at {:.4g} s, left at "
                         "{:.4g} s), more than a tenth of its duration: one bar's trace was "
                         "misread and its rebounds slipped",
                         n, apart_s, right.t_peak[n], left.t_peak[n])};
    }
  }
  return std::nullopt;
}

std::optional<BarDisagreement> AverageSlip(const BarRebounds& right, const BarRebounds& left,
                                           const BarRebounds& averaged) {
  for (std::size_t n = 0; n < averaged.xmax.size(); ++n) {
    for (const auto& [name, bar] : {std::pair{"right", &right}, std::pair{"left", &left}}) {
      // The bar's own duration: a row the average's walk misread may
      // last any time.
      if (n >= bar->xmax.size() || !PeaksApart(averaged, *bar, n, bar->duration[n])) continue;
      return BarDisagreement{
          n, fmt::format("the averaged history's rebound {} peaks at {:.4g} s, the {} bar's at "
                         "{:.4g} s: the average's walk slipped where the other bar's trace is "
                         "lost",
                         n, averaged.t_peak[n], name, bar->t_peak[n])};
    }
  }
  return std::nullopt;
}

void ExtendFromOneBar(const BarRebounds& right, const BarRebounds& left, std::size_t both,
                      BarRebounds& session) {
  if (both == 0) return;  // no rebound tells the common swing
  const bool right_longer = right.xmax.size() > left.xmax.size();
  const BarRebounds& bar = right_longer ? right : left;
  // right_n = mean_n + (-1)^n c; left_n = mean_n - (-1)^n c.
  const double side = right_longer ? 1.0 : -1.0;
  const Estimate common = CommonSwing(right, left, both);
  if (!(common.sigma > 0.0)) return;
  for (std::size_t n = session.xmax.size(); n < bar.xmax.size(); ++n) {
    const double sign = n % 2 == 0 ? 1.0 : -1.0;
    session.xmax.push_back(bar.xmax[n] - side * sign * common.value);
    session.xmax_sigma.push_back(std::hypot(bar.xmax_sigma[n], common.sigma));
    session.t_peak.push_back(bar.t_peak[n]);
    session.t_peak_sigma.push_back(bar.t_peak_sigma[n]);
    session.duration.push_back(bar.duration[n]);
    session.duration_sigma.push_back(SigmaAt(bar.duration_sigma, n));
  }
}

std::optional<std::string> OneBarStretch(const BarRebounds& right, const BarRebounds& left,
                                         std::size_t rows) {
  const bool left_short = left.xmax.size() < right.xmax.size();
  const std::size_t own = std::min(right.xmax.size(), left.xmax.size());
  if (rows <= own) return std::nullopt;
  return fmt::format(
      "the {} bar's trace gives no rebound {}{} of its own (lost under a mark, or past its "
      "record's end): the maxima there are the averaged history's where it has them, else the "
      "{} bar's less the bars' common swing",
      left_short ? "left" : "right", own,
      rows - 1 > own ? fmt::format(" to {}", rows - 1) : std::string(),
      left_short ? "right" : "left");
}

BarRebounds MeanOfBars(const BarRebounds& right, const BarRebounds& left,
                       const BarRebounds& averaged) {
  BarRebounds out;
  const std::optional<BarDisagreement> disagreement = FirstDisagreement(right, left);
  const std::size_t both =
      disagreement ? disagreement->rebound : std::min(right.xmax.size(), left.xmax.size());
  for (std::size_t n = 0; n < both; ++n) {
    const Estimate maximum = MaximumOfPair(right, left, n, CommonSwing(right, left, both, n));
    out.xmax.push_back(maximum.value);
    out.xmax_sigma.push_back(maximum.sigma);
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
  const std::optional<BarDisagreement> slip = AverageSlip(right, left, averaged);
  const std::size_t end = slip ? slip->rebound : averaged.xmax.size();
  for (std::size_t n = both; n < end; ++n) {
    out.xmax.push_back(averaged.xmax[n]);
    out.xmax_sigma.push_back(averaged.xmax_sigma[n]);
    out.t_peak.push_back(averaged.t_peak[n]);
    out.t_peak_sigma.push_back(averaged.t_peak_sigma[n]);
    out.duration.push_back(averaged.duration[n]);
    out.duration_sigma.push_back(SigmaAt(averaged.duration_sigma, n));
  }
  ExtendFromOneBar(right, left, both, out);
  return out;
}

}  // namespace impactlab
