#include "rebounds/bar_rebounds.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

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

// The rebounds (session numbering, ascending) both bars show, below `stop`,
// with each bar's row.
struct SharedRebound {
  int n;
  std::size_t right, left;
};
std::vector<SharedRebound> Shared(const BarRebounds& right, const BarRebounds& left,
                                  int stop = std::numeric_limits<int>::max()) {
  std::vector<SharedRebound> out;
  for (std::size_t i = 0; i < right.xmax.size() && right.Number(i) < stop; ++i) {
    if (const std::optional<std::size_t> j = left.RowOf(right.Number(i))) {
      out.push_back({right.Number(i), i, *j});
    }
  }
  return out;
}

double Alternating(int n) { return n % 2 == 0 ? 1.0 : -1.0; }

// One reading of the bars' common swing at rebound 0 (session numbering):
// the pair's centre of mass swings on through every impact (the impact
// exchanges momentum between the bars, not its sum), half a period per
// rebound, so each bar's maximum is the mean of the two plus this length
// with alternating sign: right_n = mean_n + (-1)^n c, left_n = mean_n -
// (-1)^n c. A rebound both bars show reads it as (-1)^n (right_n - left_n) /
// 2 (`n` its number); a bar's release reads it too
// (CommonSwingFromRelease; n = kFromRelease).
struct SwingReading {
  double c = 0.0, sigma = 0.0;
  int n = 0;
};
constexpr int kFromRelease = -1;

std::vector<SwingReading> SharedReadings(const BarRebounds& right, const BarRebounds& left,
                                         const std::vector<SharedRebound>& shared) {
  std::vector<SwingReading> out;
  for (const SharedRebound& s : shared) {
    const double c = Alternating(s.n) * 0.5 * (right.xmax[s.right] - left.xmax[s.left]);
    const double sigma = 0.5 * std::hypot(right.xmax_sigma[s.right], left.xmax_sigma[s.left]);
    if (sigma > 0.0) out.push_back({c, sigma, s.n});
  }
  return out;
}

// The weighted mean of `readings` but the one at index `skip` (none by
// default), with its standard error widened by the scatter about it (a
// Birge ratio) where two or more give it; {0, 0} where none does.
constexpr std::size_t kSkipNone = static_cast<std::size_t>(-1);

Estimate WeightedSwing(const std::vector<SwingReading>& readings, std::size_t skip = kSkipNone) {
  double sum_w = 0.0, sum_wc = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < readings.size(); ++i) {
    if (i == skip) continue;
    const double w = 1.0 / (readings[i].sigma * readings[i].sigma);
    sum_w += w;
    sum_wc += w * readings[i].c;
    ++count;
  }
  if (count == 0) return {0.0, 0.0};
  const double mean = sum_wc / sum_w;
  double chi2 = 0.0;
  for (std::size_t i = 0; i < readings.size(); ++i) {
    if (i != skip) chi2 += std::pow((readings[i].c - mean) / readings[i].sigma, 2);
  }
  const double birge = count > 1 ? std::max(1.0, std::sqrt(chi2 / (count - 1.0))) : 1.0;
  return {mean, birge / std::sqrt(sum_w)};
}

// The bars' common swing from the rebounds `shared` both bars show, rebound
// `skip` left out (none by default).
Estimate CommonSwing(const BarRebounds& right, const BarRebounds& left,
                     const std::vector<SharedRebound>& shared, int skip = -1) {
  std::vector<SwingReading> readings = SharedReadings(right, left, shared);
  std::erase_if(readings, [&](const SwingReading& r) { return r.n == skip; });
  return WeightedSwing(readings);
}

// The common swing for a rebound only one bar shows, where c carries the
// whole of that bar's offset from the mean rather than only weighting two
// readings: the weighted mean of `readings`, less the one furthest from the
// rest where it lies more than kOutlierSigmas from their mean (a bar misread
// at that rebound, or at its release), and only where two or more readings
// remain and agree within kOutlierSigmas as a whole (Birge ratio); else
// unknown ({0, 0}), and the bar's rows alone give no maximum.
constexpr double kOutlierSigmas = 3.0;

