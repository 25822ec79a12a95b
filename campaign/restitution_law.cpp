#include "campaign/restitution_law.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "model/hunt_crossley_terms.h"
#include "model/power_law_contact.h"

namespace impactlab {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// An impact the fit can weigh.
bool Weighable(const ImpactRestitution& i) {
  return i.speed > 0.0 && std::isfinite(i.speed) && i.restitution > 0.0 &&
         std::isfinite(i.restitution) && i.speed_relative_sigma > 0.0 &&
         std::isfinite(i.speed_relative_sigma) && i.rebound_speed_relative_sigma > 0.0 &&
         std::isfinite(i.rebound_speed_relative_sigma);
}

// The residuals' covariance at the law's current slopes g_k = d ln e/d ln v:
// r_k = ln v_{n+1} - ln v_n - ln e(v_n) moves by -(1 + g_k) with ln v_n and
// by +1 with ln v_{n+1}; the next impact of the run shares v_{n+1}.
MatrixXd ResidualCovariance(const std::vector<ImpactRestitution>& impacts, const VectorXd& g) {
  const auto n = static_cast<Eigen::Index>(impacts.size());
  MatrixXd v = MatrixXd::Zero(n, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const ImpactRestitution& i = impacts[static_cast<std::size_t>(k)];
    const double before = (1.0 + g[k]) * i.speed_relative_sigma;
    const double after = i.rebound_speed_relative_sigma;
    v(k, k) = before * before + after * after;
    for (Eigen::Index j = 0; j < n; ++j) {
      const ImpactRestitution& next = impacts[static_cast<std::size_t>(j)];
      if (next.run == i.run && next.rebound == i.rebound + 1) {
        v(k, j) = v(j, k) = -(1.0 + g[j]) * after * after;
      }
    }
  }
  return v;
}

}  // namespace

LogRestitutionAtSpeed RestitutionLawAt(double log_eps_ref, double exponent,
                                       double log_speed_ratio) {
  const double eps = std::exp(log_eps_ref + exponent * log_speed_ratio);
  const hunt_crossley::Exit exit = hunt_crossley::ExitOf(eps);
  const double e = exit.restitution;
  // de/deps by the implicit-function theorem (model/hunt_crossley_terms.h);
  // -2/3 where eps is too small for the difference to be exact.
  const double de = eps > 1e-6 ? (exit.gap / ((1.0 + eps) * e) - e) / eps : -2.0 / 3.0;
  const double d_log = de * eps / e;  // d ln e / d ln eps
  return {std::log(e), d_log, d_log * log_speed_ratio};
}

SessionRestitutionLaw FitRestitutionLaw(const std::vector<ImpactRestitution>& all,
                                        const RestitutionLawOptions& options) {
  SessionRestitutionLaw law;
  std::vector<ImpactRestitution> impacts;
  std::copy_if(all.begin(), all.end(), std::back_inserter(impacts), Weighable);
  law.impacts = static_cast<int>(impacts.size());
  if (impacts.size() < 3) {
    law.reason = fmt::format(
        "{} impact(s) with a speed, a restitution and the maxima's errors: the law needs 3",
        impacts.size());
    return law;
  }
  const auto n = static_cast<Eigen::Index>(impacts.size());
  double mean_log_speed = 0.0;
  for (const ImpactRestitution& i : impacts) mean_log_speed += std::log(i.speed);
  mean_log_speed /= static_cast<double>(n);
  law.reference_speed = std::exp(mean_log_speed);
  VectorXd x(n), y(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const ImpactRestitution& i = impacts[static_cast<std::size_t>(k)];
    x[k] = std::log(i.speed) - mean_log_speed;
    y[k] = std::log(i.restitution);
  }

  // Start from Hunt-Crossley (beta = 1) through the impacts' mean eps.
  double log_eps_sum = 0.0;
  int inverted = 0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double e = std::exp(y[k]);
    if (e >= 1.0) continue;
    log_eps_sum += std::log(DampingFactorFor(e, 1.0, DampingFactorConvention::kExact)) - x[k];
    ++inverted;
  }
  if (inverted == 0) {
    law.reason = "every impact keeps its whole speed (e >= 1): no damping to fit a law to";
    return law;
  }
  Eigen::Vector2d theta(log_eps_sum / inverted, 1.0);

  // Gauss-Newton, the covariance taken at the current slopes (effective
  // variance); halving a step that raises chi^2.
  const auto evaluate = [&](const Eigen::Vector2d& t, VectorXd* r, MatrixXd* j, VectorXd* g) {
    r->resize(n), j->resize(n, 2), g->resize(n);
    for (Eigen::Index k = 0; k < n; ++k) {
      const LogRestitutionAtSpeed at = RestitutionLawAt(t[0], t[1], x[k]);
      (*r)[k] = y[k] - at.value;
      (*j)(k, 0) = at.d_log_eps, (*j)(k, 1) = at.d_exponent;
      (*g)[k] = at.d_log_eps * t[1];
    }
  };
  VectorXd r, g;
  MatrixXd j, information;
  Eigen::LLT<MatrixXd> cholesky;
  double chi2 = 0.0;
  bool converged = false;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    evaluate(theta, &r, &j, &g);
    cholesky.compute(ResidualCovariance(impacts, g));
    if (cholesky.info() != Eigen::Success) {
      law.reason = "the impacts' covariance is not positive definite";
      return law;
    }
    const MatrixXd wj = cholesky.matrixL().solve(j);
    const VectorXd wr = cholesky.matrixL().solve(r);
    chi2 = wr.squaredNorm();
    information = wj.transpose() * wj;
    const Eigen::SelfAdjointEigenSolver<MatrixXd> eigen(information);
    if (!(eigen.eigenvalues().minCoeff() >
          options.min_relative_eigenvalue * eigen.eigenvalues().maxCoeff())) {
      law.reason = "the impacts' speeds do not fix the law's exponent (too narrow a range)";
      return law;
    }
    Eigen::Vector2d step = information.ldlt().solve(wj.transpose() * wr);
    // Converged when the step is a negligible fraction of the error (1e-5
    // sigma): chi^2 then changes by less than its rounding.
    if (step.dot(information * step) < 1e-10) {
      converged = true;
      break;
    }
    for (int halving = 0; halving < 30; ++halving) {
      VectorXd r_try, g_try;
      MatrixXd j_try;
      evaluate(theta + step, &r_try, &j_try, &g_try);
      if (r_try.allFinite() &&
          cholesky.matrixL().solve(r_try).squaredNorm() <= chi2 * (1.0 + 1e-12)) {
        break;
      }
      step *= 0.5;
    }
    theta += step;
  }
  if (!converged) {
    law.reason = fmt::format("did not converge in {} iterations", options.max_iterations);
    return law;
  }
  const Eigen::Matrix2d covariance = information.inverse();
  law.ok = true;
  law.log_eps = theta[0];
  law.exponent = theta[1];
  const double off_diagonal = 0.5 * (covariance(0, 1) + covariance(1, 0));  // exactly symmetric
  law.covariance = {covariance(0, 0), off_diagonal, off_diagonal, covariance(1, 1)};
  law.chi2 = chi2;
  law.dof = static_cast<int>(n) - 2;
  return law;
}

}  // namespace impactlab
