#include "campaign/shared_fit.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <Eigen/Dense>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>

namespace impactlab {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

struct Whitened {
  MatrixXd design;       // H_i
  VectorXd values;       // y_i
  MatrixXd covariance;   // C_i
  MatrixXd information;  // H_i' C_i^-1 H_i
  VectorXd weighted;     // H_i' C_i^-1 y_i
  Eigen::LLT<MatrixXd> cholesky;
};

Whitened Prepare(const SessionStatement& s, int p) {
  const auto d = static_cast<Eigen::Index>(s.values.size());
  if (d == 0 || s.covariance.size() != static_cast<std::size_t>(d * d) ||
      s.design.size() != static_cast<std::size_t>(d * p)) {
    throw std::invalid_argument("session " + s.session + ": statement of inconsistent sizes");
  }
  Whitened w;
  w.values = Eigen::Map<const VectorXd>(s.values.data(), d);
  w.covariance =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          s.covariance.data(), d, d);
  w.design =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          s.design.data(), d, p);
  w.cholesky.compute(w.covariance);
  if (w.cholesky.info() != Eigen::Success || !w.values.allFinite() || !w.covariance.allFinite()) {
    throw std::invalid_argument("session " + s.session +
                                ": its covariance is not positive definite");
  }
  w.information = w.design.transpose() * w.cholesky.solve(w.design);
  w.weighted = w.design.transpose() * w.cholesky.solve(w.values);
  return w;
}

// A^-1 b where A is well conditioned enough to fix every constant.
bool Solve(const MatrixXd& a, const VectorXd& b, VectorXd* theta, MatrixXd* inverse) {
  const Eigen::SelfAdjointEigenSolver<MatrixXd> eigen(a);
  if (eigen.info() != Eigen::Success) return false;
  const VectorXd lambda = eigen.eigenvalues();
  if (lambda.minCoeff() <= 1e-12 * std::max(lambda.maxCoeff(), 0.0)) return false;
  *inverse =
      eigen.eigenvectors() * lambda.cwiseInverse().asDiagonal() * eigen.eigenvectors().transpose();
  *theta = *inverse * b;
  return true;
}

}  // namespace

namespace {

// The fit of the sessions in `active`, and every session's pull against it:
// an active one's against the fit without it.
SharedFit FitActive(const std::vector<SessionStatement>& statements,
                    const std::vector<Whitened>& sessions, const std::vector<bool>& active, int p) {
  MatrixXd a = MatrixXd::Zero(p, p);
  VectorXd b = VectorXd::Zero(p);
  int stated = 0, count = 0;
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    if (!active[i]) continue;
    a += sessions[i].information;
    b += sessions[i].weighted;
    stated += static_cast<int>(sessions[i].values.size());
    ++count;
  }
  SharedFit fit;
  VectorXd theta;
  MatrixXd inverse;
  if (count < 2 || !Solve(a, b, &theta, &inverse)) {
    fit.reason = count < 2 ? "fewer than two sessions state these constants"
                           : "the sessions' statements do not fix every constant";
    return fit;
  }
  fit.ok = true;
  fit.values.assign(theta.data(), theta.data() + p);
  for (int i = 0; i < p; ++i) {
    for (int j = 0; j < p; ++j) fit.covariance.push_back(inverse(i, j));
    fit.sigma.push_back(std::sqrt(inverse(i, i)));
  }
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    if (!active[i]) continue;
    const VectorXd r = sessions[i].values - sessions[i].design * theta;
    fit.chi2 += r.dot(sessions[i].cholesky.solve(r));
  }
  fit.dof = stated - p;
  if (fit.dof > 0) {
    fit.birge_ratio = std::sqrt(fit.chi2 / fit.dof);
    fit.p_value = boost::math::cdf(
        boost::math::complement(boost::math::chi_squared(fit.dof), std::max(fit.chi2, 0.0)));
  }
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    const Whitened& w = sessions[i];
    VectorXd others = theta;
    MatrixXd others_inverse = inverse;
    if (active[i] && !Solve(a - w.information, b - w.weighted, &others, &others_inverse)) continue;
    const VectorXd r = w.values - w.design * others;
    const MatrixXd d = w.covariance + w.design * others_inverse * w.design.transpose();
    for (Eigen::Index k = 0; k < r.size(); ++k) {
      fit.pull_session.push_back(statements[i].session);
      fit.pull_constant.push_back(statements[i].constants.at(static_cast<std::size_t>(k)));
      fit.pull.push_back(r(k) / std::sqrt(d(k, k)));
    }
  }
  return fit;
}

}  // namespace

SharedFit FitSharedConstants(const std::vector<SessionStatement>& statements, int constants,
                             double pull_threshold) {
  std::vector<Whitened> sessions;
  for (const SessionStatement& s : statements) sessions.push_back(Prepare(s, constants));
  std::vector<bool> active(statements.size(), true);
  std::vector<std::string> set_aside;
  for (;;) {
    SharedFit fit = FitActive(statements, sessions, active, constants);
    fit.set_aside = set_aside;
    if (!fit.ok) return fit;
    // The active session farthest beyond the threshold, if any.
    std::optional<std::size_t> farthest;
    double largest = pull_threshold;
    for (std::size_t k = 0; k < fit.pull.size(); ++k) {
      const auto i =
          static_cast<std::size_t>(std::find_if(statements.begin(), statements.end(),
                                                [&](const SessionStatement& s) {
                                                  return s.session == fit.pull_session[k];
                                                }) -
                                   statements.begin());
      if (active[i] && std::abs(fit.pull[k]) > largest)
        largest = std::abs(fit.pull[k]), farthest = i;
    }
    std::vector<bool> without = active;
    if (farthest) without[*farthest] = false;
    // Set aside only while the others still fix the constants.
    if (!farthest || std::count(without.begin(), without.end(), true) < 2) return fit;
    active = without;
    set_aside.push_back(statements[*farthest].session);
  }
}

double PullThreshold(std::size_t pulls, double false_alarm) {
  if (pulls == 0) return 3.0;
  const double tail = false_alarm / (2.0 * static_cast<double>(pulls));
  const double z = boost::math::quantile(boost::math::complement(boost::math::normal(), tail));
  return std::max(3.0, z);
}

}  // namespace impactlab