Estimate CommonSwingForOneBar(const std::vector<SwingReading>& readings) {
  if (readings.size() < 2) return {0.0, 0.0};
  std::size_t worst = kSkipNone;
  double worst_apart = kOutlierSigmas;
  if (readings.size() >= 3) {
    for (std::size_t i = 0; i < readings.size(); ++i) {
      const Estimate rest = WeightedSwing(readings, i);
      const double apart =
          std::abs(readings[i].c - rest.value) / std::hypot(readings[i].sigma, rest.sigma);
      if (apart > worst_apart) worst_apart = apart, worst = i;
    }
  }
  const Estimate common = WeightedSwing(readings, worst);
  // WeightedSwing's sigma is the plain one times the Birge ratio: the ratio
  // back from the two.
  double plain_w = 0.0;
  for (std::size_t i = 0; i < readings.size(); ++i) {
    if (i != worst) plain_w += 1.0 / (readings[i].sigma * readings[i].sigma);
  }
  if (!(common.sigma > 0.0) || !(plain_w > 0.0)) return {0.0, 0.0};
  const double birge = common.sigma * std::sqrt(plain_w);
  return birge <= kOutlierSigmas ? common : Estimate{0.0, 0.0};
}

// Rebound n's maximum of the pair, mean_n = (right_n + left_n) / 2, from
// both bars' readings. Each bar alone gives it through the common swing c
// (right_n - (-1)^n c, left_n + (-1)^n c), c from the other rebounds. Where
// the two agree within kBarsAgreeSigmas of their combined error (about 95 %
// of clean rebounds) and the bars were read about as well, the plain mean,
// which needs no c. Where they do not, or where the plain mean's sigma is
// more than kPlainSigmaShare times the least-variance weighting's (one bar's
// sigma some 2.6 times the other's: its crest under a mark or misread; once
// the peak fits' sigmas carried the traces' correlated errors, the earlier
// twice, or 3.7 times, let a misread bar's error through by halves: the
// randomised seed set 1's worst maximum per run fell 0.92 -> 0.38 % of X0
// on 1021's run 0.405 and 1.07 -> 0.61 on 1010's 0.713 at 1.5, and rose
// 0.51 -> 0.82 on 1002's 0.713), the
// two are weighted for the least variance, so the bad bar gives way to the
// other instead of pulling the mean by half its error; the standard error is
// scaled by how far they disagree (the Birge ratio of two), as
// MeanOfTwoSigma does. No c known: the plain mean.
constexpr double kBarsAgreeSigmas = 2.0;
constexpr double kPlainSigmaShare = 1.5;

