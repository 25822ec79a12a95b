#include "fit/kelvin_voigt_least_squares.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>

#include "fit/least_squares_internal.h"
#include "fit/uncertainty.h"
#include "model/kelvin_voigt.h"

namespace impactlab {
namespace {

using fit_internal::AmplitudeAndSlope;

// (A(exp(w + n q)) - X)/sigma for theta = (q, w) = (ln e, ln v0).
class KelvinVoigtMaximumCost final : public ceres::SizedCostFunction<1, 2> {
 public:
  KelvinVoigtMaximumCost(const Pendulum& pendulum, int rebound, double measured, double sigma)
      : pendulum_(pendulum), n_(rebound), measured_(measured), sigma_(sigma) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double q = parameters[0][0], w = parameters[0][1];
    const double speed = std::exp(w + n_ * q);
    if (!std::isfinite(speed)) return false;
    fit_internal::AmplitudeSlope a;
    try {
      a = AmplitudeAndSlope(pendulum_, speed);
    } catch (const std::domain_error&) {
      return false;  // past the horizontal: an infeasible step, Ceres shrinks it
    }
    residuals[0] = (a.amplitude - measured_) / sigma_;
    if (jacobians && jacobians[0]) {
      const double d_speed = a.slope * speed / sigma_;  // dr/d(ln v)
      jacobians[0][0] = d_speed * n_;
      jacobians[0][1] = d_speed;
    }
    return true;
  }

 private:
  Pendulum pendulum_;
  int n_;
  double measured_, sigma_;
};

// zeta from ln e < 0 and d zeta / d ln e: kinematic in closed form
// (zeta = -q/sqrt(q^2 + pi^2)); force as the inverse of the slope of
// ln e(zeta) = -2 zeta h(zeta), by a central difference (smooth, monotone).
void DampingRatioAndSlope(double log_e, Separation separation, double* zeta, double* slope) {
  *zeta = DampingRatioFromLogRestitution(log_e, separation);
  if (separation == Separation::kKinematic) {
    const double pi2 = std::numbers::pi * std::numbers::pi;
    *slope = -pi2 / std::pow(log_e * log_e + pi2, 1.5);
    return;
  }
  const double h = 1e-6 * *zeta;
  *slope = 2.0 * h /
           (LogRestitutionFromDampingRatio(*zeta + h, separation) -
            LogRestitutionFromDampingRatio(*zeta - h, separation));
}

}  // namespace

bool KelvinVoigtLeastSquaresOptions::Check(std::string* why) const {
  return loss.Check(why) && solver.Check(why) &&
         fit_internal::CheckRelativeSingularValue(min_relative_singular_value, why);
}

