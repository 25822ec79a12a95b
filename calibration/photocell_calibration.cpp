#include "calibration/photocell_calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <Eigen/Dense>
#include <boost/math/tools/roots.hpp>

#include "calibration/curve_band.h"
#include "model/estimate.h"

namespace impactlab {
namespace {

// T_0..T_n and their derivatives dT_k/du at u (three-term recurrences).
void Chebyshev(double u, int n, Eigen::VectorXd& t, Eigen::VectorXd* dt = nullptr) {
  t(0) = 1.0;
  if (n >= 1) t(1) = u;
  for (int k = 2; k <= n; ++k) t(k) = 2.0 * u * t(k - 1) - t(k - 2);
  if (dt == nullptr) return;
  // T_k' = k U_{k-1}, U_0 = 1, U_1 = 2u, U_k = 2u U_{k-1} - U_{k-2}.
  dt->resize(n + 1);
  (*dt)(0) = 0.0;
  double u_prev = 0.0, u_cur = 1.0;  // U_{-1}, U_0
  for (int k = 1; k <= n; ++k) {
    (*dt)(k) = k * u_cur;
    const double u_next = 2.0 * u * u_cur - u_prev;
    u_prev = u_cur;
    u_cur = u_next;
  }
}

double ToUnit(double x, double x_max) { return 2.0 * x / x_max - 1.0; }

struct OrderFit {
  Eigen::VectorXd coefficients;
  Eigen::MatrixXd covariance;
  double rss = 0.0;
  double bic = 0.0;
};

OrderFit FitOrder(const Eigen::MatrixXd& basis_all, const Eigen::VectorXd& v,
                  const Eigen::VectorXd& weight, int order) {
  const Eigen::Index n = v.size();
  const Eigen::MatrixXd a = weight.asDiagonal() * basis_all.leftCols(order + 1);
  const Eigen::VectorXd b = weight.asDiagonal() * v;
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  OrderFit fit;
  fit.coefficients = qr.solve(b);
  fit.rss = (a * fit.coefficients - b).squaredNorm();
  const double dof = static_cast<double>(n - (order + 1));
  const double scatter = fit.rss / dof;
  fit.covariance = scatter * (a.transpose() * a).inverse();
  fit.bic = static_cast<double>(n) * std::log(std::max(fit.rss, 1e-300) / static_cast<double>(n)) +
            static_cast<double>(order + 1) * std::log(static_cast<double>(n));
  return fit;
}

// Why `curve` is not monotone over [0, x_max], nullopt when it is.
std::optional<std::string> NonMonotone(const PhotocellCurve& curve, double x_max) {
  const int grid = 2048;
  const double first_slope = curve.SlopeAt(0.5 * x_max);
  for (int k = 0; k <= grid; ++k) {
    const double x = x_max * k / grid;
    if (curve.SlopeAt(x) * first_slope <= 0.0) {
      return fmt::format(
          "the calibration curve is not monotone: its slope changes sign near X = {:.4g} "
          "({:.5g} V); the photocell output does not determine the displacement there",
          x, curve.VoltsAt(x));
    }
  }
  return std::nullopt;
}

}  // namespace

bool CalibrationOptions::Check(std::string* error) const {
  if (max_order < 1 || max_order > 20) {
    *error = fmt::format("max_order must be 1..20, got {}", max_order);
    return false;
  }
  if (!(skip_after_release_s >= 0.0) || !(range_margin >= 0.0 && range_margin < 0.5)) {
    *error = "skip_after_release_s must be >= 0 and range_margin in [0, 0.5)";
    return false;
  }
  return true;
}

PhotocellCurve::PhotocellCurve(double x_max, std::vector<double> chebyshev,
                               std::vector<double> covariance, double range_margin,
                               std::vector<double> fit_covariance)
    : x_max_(x_max),
      chebyshev_(std::move(chebyshev)),
      covariance_(std::move(covariance)),
      fit_covariance_(fit_covariance.empty() ? covariance_ : std::move(fit_covariance)) {
  const double v0 = VoltsAt(0.0), v1 = VoltsAt(x_max_);
  falling_ = v1 < v0;
  volts_min_ = std::min(v0, v1);
  volts_max_ = std::max(v0, v1);
  margin_volts_ = range_margin * (volts_max_ - volts_min_);
}

double PhotocellCurve::VoltsAt(double x) const {
  // Clenshaw's recurrence: sum c_k T_k(u) without forming T_k (hot path: every
  // sample of every trace goes through a root search on this).
  const double u = ToUnit(x, x_max_);
  double b1 = 0.0, b2 = 0.0;
  for (std::size_t k = chebyshev_.size(); k-- > 1;) {
    const double b0 = 2.0 * u * b1 - b2 + chebyshev_[k];
    b2 = b1;
    b1 = b0;
  }
  return u * b1 - b2 + chebyshev_[0];
}

double PhotocellCurve::SlopeAt(double x) const {
  // dV/dX = (2 / x_max) sum c_k k U_{k-1}(u), with U by its recurrence.
  const double u = ToUnit(x, x_max_);
  double sum = 0.0, u_prev = 0.0, u_cur = 1.0;  // U_{-1}, U_0
  for (std::size_t k = 1; k < chebyshev_.size(); ++k) {
    sum += chebyshev_[k] * static_cast<double>(k) * u_cur;
    const double u_next = 2.0 * u * u_cur - u_prev;
    u_prev = u_cur;
    u_cur = u_next;
  }
  return 2.0 / x_max_ * sum;
}

bool PhotocellCurve::Covers(double volts) const {
  return volts >= volts_min_ - margin_volts_ && volts <= volts_max_ + margin_volts_;
}

double PhotocellCurve::DisplacementFromVolts(double volts) const {
  if (!Covers(volts)) {
    throw std::domain_error(
        fmt::format("{:.6g} V is outside the calibrated range {:.6g} .. {:.6g} V", volts,
                    volts_min_, volts_max_));
  }
  // Within the margin the curve is extended linearly from its end.
  if (volts < volts_min_ || volts > volts_max_) {
    const double end_x = (volts < volts_min_) == falling_ ? x_max_ : 0.0;
    return end_x + (volts - VoltsAt(end_x)) / SlopeAt(end_x);
  }
  const auto residual = [&](double x) { return VoltsAt(x) - volts; };
  std::uintmax_t iterations = 100;
  const auto [lo, hi] =
      boost::math::tools::toms748_solve(residual, 0.0, x_max_, residual(0.0), residual(x_max_),
                                        boost::math::tools::eps_tolerance<double>(50), iterations);
  return 0.5 * (lo + hi);
}

double PhotocellCurve::DisplacementSigma(double volts) const {
  return DisplacementSigmaAt(DisplacementFromVolts(volts));
}

double PhotocellCurve::DisplacementSigmaAt(double x) const { return SigmaAt(covariance_, x); }

double PhotocellCurve::FitDisplacementSigma(double volts) const {
  return SigmaAt(fit_covariance_, DisplacementFromVolts(volts));
}

double PhotocellCurve::SigmaAt(const std::vector<double>& covariance, double x_in) const {
  const double x = std::clamp(x_in, 0.0, x_max_);
  const int n = order();
  Eigen::VectorXd t(n + 1);
  Chebyshev(ToUnit(x, x_max_), n, t);
  const Eigen::Map<const Eigen::MatrixXd> cov(covariance.data(), n + 1, n + 1);
  const double sigma_volts = std::sqrt(std::max(0.0, t.dot(cov * t)));
  return sigma_volts / std::abs(SlopeAt(x));
}

namespace {

// The first swing's samples as the fit takes them: the Chebyshev basis at
// each sample's ideal displacement, its volts and its weight (1 / sigma).
struct SwingSamples {
  Eigen::MatrixXd basis;
  Eigen::VectorXd v, weight;
  Eigen::Index size() const { return v.size(); }
};

SwingSamples Rows(const SwingSamples& all, const std::vector<Eigen::Index>& rows) {
  SwingSamples out{Eigen::MatrixXd(static_cast<Eigen::Index>(rows.size()), all.basis.cols()),
                   Eigen::VectorXd(static_cast<Eigen::Index>(rows.size())),
                   Eigen::VectorXd(static_cast<Eigen::Index>(rows.size()))};
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    out.basis.row(i) = all.basis.row(rows[k]);
    out.v(i) = all.v(rows[k]);
    out.weight(i) = all.weight(rows[k]);
  }
  return out;
}

// A curve through the samples, or why none is.
struct CurveFit {
  bool ok = false;
  std::string reason;  // when !ok
  PhotocellCurve curve;
  double correlation_inflation = 1.0;
  std::vector<double> bic;  // per order, from 1
  // The BIC's order's weighted residuals, whether or not its curve was
  // taken: where a misreading sits, they stand out (OffCurve).
  Eigen::VectorXd best_weighted_residual;
};

// Whether a curve turns over only where the samples leave the swing unread
// and only within its band: wherever its slope has the other sign than at
// mid-swing, that is outside the samples' span [u_lo, u_hi] (in u) and by no
// more than kTurnInsideBand standard deviations of the slope (from `band`,
// the coefficients' covariance). Where the samples leave an end of the swing
// unread (the bar is fast at X = 0, and a sparse trace may show nothing
// there) a high order extrapolates, and a turn it makes there within its
// band is no evidence that the cell folds back.
constexpr double kTurnInsideBand = 3.0;

bool TurnsOnlyWhereUnread(const Eigen::VectorXd& coefficients, const Eigen::MatrixXd& band,
                          double u_lo, double u_hi) {
  const int order = static_cast<int>(coefficients.size()) - 1;
  Eigen::VectorXd t(order + 1), dt(order + 1);
  Chebyshev(0.0, order, t, &dt);
  const double mid_slope = coefficients.dot(dt);
  constexpr int kGrid = 2048;
  for (int k = 0; k <= kGrid; ++k) {
    const double u = -1.0 + 2.0 * k / kGrid;
    Chebyshev(u, order, t, &dt);
    const double slope = coefficients.dot(dt);  // in u: its sign and its z are what count
    if (slope * mid_slope > 0.0) continue;
    if (u >= u_lo && u <= u_hi) return false;
    if (std::abs(slope) > kTurnInsideBand * std::sqrt(std::max(0.0, dt.dot(band * dt)))) {
      return false;
    }
  }
  return true;
}

// The widest stretch of the swing (in u, over [-1, 1]) that holds no sample.
// From a fifth of the swing on, the samples leave too much unread for any
// curve there to be more than the fit's guess (UnreadStretch says so when a
// calibration is refused), and the second look takes no lower order there.
constexpr double kMaxUnread = 0.2;  // of the swing

double WidestUnread(const Eigen::VectorXd& u) {
  std::vector<double> sorted(u.data(), u.data() + u.size());
  sorted.push_back(-1.0);
  sorted.push_back(1.0);
  std::sort(sorted.begin(), sorted.end());
  double widest = 0.0;
  for (std::size_t i = 1; i < sorted.size(); ++i)
    widest = std::max(widest, sorted[i] - sorted[i - 1]);
  return widest;
}

// How much further off its samples (RMS) a monotone lower order may be than
// the best order, where that one bends through the reading's own errors
// (FitCurve's systematic look).
constexpr double kSystematicRmsRise = 1.25;

// The coefficients padded with zeros to `terms` (a lower order's curve in a
// higher order's terms).
Eigen::VectorXd Padded(const Eigen::VectorXd& coefficients, Eigen::Index terms) {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(terms);
  out.head(coefficients.size()) = coefficients;
  return out;
}

// `second_look`: a best order that turns over only where no sample is,
// within its band (TurnsOnlyWhereUnread), may give way to the first lower
// order whose curve is monotone, its band widened to cover both.
// `systematic_look`: so may one that bends through the reading's own errors
// (kSystematicRmsRise), a last look at every sample, once nothing was found
// to leave out.
CurveFit FitCurve(const SwingSamples& samples, int max_order, double release_x,
                  const CalibrationOptions& options, double shared_sigma_volts,
                  bool second_look = false, bool systematic_look = false) {
  const Eigen::Index n = samples.size();
  const Eigen::MatrixXd& basis = samples.basis;
  const Eigen::VectorXd &v = samples.v, &weight = samples.weight;
  CurveFit out;
  std::vector<OrderFit> fits;
  for (int order = 1; order <= max_order; ++order) {
    fits.push_back(FitOrder(basis, v, weight, order));
    out.bic.push_back(fits.back().bic);
  }
  // The order the BIC prefers, unless its curve is not monotone over the
  // swing (the conversion would be ambiguous) while a lower order's is (the
  // first in the BIC's ranking) and fits the samples as well as the data can
  // tell: a photocell's output is monotone in X, and where the trace has a
  // gap a high order can wiggle there or at its ends and still fit the
  // samples best. A cell that truly folds back is refused: no monotone order
  // fits it.
  std::vector<int> by_bic(fits.size());
  for (std::size_t i = 0; i < fits.size(); ++i) by_bic[i] = static_cast<int>(i);
  std::stable_sort(by_bic.begin(), by_bic.end(),
                   [&](int a, int b) { return fits[a].bic < fits[b].bic; });
  const auto weighted_residual_of = [&](int index) -> Eigen::VectorXd {
    return weight.cwiseProduct(v - basis.leftCols(index + 2) * fits[index].coefficients);
  };
  // The band from the residuals as they are: correlated along the trace.
  const auto inflation_of_residual = [](const Eigen::VectorXd& weighted_residual) {
    return CorrelationInflation(
        {weighted_residual.data(), static_cast<std::size_t>(weighted_residual.size())});
  };
  const auto inflation_of = [&](int index) {
    return inflation_of_residual(weighted_residual_of(index));
  };
  // The band: least squares' (inflated), widened where the curve moves more
  // than that says when an inner tenth of the trace is left out (curve_band.h), plus
  // the error every sample shares (a constant in volts: T_0 = 1 everywhere).
  constexpr int kJackknifeBlocks = 10;
  const auto band_of = [&](int index, double inflation) -> Eigen::MatrixXd {
    const Eigen::MatrixXd weighted_basis = weight.asDiagonal() * basis.leftCols(index + 2);
    return curve_band::Widened(fits[index].covariance * inflation,
                               curve_band::BlockJackknifeCovariance(
                                   weighted_basis, weight.cwiseProduct(v), kJackknifeBlocks));
  };
  const auto curve_from = [&](std::vector<double> coefficients, Eigen::MatrixXd band,
                              const Eigen::MatrixXd& inflated) {
    band(0, 0) += shared_sigma_volts * shared_sigma_volts;
    std::vector<double> covariance(band.data(), band.data() + band.size());
    std::vector<double> fit_covariance(inflated.data(), inflated.data() + inflated.size());
    return PhotocellCurve(release_x, std::move(coefficients), std::move(covariance),
                          options.range_margin, std::move(fit_covariance));
  };
  const auto curve_of = [&](int index, double inflation) {
    const OrderFit& fit = fits[index];
    return curve_from(std::vector<double>(fit.coefficients.data(),
                                          fit.coefficients.data() + fit.coefficients.size()),
                      band_of(index, inflation), fit.covariance * inflation);
  };
  const int best = by_bic.front();
  out.best_weighted_residual = weighted_residual_of(best);
  const double best_inflation = inflation_of_residual(out.best_weighted_residual);
  out.curve = curve_of(best, best_inflation);
  out.correlation_inflation = best_inflation;
  out.ok = true;
  if (std::optional<std::string> problem = NonMonotone(out.curve, release_x)) {
    // The residual's rise over the best order's scatter, in effective
    // samples (each inflation-many correlated ones count once), against a
    // chi-square of as many degrees of freedom as terms dropped, at 3 sigma.
    const double scatter = fits[best].rss / static_cast<double>(n - (best + 2));
    out.ok = false;
    for (const int index : by_bic) {
      if (index >= best) continue;
      const double terms = best - index;
      const double rise = (fits[index].rss - fits[best].rss) / scatter / best_inflation;
      if (rise > terms + 3.0 * std::sqrt(2.0 * terms)) continue;
      const double inflation = inflation_of(index);
      PhotocellCurve curve = curve_of(index, inflation);
      if (NonMonotone(curve, release_x)) continue;
      out.curve = std::move(curve);
      out.correlation_inflation = inflation;
      out.ok = true;
      break;
    }
    // The first lower order (in the BIC's ranking) that `may` allows and
    // whose curve is monotone, in the best order's terms and with the best
    // order's `band` widened by the two curves' difference, so that its band
    // covers both; false when there is none.
    const auto take_lower_covering_best = [&](const Eigen::MatrixXd& band, const auto& may) {
      const Eigen::VectorXd& best_c = fits[best].coefficients;
      for (const int index : by_bic) {
        if (index >= best || !may(index)) continue;
        const Eigen::Index terms = best_c.size(), own = index + 2;
        const Eigen::VectorXd c = Padded(fits[index].coefficients, terms);
        const Eigen::VectorXd difference = c - best_c;
        const double inflation = inflation_of(index);
        Eigen::MatrixXd inflated = Eigen::MatrixXd::Zero(terms, terms);
        inflated.topLeftCorner(own, own) = fits[index].covariance * inflation;
        PhotocellCurve curve = curve_from(std::vector<double>(c.data(), c.data() + terms),
                                          band + difference * difference.transpose(), inflated);
        if (NonMonotone(curve, release_x)) continue;
        out.curve = std::move(curve);
        out.correlation_inflation = inflation;
        return true;
      }
      return false;
    };
    if (!out.ok && second_look) {
      // The best order turns over only where no sample is, within its band.
      const Eigen::MatrixXd band = band_of(best, best_inflation);
      const double u_lo = basis.col(1).minCoeff(), u_hi = basis.col(1).maxCoeff();  // T_1 = u
      if (WidestUnread(basis.col(1)) < kMaxUnread * 2.0 &&
          TurnsOnlyWhereUnread(fits[best].coefficients, band, u_lo, u_hi)) {
        out.ok = take_lower_covering_best(band, [](int) { return true; });
      }
    }
    if (!out.ok && systematic_look) {
      // The best order bends through the reading's own errors: a halftone's
      // rows of dots, a bold trace's edge, the glow of its slow start, all
      // along the trace and far above the scatter each sample states, which
      // the BIC then takes for the cell's shape until a high order turns
      // over (randomised seed 2029's calibration L-0.713, a printed figure:
      // order 9 misses its samples by 4.6 mV RMS and turns at X = 0.0075
      // and 0.704, order 7 misses them by 5.6 mV and is monotone, each
      // sample's scatter 0.8 mV). A monotone lower order that misses the
      // samples by at most kSystematicRmsRise times the best's RMS is taken
      // so: a cell that truly folds back leaves any monotone curve many
      // times further off than its best order.
      const double best_rss = fits[best].rss;
      out.ok = take_lower_covering_best(band_of(best, best_inflation), [&](int index) {
        return fits[index].rss <= kSystematicRmsRise * kSystematicRmsRise * best_rss;
      });
    }
    if (!out.ok) out.reason = std::move(*problem);
  }
  return out;
}

// A misread stretch of the trace (the tracking on a mark or a scratch for a
// few milliseconds) lies far off a smooth curve through the rest, while a
// reading's own errors scatter about it: its samples' residuals exceed
// kOffCurve robust standard deviations (1.4826 times the median absolute
// residual of the samples on the curve, which such a stretch hardly moves).
constexpr double kOffCurve = 8.0, kOffCurveEdge = 3.0;
// At most this share of the swing's samples may be left out so: beyond it
// the reading itself is in doubt, not a stretch of it.
constexpr double kOffCurveMaxShare = 0.15;
// Unless what was read there is plainly another line: a hand mark or a label
// the tracking followed lies a tenth of the cell's swing in volts or more off
// the curve through the rest (its median sample), where the trace's own
// reading errors are hundredths. Then up to this share of the samples may go
// (near the release the bar is slow: a mark crossed there holds many of
// them), while it spans at most a third of the swing in X and leaves a
// twentieth of the samples or more on each side of it: the curve through
// the rest is read on both sides. At the swing's ends the curve over the
// stretch would be the fit's extrapolation, and its offset from it no
// evidence of another line.
constexpr double kMarkMaxShare = 0.4, kMarkMinOffset = 0.1;
constexpr double kMarkMaxSpan = 1.0 / 3.0, kMarkMinBeyond = 0.05;

// How far the samples in `off` lie from `curve` and where: their count, the
// median offset in volts, the first and last index and the X they span.
struct OffStretch {
  std::size_t count = 0, first = 0, last = 0;
  double median_offset_volts = 0.0, x_lo = 0.0, x_hi = 0.0;
};

OffStretch Describe(const std::vector<bool>& off, std::size_t from, std::size_t to,
                    const std::vector<double>& x, const std::vector<double>& volts,
                    const PhotocellCurve& curve, double release_x) {
  OffStretch out{0, to, from, 0.0, release_x, 0.0};
  std::vector<double> offset;
  for (std::size_t i = from; i < to; ++i) {
    if (!off[i]) continue;
    offset.push_back(std::abs(volts[i] - curve.VoltsAt(x[i])));
    out.first = std::min(out.first, i);
    out.last = i;
    out.x_lo = std::min(out.x_lo, x[i]);
    out.x_hi = std::max(out.x_hi, x[i]);
  }
  out.count = offset.size();
  if (offset.empty()) return out;
  std::nth_element(offset.begin(), offset.begin() + offset.size() / 2, offset.end());
  out.median_offset_volts = offset[offset.size() / 2];
  return out;
}

// Whether a stretch is plainly another line (kMarkMaxShare): far off the
// curve, within a third of X0, and with the curve read on both sides of it.
bool PlainlyAnotherLine(const OffStretch& stretch, std::size_t n, const PhotocellCurve& curve,
                        double release_x) {
  const auto samples = static_cast<double>(n);
  const double span_volts = std::abs(curve.VoltsAt(release_x) - curve.VoltsAt(0.0));
  if (stretch.median_offset_volts < kMarkMinOffset * span_volts) return false;
  const bool at_end = static_cast<double>(stretch.first) < kMarkMinBeyond * samples ||
                      static_cast<double>(n - 1 - stretch.last) < kMarkMinBeyond * samples;
  return !at_end && stretch.x_hi - stretch.x_lo <= kMarkMaxSpan * release_x;
}

// Whether the samples in `off` may be left out of the curve through the
// rest (`curve`): few of them, or one plainly other line, or several
// stretches of which those that are not plainly other lines are few
// together (a trace crossed by more than one mark: each is judged by its
// own offset and reach, not by the others').
// `second_look`: several stretches may be judged each by itself.
bool MayLeaveOut(const std::vector<bool>& off, const std::vector<double>& x,
                 const std::vector<double>& volts, const PhotocellCurve& curve, double release_x,
                 bool second_look) {
  const std::size_t n = off.size();
  const OffStretch all = Describe(off, 0, n, x, volts, curve, release_x);
  const auto samples = static_cast<double>(n);
  const auto count = static_cast<double>(all.count);
  if (count <= kOffCurveMaxShare * samples) return true;
  if (count > kMarkMaxShare * samples) return false;
  if (PlainlyAnotherLine(all, n, curve, release_x)) return true;
  if (!second_look) return false;
  double not_marks = 0.0;
  for (std::size_t i = 0; i < n;) {
    if (!off[i]) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < n && off[end]) ++end;
    const OffStretch run = Describe(off, i, end, x, volts, curve, release_x);
    if (!PlainlyAnotherLine(run, n, curve, release_x)) not_marks += static_cast<double>(run.count);
    i = end;
  }
  return not_marks <= kOffCurveMaxShare * samples;
}