Estimate MaximumOfPairWeighted(const BarRebounds& right, const BarRebounds& left,
                               const SharedRebound& s, const Estimate& common) {
  const double r = right.xmax[s.right], l = left.xmax[s.left];
  const double sr = right.xmax_sigma[s.right], sl = left.xmax_sigma[s.left];
  if (!(sr > 0.0) || !(sl > 0.0) || !(common.sigma > 0.0)) {
    return {0.5 * (r + l), 0.5 * std::hypot(sr, sl)};
  }
  const double sign = Alternating(s.n);
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

// Where the bars' differences at the other rebounds follow no common swing
// (CommonSwingForOneBar finds none, one outlying rebound left out), one bar
// is read wrong throughout, through its calibration or its voltage scale,
// and which one nothing here tells: the standard error is then at least half
// the bars' distance, as MeanOfTwoSigma's (randomised seed 3031's run 0.405,
// its left bar read through a calibration misread over a stretch of its
// swing, 3 to 28 % of X0 low at sigmas of 0.2 to 0.7 %: its maxima were
// stated 5 to 8 sigmas off).
Estimate MaximumOfPair(const BarRebounds& right, const BarRebounds& left, const SharedRebound& s,
                       const Estimate& common, bool swing_follows) {
  const Estimate pair = MaximumOfPairWeighted(right, left, s, common);
  if (swing_follows) return pair;
  const double half_apart = 0.5 * std::abs(right.xmax[s.right] - left.xmax[s.left]);
  return {pair.value, std::max(pair.sigma, half_apart)};
}

// How far apart (as a share of the rebound's duration) two readings of one
// rebound's peak may lie: a tenth.
constexpr double kPeakShareOfDuration = 0.1;

// Whether a rebound's peaks, row `i` of `a` and row `j` of `b`, lie more than
// a tenth of its duration (`duration`) apart: the bars meet at every impact,
// so the same rebound peaks within a millisecond in both bars and in their
// average.
bool PeaksApart(const BarRebounds& a, std::size_t i, const BarRebounds& b, std::size_t j,
                double duration) {
  return std::abs(a.t_peak[i] - b.t_peak[j]) > kPeakShareOfDuration * duration;
}

// The rebounds both bars show whose peaks agree (not PeaksApart).
std::vector<SharedRebound> Agreeing(const BarRebounds& right, const BarRebounds& left) {
  std::vector<SharedRebound> out;
  for (const SharedRebound& s : Shared(right, left)) {
    if (!PeaksApart(right, s.right, left, s.left,
                    0.5 * (right.duration[s.right] + left.duration[s.left]))) {
      out.push_back(s);
    }
  }
  return out;
}

// Appends row `i` of `bar` to `session`, its maximum moved by `shift`
// (sigma `shift_sigma` added in quadrature).
void AppendRow(const BarRebounds& bar, std::size_t i, double shift, double shift_sigma,
               BarRebounds& session) {
  session.xmax.push_back(bar.xmax[i] + shift);
  session.xmax_sigma.push_back(std::hypot(bar.xmax_sigma[i], shift_sigma));
  session.t_peak.push_back(bar.t_peak[i]);
  session.t_peak_sigma.push_back(bar.t_peak_sigma[i]);
  session.duration.push_back(bar.duration[i]);
  session.duration_sigma.push_back(SigmaAt(bar.duration_sigma, i));
}

// The spacing of the peaks the bars read, rebound by rebound: the median
// of (t_j - t_i) / (j - i) over every two rows of different rebounds (the
// bars peak together, on one clock), which a misread peak or two hardly
// moves. The rows of rebound `tested` are left out: the clock tests them.
// `otherwise` where the other rows span one rebound.
double PeakSpacing(const BarRebounds& right, const BarRebounds& left, int tested,
                   double otherwise) {
  std::vector<std::pair<int, double>> peaks;
  for (const BarRebounds* bar : {&right, &left}) {
    for (std::size_t i = 0; i < bar->t_peak.size(); ++i) {
      if (bar->Number(i) != tested && std::isfinite(bar->t_peak[i])) {
        peaks.emplace_back(bar->Number(i), bar->t_peak[i]);
      }
    }
  }
  std::vector<double> spacings;
  for (std::size_t i = 0; i < peaks.size(); ++i) {
    for (std::size_t j = i + 1; j < peaks.size(); ++j) {
      const int apart = peaks[j].first - peaks[i].first;
      if (apart != 0) spacings.push_back((peaks[j].second - peaks[i].second) / apart);
    }
  }
  if (spacings.empty()) return otherwise;
  std::sort(spacings.begin(), spacings.end());
  const std::size_t middle = spacings.size() / 2;
  return spacings.size() % 2 == 1 ? spacings[middle]
                                  : 0.5 * (spacings[middle - 1] + spacings[middle]);
}

// When the pendulum's clock says rebound `n` peaks: the bars meet at
// equilibrium once every half period, so rebound n peaks (n - m) half periods
// after rebound m, m the nearest rebound both bars show; the half period is
// the spacing of their peaks where two or more give it, else the spacing of
// every other peak either bar reads (PeakSpacing). Not one rebound's
// durations: a duration is read between crossings of X = 0, which the
// calibration curve's error there moves alike for every rebound (randomised
// seed 2029's run 0.405 read every duration 0.772 s for 0.750; four of them
// back from its one shared rebound put rebound 0 0.09 s early, and the left
// bar's true rebound 0 was refused as off the clock). `half_period`
// receives it. nullopt where the bars share none.
std::optional<double> DuePeak(const BarRebounds& right, const BarRebounds& left,
                              const std::vector<SharedRebound>& shared, int n,
                              double& half_period) {
  if (shared.empty()) return std::nullopt;
  const auto peak = [&](const SharedRebound& s) {
    return 0.5 * (right.t_peak[s.right] + left.t_peak[s.left]);
  };
  const SharedRebound &first = shared.front(), &last = shared.back();
  half_period = last.n > first.n
                    ? (peak(last) - peak(first)) / (last.n - first.n)
                    : PeakSpacing(right, left, n,
                                  0.5 * (right.duration[first.right] + left.duration[first.left]));
  const SharedRebound* nearest = &first;
  for (const SharedRebound& s : shared) {
    if (std::abs(s.n - n) < std::abs(nearest->n - n)) nearest = &s;
  }
  return peak(*nearest) + (n - nearest->n) * half_period;
}

// Whether row `i` of `history` (rebound `n` of one bar's trace, or of the
// averaged history, where the other bar does not show it) peaks where the
// pendulum's clock puts rebound n, within a tenth of a half period. Where a
// bar's peak at the release end is misread (a stretch of its trace lost,
// a fall read as a crest), nothing else tests it: randomised seed 3033's
// run 0.405 took its right bar's rebound 0 at 0.92 s, 0.17 s after the
// rebound peaks, and stated a maximum 26 % of X0 off with a sigma of 2 %.
// True where the bars share no rebound (no clock to read).
bool OnTheClock(const BarRebounds& right, const BarRebounds& left,
                const std::vector<SharedRebound>& shared, int n, const BarRebounds& history,
                std::size_t i) {
  double half_period = 0.0;
  const std::optional<double> due = DuePeak(right, left, shared, n, half_period);
  return !due || std::abs(history.t_peak[i] - *due) <= kPeakShareOfDuration * half_period;
}

// How many of the averaged history's rows from rebound 0 hold: the average
// is read only where both bars are, so where both bars' traces are lost at
// the start its walk begins later and numbers from there. Its rows hold up to
// the first that peaks away from a bar's rebound of the same number, and only
// if a bar's rebound confirmed a row before it (the walk numbers all its rows
// alike, right or wrong); none where no bar shows any of its rebounds.
int AnchoredRows(const BarRebounds& right, const BarRebounds& left, const BarRebounds& averaged) {
  const std::optional<BarDisagreement> slip = AverageSlip(right, left, averaged);
  const std::size_t rows = averaged.GapFreeRows();
  const std::size_t end = slip ? std::min(slip->rebound, rows) : rows;
  for (std::size_t i = 0; i < end; ++i) {
    if (right.RowOf(static_cast<int>(i)) || left.RowOf(static_cast<int>(i))) {
      return static_cast<int>(end);  // a bar's rebound peaks with this row
    }
  }
  return 0;
}

}  // namespace

