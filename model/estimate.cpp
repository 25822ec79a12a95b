#include "model/estimate.h"

#include <algorithm>
#include <cstddef>

#include <Eigen/Dense>

namespace impactlab {

double CorrelationInflation(std::span<const double> residual) {
  const std::size_t n = residual.size();
  double variance = 0.0;
  for (double r : residual) variance += r * r;
  if (n < 8 || !(variance > 0.0)) return 1.0;
  const std::size_t max_lag = std::min<std::size_t>(n / 4, 4096);
  double sum = 0.0;
  for (std::size_t k = 1; k <= max_lag; ++k) {
    double lagged = 0.0;
    for (std::size_t i = 0; i + k < n; ++i) lagged += residual[i] * residual[i + k];
    const double rho = lagged / variance;
    if (!(rho > 0.0)) break;
    sum += rho;
  }
  return std::max(1.0, 1.0 + 2.0 * sum);
}

std::vector<double> FitErrorAutocovariance(std::span<const double> residual,
                                           std::span<const double> jacobian, int parameters,
                                           int max_lag) {
  const auto n = static_cast<Eigen::Index>(residual.size());
  const Eigen::Index p = parameters;
  const Eigen::Index lags = std::min<Eigen::Index>(max_lag, n - p - 1);
  if (p < 1 || lags < 0 || static_cast<Eigen::Index>(jacobian.size()) != n * p) return {};
  const Eigen::Map<const Eigen::VectorXd> r(residual.data(), n);
  if (!(r.squaredNorm() > 0.0)) return {};
  // An orthonormal basis Q of the model's columns: the hat matrix is Q Q^T.
  const Eigen::Map<const Eigen::MatrixXd> j(jacobian.data(), n, p);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(j);
  const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(n, p);
  // The hat matrix H = Q Q^T enters through sums along its diagonals:
  // along[d][m] = sum over b < m of H(b + d, b), for offsets d up to twice
  // the longest lag.
  const Eigen::Index offsets = std::min<Eigen::Index>(2 * lags, n - 1);
  std::vector<std::vector<double>> along(static_cast<std::size_t>(offsets + 1));
  for (Eigen::Index d = 0; d <= offsets; ++d) {
    std::vector<double>& sums = along[d];
    sums.assign(static_cast<std::size_t>(n - d + 1), 0.0);
    for (Eigen::Index b = 0; b < n - d; ++b) sums[b + 1] = sums[b] + q.row(b + d).dot(q.row(b));
  }
  // Sum of H(b + d, b) over b < m (0 where the diagonal lies outside).
  const auto diagonal = [&](Eigen::Index d, Eigen::Index m) {
    return d <= offsets && m > 0 ? along[d][std::min(m, n - d)] : 0.0;
  };
  // L_j = sum_a Q_a Q_(a+j)^T, so that Q^T T_k Q = L_k + L_k^T (k > 0; L_0 at 0).
  std::vector<Eigen::MatrixXd> shifted(static_cast<std::size_t>(lags + 1)),
      pattern(static_cast<std::size_t>(lags + 1));
  for (Eigen::Index lag = 0; lag <= lags; ++lag) {
    shifted[lag] = q.topRows(n - lag).transpose() * q.bottomRows(n - lag);
    pattern[lag] = lag == 0 ? shifted[0] : Eigen::MatrixXd(shifted[lag] + shifted[lag].transpose());
  }
  // E[r^T S_j r] = tr(S_j M T_k M) gamma_k summed over k, with S_j picking
  // lag j's products and T_k the symmetric lag-k pattern; M = I - Q Q^T.
  Eigen::MatrixXd system(lags + 1, lags + 1);
  Eigen::VectorXd observed(lags + 1);
  for (Eigen::Index lag = 0; lag <= lags; ++lag) {
    observed(lag) = r.head(n - lag).dot(r.tail(n - lag));
    for (Eigen::Index k = 0; k <= lags; ++k) {
      // tr(S_j T_k): the products at lag j the pattern T_k holds.
      double trace = lag == k ? static_cast<double>(n - lag) : 0.0;
      // tr(S_j H T_k) + tr(S_j T_k H): H(a+j, a+k) and H(a+j-k, a) run
      // along diagonal |j - k|, H(a+j, a-k) and H(a+j+k, a) along j + k.
      if (k == 0) {
        trace -= 2.0 * diagonal(lag, n - lag);
      } else {
        const Eigen::Index apart = std::abs(lag - k), together = lag + k;
        trace -= diagonal(apart, n - apart) - diagonal(apart, std::min(lag, k));
        trace -= diagonal(apart, n - std::max(lag, k));
        trace -= 2.0 * diagonal(together, n - together);
      }
      // tr(S_j H T_k H) = tr(Q^T T_k Q L_j).
      trace += (pattern[k].array() * shifted[lag].transpose().array()).sum();
      system(lag, k) = trace;
    }
  }
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(system);
  if (!lu.isInvertible()) return {};
  const Eigen::VectorXd gamma = lu.solve(observed);
  if (!(gamma(0) > 0.0) || !gamma.allFinite()) return {};
  std::vector<double> out{gamma(0)};
  for (Eigen::Index k = 1; k <= lags && gamma(k) > 0.0; ++k) out.push_back(gamma(k));
  return out;
}

double CorrelatedVariance(std::span<const double> autocovariance, std::span<const double> h) {
  double variance = 0.0;
  for (std::size_t k = 0; k < autocovariance.size() && k < h.size(); ++k) {
    double products = 0.0;
    for (std::size_t i = 0; i + k < h.size(); ++i) products += h[i] * h[i + k];
    variance += (k == 0 ? 1.0 : 2.0) * autocovariance[k] * products;
  }
  return std::max(0.0, variance);
}

}  // namespace impactlab