// True where a sample's weighted residual is off the curve, its scale from
// the samples not in `off_before`.
std::vector<bool> OffCurve(const Eigen::VectorXd& weighted_residual,
                           const std::vector<bool>& off_before) {
  std::vector<double> on;
  for (Eigen::Index i = 0; i < weighted_residual.size(); ++i) {
    if (!off_before[static_cast<std::size_t>(i)]) on.push_back(std::abs(weighted_residual(i)));
  }
  std::vector<bool> off(off_before.size(), false);
  if (on.empty()) return off;
  std::nth_element(on.begin(), on.begin() + on.size() / 2, on.end());
  const double scale = 1.4826 * on[on.size() / 2];
  if (!(scale > 0.0)) return off;
  const auto r = [&](std::size_t i) { return weighted_residual(static_cast<Eigen::Index>(i)); };
  for (std::size_t i = 0; i < off.size(); ++i) off[i] = std::abs(r(i)) > kOffCurve * scale;
  // Each run grown over its neighbours that stray the same way beyond
  // kOffCurveEdge: where the tracking leaves the trace and comes back, and
  // what a curve bent towards the stretch brought nearer.
  const auto grows = [&](std::size_t from, std::size_t to) {
    return !off[to] && std::abs(r(to)) > kOffCurveEdge * scale && r(to) * r(from) > 0.0;
  };
  for (std::size_t i = 0; i < off.size(); ++i) {
    if (!off[i]) continue;
    for (std::size_t j = i; j > 0 && grows(j, j - 1); --j) off[j - 1] = true;
    std::size_t j = i;
    for (; j + 1 < off.size() && grows(j, j + 1); ++j) off[j + 1] = true;
    i = j;
  }
  // A tracking that follows a mark does so in one stretch: two runs closer
  // than the shorter is long are one, the curve bent back to the samples
  // between them.
  std::size_t previous_begin = 0, previous_end = 0;  // the last run, [begin, end)
  for (std::size_t i = 0; i < off.size();) {
    if (!off[i]) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < off.size() && off[end]) ++end;
    if (previous_end > previous_begin &&
        i - previous_end <= std::min(previous_end - previous_begin, end - i)) {
      std::fill(off.begin() + static_cast<std::ptrdiff_t>(previous_end),
                off.begin() + static_cast<std::ptrdiff_t>(i), true);
      previous_end = end;
    } else {
      previous_begin = i;
      previous_end = end;
    }
    i = end;
  }
  return off;
}

