#include "fit/secant_covariance.h"

#include <cmath>
#include <cstddef>

namespace impactlab {

SecantCovariance SecantCovarianceAt(const Eigen::VectorXd& x, const Eigen::MatrixXd& jacobian,
                                    const ResidualsAtPoints& residuals_at,
                                    const SecantCovarianceOptions& options) {
  const Eigen::Index p = x.size();
  SecantCovariance out;
  out.covariance = Eigen::MatrixXd::Zero(p, p);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(jacobian, Eigen::ComputeThinV);
  out.directions = svd.matrixV();
  out.singular_values = svd.singularValues();
  const Eigen::VectorXd& s = out.singular_values;
  const auto size = static_cast<std::size_t>(p);
  out.determined.assign(size, false);
  out.sigma_ratios.assign(size, 0.0);
  out.steps.assign(size, 0.0);
  out.secant_failed.assign(size, false);

  std::vector<Eigen::Index> used;  // the determined directions
  for (Eigen::Index i = 0; i < s.size(); ++i) {
    const double ratio = s(0) > 0.0 ? s(i) / s(0) : 0.0;
    if (ratio >= options.undetermined_ratio && s(i) > 0.0) {
      out.determined[static_cast<std::size_t>(i)] = true;
      used.push_back(i);
    }
  }
  if (used.empty()) return out;
  const auto d = static_cast<Eigen::Index>(used.size());
  Eigen::MatrixXd basis(p, d);
  for (Eigen::Index k = 0; k < d; ++k) basis.col(k) = out.directions.col(used[k]);

  // Each direction's response, J v until its secants replace it; the first
  // steps from the Jacobian's sigma along it, 1 / s.
  Eigen::MatrixXd secants = jacobian * basis;
  std::vector<double> step(used.size()), evaluated(used.size(), 0.0);
  for (Eigen::Index k = 0; k < d; ++k) {
    const auto i = static_cast<std::size_t>(used[k]);
    const bool given = i < options.first_steps.size() && options.first_steps[i] > 0.0;
    step[k] = given ? options.first_steps[i] : options.step_in_sigmas / s(used[k]);
  }
  std::vector<bool> stale(used.size(), true), failed(used.size(), false);
  Eigen::MatrixXd rotated;  // the covariance in the directions' coordinates
  for (int round = 0; round < options.max_rounds; ++round) {
    std::vector<Eigen::VectorXd> points;
    std::vector<Eigen::Index> asked;
    for (Eigen::Index k = 0; k < d; ++k) {
      if (!stale[k]) continue;
      points.push_back(x + step[k] * basis.col(k));
      points.push_back(x - step[k] * basis.col(k));
      asked.push_back(k);
    }
    if (points.empty()) break;
    const std::vector<std::optional<Eigen::VectorXd>> r = residuals_at(points);
    out.evaluations += static_cast<int>(points.size());
    ++out.rounds;
    for (std::size_t a = 0; a < asked.size(); ++a) {
      const Eigen::Index k = asked[a];
      const std::optional<Eigen::VectorXd>& up = r[2 * a];
      const std::optional<Eigen::VectorXd>& down = r[2 * a + 1];
      if (up && down && up->size() == jacobian.rows() && down->size() == jacobian.rows()) {
        secants.col(k) = (*up - *down) / (2.0 * step[k]);
        evaluated[k] = step[k];
      } else {
        // A point the model cannot take: the Jacobian's response stays.
        secants.col(k) = jacobian * basis.col(k);
        failed[k] = true;
      }
    }
    // (A^T A)^-1 through A's own decomposition: the secants of two
    // directions may come out nearly parallel, and then their sigma is large,
    // not a numerical accident of forming A^T A.
    const Eigen::JacobiSVD<Eigen::MatrixXd> secant_svd(secants, Eigen::ComputeThinV);
    const Eigen::VectorXd& sa = secant_svd.singularValues();
    Eigen::VectorXd inverse_square = Eigen::VectorXd::Zero(d);
    for (Eigen::Index k = 0; k < d; ++k) {
      if (sa(k) > 0.0) inverse_square(k) = 1.0 / (sa(k) * sa(k));
    }
    rotated = secant_svd.matrixV() * inverse_square.asDiagonal() * secant_svd.matrixV().transpose();
    bool settled = true;
    for (Eigen::Index k = 0; k < d; ++k) {
      stale[k] = false;
      if (failed[k]) continue;
      const double wanted = options.step_in_sigmas * std::sqrt(rotated(k, k));
      if (std::abs(step[k] - wanted) > options.step_tolerance * wanted) {
        step[k] = wanted;
        stale[k] = true;
        settled = false;
      }
    }
    if (settled) break;
  }
  out.covariance = basis * rotated * basis.transpose();
  out.basis = basis;
  out.secants = secants;
  for (Eigen::Index k = 0; k < d; ++k) {
    const auto i = static_cast<std::size_t>(used[k]);
    out.sigma_ratios[i] = std::sqrt(rotated(k, k)) * s(used[k]);
    out.steps[i] = evaluated[k];
    out.secant_failed[i] = failed[k];
  }
  return out;
}

Eigen::MatrixXd SecantSandwich(const SecantCovariance& secant, const Eigen::VectorXd& row_scale,
                               const Eigen::MatrixXd& meat) {
  const Eigen::Index p = secant.directions.rows(), d = secant.basis.cols();
  if (d == 0) return Eigen::MatrixXd::Zero(p, p);
  const Eigen::MatrixXd a =
      row_scale.size() == 0 ? secant.secants : row_scale.asDiagonal() * secant.secants;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinV);
  Eigen::VectorXd inverse_square = Eigen::VectorXd::Zero(d);
  for (Eigen::Index k = 0; k < d; ++k) {
    const double sk = svd.singularValues()(k);
    if (sk > 0.0) inverse_square(k) = 1.0 / (sk * sk);
  }
  const Eigen::MatrixXd bread =
      svd.matrixV() * inverse_square.asDiagonal() * svd.matrixV().transpose();
  return secant.basis * (bread * meat * bread) * secant.basis.transpose();
}

Eigen::VectorXd SecantStep(const SecantCovariance& secant, const Eigen::VectorXd& residuals,
                           const Eigen::VectorXd& row_scale) {
  const Eigen::Index p = secant.directions.rows();
  if (secant.basis.cols() == 0) return Eigen::VectorXd::Zero(p);
  const Eigen::MatrixXd a =
      row_scale.size() == 0 ? secant.secants : row_scale.asDiagonal() * secant.secants;
  // Least squares through A's own decomposition, as for the covariance.
  const Eigen::VectorXd along =
      a.jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(-residuals);
  return secant.basis * along;
}

}  // namespace impactlab
