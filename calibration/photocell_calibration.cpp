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
    return {.ok = false,
            .reason = fmt::format("the calibration trace has {} samples in the first swing "
                                  "(0 .. {:.4g} s); at least 8 are needed",
                                  n, quarter_period)};
  }

  const int max_order = std::min(options.max_order, n / 4);
  Eigen::MatrixXd basis(n, max_order + 1);
  Eigen::VectorXd v(n), weight(n);
  Eigen::VectorXd row(max_order + 1);
  for (int i = 0; i < n; ++i) {
    Chebyshev(ToUnit(out.ideal_displacement[i], release_x), max_order, row);
    basis.row(i) = row.transpose();
    v(i) = out.volts[i];
    weight(i) = 1.0 / sigma[i];
  }
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
  // The band from the residuals as they are: correlated along the trace.
  const auto inflation_of = [&](int index) {
    const Eigen::VectorXd weighted_residual =
        weight.cwiseProduct(v - basis.leftCols(index + 2) * fits[index].coefficients);
    return CorrelationInflation(
        {weighted_residual.data(), static_cast<std::size_t>(weighted_residual.size())});
  };
  // The band: least squares' (inflated), widened where the curve moves more
  // than that says when an inner tenth of the trace is left out (curve_band.h), plus
  // the error every sample shares (a constant in volts: T_0 = 1 everywhere).
  constexpr int kJackknifeBlocks = 10;
  const auto curve_of = [&](int index, double inflation) {
    const OrderFit& fit = fits[index];
    std::vector<double> coefficients(fit.coefficients.data(),
                                     fit.coefficients.data() + fit.coefficients.size());
    const Eigen::MatrixXd weighted_basis = weight.asDiagonal() * basis.leftCols(index + 2);
    Eigen::MatrixXd band = curve_band::Widened(
        fit.covariance * inflation, curve_band::BlockJackknifeCovariance(
                                        weighted_basis, weight.cwiseProduct(v), kJackknifeBlocks));
    band(0, 0) += shared_sigma_volts * shared_sigma_volts;
    std::vector<double> covariance(band.data(), band.data() + band.size());
    const Eigen::MatrixXd inflated = fit.covariance * inflation;
    std::vector<double> fit_covariance(inflated.data(), inflated.data() + inflated.size());
    return PhotocellCurve(release_x, std::move(coefficients), std::move(covariance),
                          options.range_margin, std::move(fit_covariance));
  };
  const int best = by_bic.front();
  const double best_inflation = inflation_of(best);
  out.curve = curve_of(best, best_inflation);
  out.correlation_inflation = best_inflation;
  if (std::optional<std::string> problem = NonMonotone(out.curve, release_x)) {
    // The residual's rise over the best order's scatter, in effective
    // samples (each inflation-many correlated ones count once), against a
    // chi-square of as many degrees of freedom as terms dropped, at 3 sigma.
    const double scatter = fits[best].rss / static_cast<double>(n - (best + 2));
    bool found = false;
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
      found = true;
      break;
    }
    if (!found) return {.ok = false, .reason = std::move(*problem)};
  }

  double sum_v = 0.0, sum_x = 0.0;
  for (int i = 0; i < n; ++i) {
    const double r = out.volts[i] - out.curve.VoltsAt(out.ideal_displacement[i]);
    out.residual_volts.push_back(r);
    sum_v += r * r;
    const double rx = r / out.curve.SlopeAt(out.ideal_displacement[i]);
    sum_x += rx * rx;
  }
  out.samples_used = n;
  out.residual_rms_volts = std::sqrt(sum_v / n);
  out.residual_rms_length = std::sqrt(sum_x / n);
  out.ok = true;
  return out;
}

}  // namespace impactlab