// Where the samples leave a fifth of the swing or more unread (a trace not
// seen where the bar is fast, or lost behind a mark), the curve there is
// the fit's guess: said, with the widest such stretch, after the reason a
// curve was refused. Empty otherwise.
std::string UnreadStretch(std::vector<double> x, double release_x) {
  x.push_back(0.0);
  x.push_back(release_x);
  std::sort(x.begin(), x.end());
  std::size_t widest = 0;
  for (std::size_t i = 1; i < x.size(); ++i) {
    if (x[i] - x[i - 1] > x[widest + 1] - x[widest]) widest = i - 1;
  }
  const double gap = x[widest + 1] - x[widest];
  if (gap < kMaxUnread * release_x) return {};
  return fmt::format(
      "; the trace's samples leave X = {:.4g} .. {:.4g} unread ({:.0f} % of the swing), where "
      "no curve is determined",
      x[widest], x[widest + 1], 100.0 * gap / release_x);
}

// A calibration that could not be made, and why (the rest unset).
CalibrationResult Refusal(std::string reason) {
  CalibrationResult out;
  out.reason = std::move(reason);
  return out;
}

}  // namespace

CalibrationResult CalibratePhotocell(const Trace& trace, const Pendulum& pendulum, double release_x,
                                     const CalibrationOptions& options, double shared_sigma_volts) {
  std::string error;
  if (!options.Check(&error)) throw std::invalid_argument(error);
  // The first swing: release to the equilibrium crossing, a quarter period.
  const double quarter_period = 0.5 * HalfPeriod(pendulum, release_x);
  CalibrationResult out;
  std::vector<double> sigma;
  for (std::size_t i = 0; i < trace.time_s.size(); ++i) {
    const double t = trace.time_s[i];
    if (t < options.skip_after_release_s || t > quarter_period) continue;
    out.time_s.push_back(t);
    out.ideal_displacement.push_back(ReleaseSwingDisplacement(pendulum, release_x, t));
    out.volts.push_back(trace.volts[i]);
    sigma.push_back(trace.sigma_volts.empty() ? 1.0 : trace.sigma_volts[i]);
  }
  const int n = static_cast<int>(out.volts.size());
  if (n < 8) {
    return Refusal(
        fmt::format("the calibration trace has {} samples in the first swing "
                    "(0 .. {:.4g} s); at least 8 are needed",
                    n, quarter_period));
  }

  const int max_order = std::min(options.max_order, n / 4);
  SwingSamples samples{Eigen::MatrixXd(n, max_order + 1), Eigen::VectorXd(n), Eigen::VectorXd(n)};
  Eigen::VectorXd row(max_order + 1);
  for (int i = 0; i < n; ++i) {
    Chebyshev(ToUnit(out.ideal_displacement[i], release_x), max_order, row);
    samples.basis.row(i) = row.transpose();
    samples.v(i) = out.volts[i];
    samples.weight(i) = 1.0 / sigma[i];
  }
  CurveFit fit = FitCurve(samples, max_order, release_x, options, shared_sigma_volts);
  // No monotone curve fits every sample: one through the rest, when the
  // ones that prevent it are a misread stretch (OffCurve), which is left out
  // and recorded. A curve bent towards the stretch hides part of it, so the
  // samples off each refitted curve are taken in turn, while they change.
  const auto leave_out_stretch =
      [&](const Eigen::VectorXd& weighted_residual,
          bool second_look) -> std::optional<std::pair<std::vector<bool>, CurveFit>> {
    std::vector<bool> off = OffCurve(weighted_residual, std::vector<bool>(n, false));
    CurveFit refit;
    bool settled = false;
    for (int pass = 0; pass < 6 && !settled; ++pass) {
      std::vector<Eigen::Index> kept;
      for (int i = 0; i < n; ++i) {
        if (!off[static_cast<std::size_t>(i)]) kept.push_back(i);
      }
      const auto left_out = static_cast<double>(n) - static_cast<double>(kept.size());
      if (left_out == 0.0 || left_out > kMarkMaxShare * n || kept.size() < 8) break;
      refit = FitCurve(Rows(samples, kept), std::min(max_order, static_cast<int>(kept.size()) / 4),
                       release_x, options, shared_sigma_volts, second_look);
      // Off the curve fitted to the rest (the BIC's, where none is monotone).
      Eigen::VectorXd residual(n);
      for (int i = 0; i < n; ++i) {
        residual(i) =
            samples.weight(i) * (samples.v(i) - refit.curve.VoltsAt(out.ideal_displacement[i]));
      }
      std::vector<bool> next = OffCurve(residual, off);
      settled = next == off;
      off = std::move(next);
    }
    if (!(refit.ok && settled &&
          MayLeaveOut(off, out.ideal_displacement, out.volts, refit.curve, release_x,
                      second_look))) {
      return std::nullopt;
    }
    return std::make_pair(std::move(off), std::move(refit));
  };
  // A stretch the curve follows closely enough to hide it, or that makes
  // the whole curve ring about it (so that the residuals' robust scale grows
  // and no sample stands out), shows against a curve through the other
  // samples. The stretch is one run of samples in time (the tracking on a
  // mark): runs of one to eight twentieths of the swing's samples (a mark
  // crossed near the release holds many), the shortest first, each left out
  // in turn; the first whose curve through the rest is monotone starts the
  // search above, which judges what it leaves out (MayLeaveOut).
  const auto leave_out_a_run =
      [&](bool second_look) -> std::optional<std::pair<std::vector<bool>, CurveFit>> {
    constexpr int kBlocks = 20;
    if (n < 4 * kBlocks) return std::nullopt;
    const int max_blocks = static_cast<int>(kMarkMaxShare * kBlocks);
    for (int length = 1; length <= max_blocks; ++length) {
      for (int first = 0; first + length <= kBlocks; ++first) {
        const int begin = n * first / kBlocks, end = n * (first + length) / kBlocks;
        std::vector<Eigen::Index> kept;
        for (int i = 0; i < n; ++i) {
          if (i < begin || i >= end) kept.push_back(i);
        }
        const CurveFit rest =
            FitCurve(Rows(samples, kept), std::min(max_order, static_cast<int>(kept.size()) / 4),
                     release_x, options, shared_sigma_volts, second_look);
        if (!rest.ok) continue;
        Eigen::VectorXd residual(n);
        for (int i = 0; i < n; ++i) {
          residual(i) =
              samples.weight(i) * (samples.v(i) - rest.curve.VoltsAt(out.ideal_displacement[i]));
        }
        if (auto found = leave_out_stretch(residual, second_look)) return found;
      }
    }
    return std::nullopt;
  };
  if (!fit.ok) {
    auto left_out = leave_out_stretch(fit.best_weighted_residual, false);
    if (!left_out) left_out = leave_out_a_run(false);
    // A second look, only where the first found no curve (so that nothing
    // it found changes): a turn where no sample is and within the curve's
    // band is no fold (FitCurve), and a trace crossed by several marks has
    // each judged by itself (MayLeaveOut).
    if (!left_out) {
      CurveFit second = FitCurve(samples, max_order, release_x, options, shared_sigma_volts, true);
      if (second.ok) {
        fit = std::move(second);
      } else {
        left_out = leave_out_stretch(second.best_weighted_residual, true);
        if (!left_out) left_out = leave_out_a_run(true);
      }
    }
    if (left_out) {
      const std::vector<bool>& off = left_out->first;
      for (int i = 0; i < n; ++i) {
        if (!off[static_cast<std::size_t>(i)]) continue;
        if (i == 0 || !off[static_cast<std::size_t>(i - 1)]) {
          out.left_out_s.push_back({out.time_s[i], out.time_s[i]});
        }
        out.left_out_s.back()[1] = out.time_s[i];
      }
      const auto keep = [&](std::vector<double>& values) {
        std::vector<double> kept_values;
        for (int i = 0; i < n; ++i) {
          if (!off[static_cast<std::size_t>(i)]) kept_values.push_back(values[i]);
        }
        values = std::move(kept_values);
      };
      keep(out.time_s);
      keep(out.ideal_displacement);
      keep(out.volts);
      fit = std::move(left_out->second);
    }
  }
  if (!fit.ok) {
    // Last, the whole swing again: its best order may bend through the
    // reading's systematic errors rather than a misread stretch.
    // (The second look's own rule failed on these samples already.)
    CurveFit last =
        FitCurve(samples, max_order, release_x, options, shared_sigma_volts, false, true);
    if (last.ok) fit = std::move(last);
  }
  if (!fit.ok) return Refusal(fit.reason + UnreadStretch(out.ideal_displacement, release_x));
  out.curve = std::move(fit.curve);
  out.correlation_inflation = fit.correlation_inflation;
  out.bic = std::move(fit.bic);

  const std::size_t used = out.volts.size();
  double sum_v = 0.0, sum_x = 0.0;
  for (std::size_t i = 0; i < used; ++i) {
    const double r = out.volts[i] - out.curve.VoltsAt(out.ideal_displacement[i]);
    out.residual_volts.push_back(r);
    sum_v += r * r;
    const double rx = r / out.curve.SlopeAt(out.ideal_displacement[i]);
    sum_x += rx * rx;
  }
  out.samples_used = static_cast<int>(used);
  out.residual_rms_volts = std::sqrt(sum_v / static_cast<double>(used));
  out.residual_rms_length = std::sqrt(sum_x / static_cast<double>(used));
  out.ok = true;
  return out;
}

}  // namespace impactlab