std::optional<std::size_t> BarRebounds::RowOf(int n) const {
  if (rebound.empty()) {
    if (n >= 0 && static_cast<std::size_t>(n) < xmax.size()) return static_cast<std::size_t>(n);
    return std::nullopt;
  }
  const auto it = std::lower_bound(rebound.begin(), rebound.end(), n);
  if (it == rebound.end() || *it != n) return std::nullopt;
  return static_cast<std::size_t>(it - rebound.begin());
}

std::size_t BarRebounds::GapFreeRows() const {
  std::size_t rows = 0;
  while (rows < xmax.size() && Number(rows) == static_cast<int>(rows)) ++rows;
  return rows;
}

BarRebounds InSessionNumbering(const ReboundExtraction& extraction, int first_rebound) {
  BarRebounds out;
  for (const ExtractedRebound& r : extraction.rebounds) {
    const int n = r.number - first_rebound;
    if (n < 0) continue;
    out.rebound.push_back(n);
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

namespace {

// A bar's columns with one value per row (duration_sigma may be empty: read
// back from a results file), `rebound` aside.
std::array<std::vector<double>*, 6> RowColumns(BarRebounds& bar) {
  return {&bar.xmax,         &bar.xmax_sigma, &bar.t_peak,
          &bar.t_peak_sigma, &bar.duration,   &bar.duration_sigma};
}

}  // namespace

BarRebounds Informative(const BarRebounds& bar) {
  BarRebounds out = bar;
  out.rebound.clear();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < bar.xmax.size(); ++i) {
    if (!(bar.xmax_sigma[i] <= std::abs(bar.xmax[i]))) continue;
    out.rebound.push_back(bar.Number(i));
    for (std::vector<double>* column : RowColumns(out)) {
      if (i < column->size()) (*column)[kept] = (*column)[i];
    }
    ++kept;
  }
  for (std::vector<double>* column : RowColumns(out)) {
    column->resize(std::min(column->size(), kept));
  }
  return out;
}

BarRebounds GapFree(BarRebounds bar) {
  const std::size_t rows = bar.GapFreeRows();
  for (std::vector<double>* v : RowColumns(bar)) {
    if (v->size() > rows) v->resize(rows);
  }
  if (bar.rebound.size() > rows) bar.rebound.resize(rows);
  return bar;
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
  for (const SharedRebound& s : Shared(right, left)) {
    const double tr = right.t_peak[s.right], tl = left.t_peak[s.left];
    if (PeaksApart(right, s.right, left, s.left,
                   0.5 * (right.duration[s.right] + left.duration[s.left]))) {
      return BarDisagreement{
          static_cast<std::size_t>(s.n),
          fmt::format("the bars' rebound {} peaks {:.4g} s apart (right at {:.4g} s, left at "
                      "{:.4g} s), more than a tenth of its duration: one bar's trace was "
                      "misread and its rebounds slipped",
                      s.n, std::abs(tr - tl), tr, tl)};
    }
  }
  return std::nullopt;
}

std::optional<BarDisagreement> AverageSlip(const BarRebounds& right, const BarRebounds& left,
                                           const BarRebounds& averaged) {
  for (std::size_t i = 0; i < averaged.xmax.size(); ++i) {
    const int n = averaged.Number(i);
    for (const auto& [name, bar] : {std::pair{"right", &right}, std::pair{"left", &left}}) {
      const std::optional<std::size_t> j = bar->RowOf(n);
      // The bar's own duration: a row the average's walk misread may
      // last any time.
      if (!j || !PeaksApart(averaged, i, *bar, *j, bar->duration[*j])) continue;
      return BarDisagreement{
          static_cast<std::size_t>(n),
          fmt::format("the averaged history's rebound {} peaks at {:.4g} s, the {} bar's at "
                      "{:.4g} s: the average's walk slipped where the other bar's trace is "
                      "lost",
                      n, averaged.t_peak[i], name, bar->t_peak[*j])};
    }
  }
  return std::nullopt;
}

std::optional<BarDisagreement> OffTheClock(const BarRebounds& right, const BarRebounds& left,
                                           std::size_t rows) {
  const int n = static_cast<int>(rows);
  const std::vector<SharedRebound> shared = Shared(right, left);
  double half_period = 0.0;
  const std::optional<double> due = DuePeak(right, left, shared, n, half_period);
  if (!due) return std::nullopt;
  for (const auto& [name, bar, other] :
       {std::tuple{"right", &right, &left}, std::tuple{"left", &left, &right}}) {
    const std::optional<std::size_t> j = bar->RowOf(n);
    if (!j || other->RowOf(n) || OnTheClock(right, left, shared, n, *bar, *j)) continue;
    return BarDisagreement{
        rows,
        fmt::format("the {} bar's rebound {}, which the other bar's trace does not show, "
                    "peaks at {:.4g} s, {:.2g} s from where the pendulum's clock puts it "
                    "({:.4g} s, half periods of {:.4g} s): its trace was misread there",
                    name, n, bar->t_peak[*j], std::abs(bar->t_peak[*j] - *due), *due, half_period)};
  }
  return std::nullopt;
}

std::optional<std::string> OneBarStretch(const BarRebounds& right, const BarRebounds& left,
                                         std::size_t rows) {
  std::vector<std::string> lost;
  for (const auto& [name, bar] : {std::pair{"right", &right}, std::pair{"left", &left}}) {
    std::vector<int> missing;
    for (int n = 0; n < static_cast<int>(rows); ++n) {
      if (!bar->RowOf(n)) missing.push_back(n);
    }
    if (missing.empty()) continue;
    // Consecutive rebounds as a range: "2 to 4".
    std::string which;
    for (std::size_t k = 0; k < missing.size();) {
      std::size_t end = k;
      while (end + 1 < missing.size() && missing[end + 1] == missing[end] + 1) ++end;
      if (!which.empty()) which += ", ";
      which += end > k ? fmt::format("{} to {}", missing[k], missing[end])
                       : fmt::format("{}", missing[k]);
      k = end + 1;
    }
    lost.push_back(fmt::format("the {} bar's trace gives no rebound {} of its own", name, which));
  }
  if (lost.empty()) return std::nullopt;
  return fmt::format(
      "{} (lost under a mark, in a gap, or past its record's end): the maxima there are the "
      "averaged history's where it has them and the other bar agrees, else the other bar's less "
      "the bars' common swing",
      fmt::join(lost, "; "));
}

// How far one bar's release may lie from the run's typed X0, as a share of
// it, for the two to give the common swing: the bars of the external
// sessions are let go within 1.3 % of X0 (docs/reduction.md, "Each bar's
// voltage scale against the other's").
constexpr double kReleaseOffX0 = 0.03;

Estimate CommonSwingFromRelease(const BarRebounds& bar, bool right_bar, const TypedRelease& typed) {
  if (!(bar.release.sigma > 0.0) || !(typed.x0 > 0.0)) return {};
  const double offset = right_bar ? bar.release.value - typed.x0 : typed.x0 - bar.release.value;
  if (std::abs(offset) > kReleaseOffX0 * typed.x0) return {};
  return {Alternating(typed.first_rebound) * offset, bar.release.sigma};
}

BarRebounds MeanOfBars(const BarRebounds& right_read, const BarRebounds& left_read,
                       const BarRebounds& averaged, const TypedRelease& typed) {
  const BarRebounds right = Informative(right_read), left = Informative(left_read);
  BarRebounds out;
  const std::optional<BarDisagreement> disagreement = FirstDisagreement(right, left);
  // The rebounds whose peaks the bars agree on set the pendulum's clock and
  // the common swing; one they disagree on is one bar's misread, and which
  // one the clock tells (below).
  const std::vector<SharedRebound> shared = Agreeing(right, left);
  // Each bar's own release; the averaged history's where a bar's is not
  // known.
  out.release = right.release.sigma > 0.0 && left.release.sigma > 0.0
                    ? Estimate{0.5 * (right.release.value + left.release.value),
                               0.5 * std::hypot(right.release.sigma, left.release.sigma)}
                    : averaged.release;
  // The average's rows hold as far as its numbering does.
  const int average_end = disagreement ? 0 : AnchoredRows(right, left, averaged);
  // The common swing from the rebounds both bars show; where they share
  // fewer than two, each bar's release reads it too, and the readings must
  // agree (CommonSwingForOneBar): a bar's release alone (off X0 by a
  // mistyped X0, a hold's corner read as the release) tests nothing.
  std::vector<SwingReading> readings = SharedReadings(right, left, shared);
  if (shared.size() < 2) {
    for (const bool right_bar : {true, false}) {
      const Estimate c = CommonSwingFromRelease(right_bar ? right : left, right_bar, typed);
      if (c.sigma > 0.0) readings.push_back({c.value, c.sigma, kFromRelease});
    }
  }
  const Estimate common = CommonSwingForOneBar(readings);
  const bool swing_follows = shared.size() < 2 || common.sigma > 0.0;
  // Where the bars share fewer than two rebounds and one bar is lost (its
  // trace shows at most one), the other's common swing from its own
  // release: one reading that nothing tests. A release read off the typed X0 may be the
  // bars let go unevenly or the release misread (its trace lost over the
  // hold and the fall's start, the fall's fit then extrapolated: in a trial
  // that read runs on one bar where the other's calibration failed,
  // randomised seeds 1018's and 1034's runs 0.713 read their right bar's release 1.9
  // and 2.8 % of X0 low at 8 and 7 of its sigmas, the bars let go within
  // 0.1 %), and one bar alone cannot tell which: its sigma is at least the
  // offset it reads.
  const auto lost = [](const BarRebounds& bar) { return bar.xmax.size() <= 1; };
  // (A lost bar's one row, shared or not, is as doubtful as the rest of it
  // was: randomised seed 3017's run 0.405 showed its left bar only at
  // rebound 3, misread 6 % of X0 low, which as a reading of the common swing
  // disagreed with the right bar's release and ended the maxima there.)
  // (A lost bar shares at most one rebound: `common` is the shared ones'
  // reading wherever the other bar is not lost.)
  const auto common_for = [&](bool right_bar) {
    if (lost(right_bar ? left : right)) {
      const Estimate c = CommonSwingFromRelease(right_bar ? right : left, right_bar, typed);
      return Estimate{c.value, std::max(c.sigma, std::abs(c.value))};
    }
    return common;
  };
  for (int n = 0;; ++n) {
    std::optional<std::size_t> r = right.RowOf(n), l = left.RowOf(n);
    if (r && l && PeaksApart(right, *r, left, *l, 0.5 * (right.duration[*r] + left.duration[*l]))) {
      // The bar whose peak the clock of the agreeing rebounds puts here is
      // the one read right; where both or neither are (or no clock runs),
      // nothing tells them apart and the sequence ends.
      // A lost bar's one row gives way to the other bar's, as it gives no
      // common swing (above).
      bool right_on = lost(left), left_on = lost(right);
      if (right_on == left_on) {
        right_on = OnTheClock(right, left, shared, n, right, *r);
        left_on = OnTheClock(right, left, shared, n, left, *l);
        if (shared.empty() || right_on == left_on) break;
      }
      (right_on ? l : r).reset();
    }
    if (r && l) {
      const SharedRebound s{n, *r, *l};
      const Estimate maximum =
          MaximumOfPair(right, left, s, CommonSwing(right, left, shared, n), swing_follows);
      out.xmax.push_back(maximum.value);
      out.xmax_sigma.push_back(maximum.sigma);
      out.t_peak.push_back(0.5 * (right.t_peak[*r] + left.t_peak[*l]));
      out.t_peak_sigma.push_back(0.5 * std::hypot(right.t_peak_sigma[*r], left.t_peak_sigma[*l]));
      out.duration.push_back(0.5 * (right.duration[*r] + left.duration[*l]));
      out.duration_sigma.push_back(
          MeanOfTwoSigma(right.duration[*r], SigmaAt(right.duration_sigma, *r), left.duration[*l],
                         SigmaAt(left.duration_sigma, *l)));
      continue;
    }
    // One bar shows the rebound: its maximum through the common swing c,
    // right_n = mean_n + (-1)^n c and left_n = mean_n - (-1)^n c.
    const bool one_bar = (r || l) && common_for(r.has_value()).sigma > 0.0;
    const BarRebounds& bar = r ? right : left;
    const std::size_t row = r ? *r : (l ? *l : 0);
    const auto shift_of_one_bar = [&] {
      const Estimate c = common_for(r.has_value());
      return Estimate{-(r ? 1.0 : -1.0) * Alternating(n) * c.value, c.sigma};
    };
    if (n < average_end) {
      const auto i = static_cast<std::size_t>(n);
      if (!OnTheClock(right, left, shared, n, averaged, i)) break;
      // The averaged history is read only where both bars are: a bar that
      // lost its crest leaves the average's crest to be extrapolated from
      // its flanks, and where the other bar's own maximum (through c)
      // disagrees with it, the bar that saw the crest is taken (randomised
      // seed 5020's run 0.713: the right bar's trace lost for 0.57 s over
      // rebound 0's crest, the average's maximum 0.357 +- 0.022 against the
      // left bar's 0.566 +- 0.010, the truth 0.575).
      const Estimate shift = one_bar ? shift_of_one_bar() : Estimate{};
      const bool averaged_disagrees =
          one_bar && std::abs(averaged.xmax[i] - (bar.xmax[row] + shift.value)) >
                         kBarsAgreeSigmas *
                             std::sqrt(std::pow(averaged.xmax_sigma[i], 2) +
                                       std::pow(bar.xmax_sigma[row], 2) + std::pow(shift.sigma, 2));
      if (!averaged_disagrees) {
        AppendRow(averaged, i, 0.0, 0.0, out);
        continue;
      }
    }
    if (!one_bar) break;  // nothing gives this rebound: the sequence stays gap-free
    if (!OnTheClock(right, left, shared, n, bar, row)) break;
    const Estimate shift = shift_of_one_bar();
    AppendRow(bar, row, shift.value, shift.sigma, out);
  }
  return out;
}

}  // namespace impactlab