KelvinVoigtLeastSquaresFit FitKelvinVoigtLeastSquares(
    const Pendulum& pendulum, double mass, const ReboundMeasurements& measured,
    const KelvinVoigtLeastSquaresOptions& options) {
  const fit_internal::Stopwatch stopwatch;
  if (std::string why; !options.Check(&why)) throw std::invalid_argument(why);
  if (!(mass > 0.0)) throw std::invalid_argument(fmt::format("mass must be > 0, got {}", mass));
  KelvinVoigtLeastSquaresFit fit;
  fit.separation = options.separation;
  // Data the fit cannot take: a fit that did not run, with why.
  const auto refuse = [&](std::string why) {
    fit.reason = std::move(why);
    return fit;
  };
  bool weighted = false;
  std::string refusal;
  const std::vector<double> sigmas =
      fit_internal::MaximumSigmas(measured.xmax, measured.xmax_sigma, &weighted, &refusal);
  if (!refusal.empty()) return refuse(refusal);
  std::vector<int> used;
  for (std::size_t i = 0; i < measured.xmax.size(); ++i) {
    const double x = measured.xmax[i];
    if (std::isnan(x)) continue;  // not read
    if (!(x > 0.0) || !std::isfinite(x)) {
      return refuse(fmt::format("rebound {} maximum must be > 0, got {}", i, x));
    }
    if (std::string beyond = SwingAmplitudeProblem(pendulum, x); !beyond.empty()) {
      return refuse(beyond);
    }
    used.push_back(static_cast<int>(i));
  }
  if (used.size() < 2) {
    return refuse(
        fmt::format("a least-squares fit needs at least two maxima, got {}", used.size()));
  }
  if (measured.contact_time && !(*measured.contact_time > 0.0)) {
    return refuse(fmt::format("contact time must be > 0, got {}", *measured.contact_time));
  }

  fit.dof = static_cast<int>(used.size()) - 2;

  // Start from the first and last maxima used (the two-point estimate).
  const int first = used.front(), last = used.back();
  const double v_first =
      SpeedFromAmplitude(pendulum, measured.xmax[static_cast<std::size_t>(first)]);
  const double v_last = SpeedFromAmplitude(pendulum, measured.xmax[static_cast<std::size_t>(last)]);
  double theta[2];
  theta[0] = std::log(v_last / v_first) / (last - first);
  theta[1] = std::log(v_first) - first * theta[0];

  ceres::Problem problem;
  for (const int n : used) {
    const auto i = static_cast<std::size_t>(n);
    problem.AddResidualBlock(new KelvinVoigtMaximumCost(pendulum, n, measured.xmax[i], sigmas[i]),
                             fit_internal::MakeLoss(options.loss), theta);
  }
  const auto finish = [&] {
    fit.status.seconds = stopwatch.Seconds();
    return fit;
  };
  if (!fit_internal::SolveUsable(problem, options.solver, &fit.status, &fit.reason)) {
    return finish();
  }

  // Residuals, chi^2 and the identifiability of (ln e, ln v0).
  Eigen::VectorXd r;
  const Eigen::MatrixXd j = fit_internal::Jacobian(problem, {theta}, &r);
  fit.chi2 = r.squaredNorm();
  if (weighted) fit.scatter = CheckScatter(fit.chi2, fit.dof);
  for (std::size_t k = 0; k < used.size(); ++k) {
    const auto i = static_cast<std::size_t>(used[k]);
    MaximumResidual res;
    res.rebound = used[k];
    res.measured = measured.xmax[i];
    res.sigma = sigmas[i];
    res.model = res.measured + r[static_cast<Eigen::Index>(k)] * res.sigma;
    res.normalized = -r[static_cast<Eigen::Index>(k)];
    fit.residuals.push_back(res);
  }
  fit.identifiability =
      fit_internal::Analyse(j, 2, {"ln e", "ln v0"}, options.min_relative_singular_value);
  if (!fit.identifiability.identifiable) {
    fit.identifiability.message = fmt::format(
        "not identifiable: only {} is determined",
        FormatCombination(fit.identifiability.directions[0], fit.identifiability.parameter_names));
    fit.reason = fit.identifiability.message;
    return finish();
  }
  fit.identifiability.message = "ln e and ln v0 are both determined";

  Eigen::MatrixXd cov;
  if (!fit_internal::Covariance(problem, {theta}, 0, &cov)) {
    fit.reason = "the covariance could not be computed (ill-conditioned Jacobian)";
    return finish();
  }
  // Without uncertainties, scale by s^2 = chi^2/(N - p); with no degrees of
  // freedom the scatter is unknown and the uncertainties are reported as 0.
  if (!weighted) cov *= fit.dof > 0 ? fit.chi2 / fit.dof : 0.0;
  fit.fitted_covariance = fit_internal::MakeCovariance({"ln e", "ln v0"}, cov, !weighted);

  const double q = theta[0], w = theta[1];
  const double sq = std::sqrt(cov(0, 0)), sw = std::sqrt(cov(1, 1));
  fit.log_restitution = {q, sq};
  fit.restitution = {std::exp(q), std::exp(q) * sq};
  fit.rebound0_speed = {std::exp(w), std::exp(w) * sw};
  // The model's maxima from rebound 0 on: rebounds before the first read one
  // were fitted to nothing, and their swings may pass the horizontal.
  const int count = measured.xmax.empty() ? 0 : static_cast<int>(measured.xmax.size());
  for (int n = 0; n < count; ++n) {
    if (std::string beyond = SwingSpeedProblem(pendulum, std::exp(w + n * q)); !beyond.empty()) {
      fit.reason = fmt::format("the model's rebound {}: {}", n, beyond);
      return finish();
    }
  }
  const fit_internal::AmplitudeSlope a0 = AmplitudeAndSlope(pendulum, std::exp(w));
  fit.rebound0_xmax = {a0.amplitude, a0.slope * std::exp(w) * sw};
  // The model's maxima, with sigma from the gradient of X_n in (q, w), scaled
  // by the Birge ratio where the scatter exceeds the stated sigmas: a
  // prediction must cover what the data scatter by, not what they promised.
  for (int n = 0; n < count; ++n) {
    const double v = std::exp(w + n * q);
    const fit_internal::AmplitudeSlope a = AmplitudeAndSlope(pendulum, v);
    const Eigen::Vector2d g(a.slope * v * n, a.slope * v);
    fit.predicted_xmax.push_back({a.amplitude, fit.scatter.Scale() * std::sqrt(g.dot(cov * g))});
  }

  if (!(q < 0.0)) {
    fit.reason = fmt::format(
        "the maxima show no dissipation (fitted ln e = {:.6g} >= 0): no damping ratio", q);
    return finish();
  }
  double zeta = 0.0, dzeta = 0.0;
  DampingRatioAndSlope(q, options.separation, &zeta, &dzeta);
  fit.damping_ratio = {zeta, std::abs(dzeta) * sq};
  // Covariance of (zeta, v0): J = diag(d zeta/d ln e, v0).
  Eigen::Matrix2d t = Eigen::Matrix2d::Zero();
  t(0, 0) = dzeta;
  t(1, 1) = std::exp(w);
  fit.covariance = fit_internal::MakeCovariance({"zeta", "v0"}, t * cov * t.transpose(), !weighted);

  if (measured.contact_time) {
    const double tau = *measured.contact_time;
    fit.contact_time = tau;
    const auto kc = [&](const std::vector<double>& in) {
      const double k = StiffnessFromContactTime(mass, in[1], in[0], options.separation);
      return std::vector<double>{k, 2.0 * in[0] * std::sqrt(k * mass)};
    };
    const std::vector<double> values = kc({zeta, tau});
    const std::vector<double> s = PropagateUncertainty(
        kc, {zeta, tau}, {fit.damping_ratio.sigma, measured.contact_time_sigma});
    fit.stiffness = Estimate{values[0], s[0]};
    fit.damping = Estimate{values[1], s[1]};
  }
  fit.ok = true;
  if (!weighted && fit.dof == 0) {
    fit.reason =
        "two maxima without uncertainties: the fit is exact and the scatter unknown "
        "(uncertainties reported as 0)";
  }
  return finish();
}

}  // namespace impactlab
