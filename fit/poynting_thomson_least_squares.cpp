#include "fit/poynting_thomson_least_squares.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "fit/least_squares_internal.h"
#include "model/kelvin_voigt.h"

namespace impactlab {
namespace {

using fit_internal::AmplitudeAndSlope;
constexpr double kInf = std::numeric_limits<double>::infinity();

// What the data see of the contact: ln e, tau_c, x_peak/v0.
struct Response {
  double log_e = 0, contact_time = 0, peak = 0;
};
using ResponseSlopes = std::array<Response, 3>;  // d/d log K1, d/d log K2, d/d log C

// The contact response at theta = (log K1, log K2, log C) and its central-
// difference derivatives, cached for the last point asked: Ceres evaluates
// every residual block at the same parameters in turn, so each point costs
// one response (seven with derivatives), not one per residual.
class ResponseModel {
 public:
  ResponseModel(double mass, Separation separation, double step)
      : mass_(mass), separation_(separation), step_(step) {}

  // False where contact never ends (kinematic) or the parameters are invalid.
  bool Value(const double* theta, Response* out) const {
    if (!Same(theta, value_theta_)) {
      std::copy(theta, theta + 3, value_theta_.begin());
      value_ok_ = Compute(value_theta_, &value_);
    }
    *out = value_;
    return value_ok_;
  }

  bool ValueAndSlopes(const double* theta, Response* out, ResponseSlopes* slopes) const {
    if (!Value(theta, out)) return false;
    if (!Same(theta, slope_theta_)) {
      std::copy(theta, theta + 3, slope_theta_.begin());
      slopes_ok_ = true;
      for (std::size_t i = 0; i < 3 && slopes_ok_; ++i) {
        std::array<double, 3> up = slope_theta_, down = slope_theta_;
        up[i] += step_;
        down[i] -= step_;
        Response hi, lo;
        slopes_ok_ = Compute(up, &hi) && Compute(down, &lo);
        slopes_[i] = {(hi.log_e - lo.log_e) / (2 * step_),
                      (hi.contact_time - lo.contact_time) / (2 * step_),
                      (hi.peak - lo.peak) / (2 * step_)};
      }
    }
    *slopes = slopes_;
    return slopes_ok_;
  }

 private:
  static bool Same(const double* a, const std::array<double, 3>& b) {
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
  }
  bool Compute(const std::array<double, 3>& theta, Response* out) const {
    try {
      const ContactResponse c = PoyntingThomsonContact(
          PoyntingThomson{mass_, std::exp(theta[0]), std::exp(theta[1]), std::exp(theta[2])}, 1.0,
          separation_);
      *out = {c.log_restitution, c.contact_time, c.peak_compression};
      return std::isfinite(c.log_restitution) && std::isfinite(c.contact_time);
    } catch (const NoSeparationError&) {
      return false;
    } catch (const std::invalid_argument&) {
      return false;
    }
  }

  double mass_;
  Separation separation_;
  double step_;
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  mutable std::array<double, 3> value_theta_{kNaN, kNaN, kNaN}, slope_theta_{kNaN, kNaN, kNaN};
  mutable Response value_;
  mutable ResponseSlopes slopes_{};
  mutable bool value_ok_ = false, slopes_ok_ = false;
};

// Maximum of rebound n of a run: (A(v_r e^n) - X)/sigma over (theta, ln v_r).
class PoyntingThomsonMaximumCost final : public ceres::SizedCostFunction<1, 3, 1> {
 public:
  PoyntingThomsonMaximumCost(const ResponseModel& model, const Pendulum& pendulum, int n, double x,
                             double sigma)
      : model_(model), pendulum_(pendulum), n_(n), x_(x), sigma_(sigma) {}
  bool Evaluate(double const* const* p, double* r, double** jac) const override {
    Response resp;
    ResponseSlopes d{};
    const bool want = jac && jac[0];
    if (!(want ? model_.ValueAndSlopes(p[0], &resp, &d) : model_.Value(p[0], &resp))) return false;
    const double v = std::exp(p[1][0] + n_ * resp.log_e);
    fit_internal::AmplitudeSlope a;
    try {
      a = AmplitudeAndSlope(pendulum_, v);
    } catch (const std::domain_error&) {
      return false;
    }
    r[0] = (a.amplitude - x_) / sigma_;
    const double dv = a.slope * v / sigma_;  // dr/d ln v
    if (want) {
      for (int i = 0; i < 3; ++i) jac[0][i] = dv * n_ * d[static_cast<std::size_t>(i)].log_e;
    }
    if (jac && jac[1]) jac[1][0] = dv;
    return true;
  }

 private:
  const ResponseModel& model_;
  Pendulum pendulum_;
  int n_;
  double x_, sigma_;
};

// Contact time of a run: (tau_c - tau)/sigma over theta.
class ContactTimeCost final : public ceres::SizedCostFunction<1, 3> {
 public:
  ContactTimeCost(const ResponseModel& model, double tau, double sigma)
      : model_(model), tau_(tau), sigma_(sigma) {}
  bool Evaluate(double const* const* p, double* r, double** jac) const override {
    Response resp;
    ResponseSlopes d{};
    const bool want = jac && jac[0];
    if (!(want ? model_.ValueAndSlopes(p[0], &resp, &d) : model_.Value(p[0], &resp))) return false;
    r[0] = (resp.contact_time - tau_) / sigma_;
    if (want) {
      for (int i = 0; i < 3; ++i) jac[0][i] = d[static_cast<std::size_t>(i)].contact_time / sigma_;
    }
    return true;
  }

 private:
  const ResponseModel& model_;
  double tau_, sigma_;
};

// Peak compression of the impact after rebound k: ((x_peak/v0) v_r e^k - X)/sigma.
class PeakCost final : public ceres::SizedCostFunction<1, 3, 1> {
 public:
  PeakCost(const ResponseModel& model, int k, double x, double sigma)
      : model_(model), k_(k), x_(x), sigma_(sigma) {}
  bool Evaluate(double const* const* p, double* r, double** jac) const override {
    Response resp;
    ResponseSlopes d{};
    const bool want = jac && jac[0];
    if (!(want ? model_.ValueAndSlopes(p[0], &resp, &d) : model_.Value(p[0], &resp))) return false;
    const double v = std::exp(p[1][0] + k_ * resp.log_e);
    r[0] = (resp.peak * v - x_) / sigma_;
    if (want) {
      for (std::size_t i = 0; i < 3; ++i) {
        jac[0][i] = (d[i].peak + resp.peak * k_ * d[i].log_e) * v / sigma_;
      }
    }
    if (jac && jac[1]) jac[1][0] = resp.peak * v / sigma_;
    return true;
  }

 private:
  const ResponseModel& model_;
  int k_;
  double x_, sigma_;
};

// The usable maxima of a run: (rebound, value), the unread (NaN) left out.
std::vector<std::pair<int, double>> UsableMaxima(const PoyntingThomsonRun& run) {
  std::vector<std::pair<int, double>> out;
  for (std::size_t i = 0; i < run.measured.xmax.size(); ++i) {
    const double x = run.measured.xmax[i];
    if (!std::isnan(x)) out.emplace_back(static_cast<int>(i), x);
  }
  return out;
}

// Why the run's maxima cannot be fitted (one not in 0 < X < L, none read);
// empty when they can.
std::string MaximaRefusal(const PoyntingThomsonRun& run) {
  const auto maxima = UsableMaxima(run);
  for (const auto& [i, x] : maxima) {
    if (!(x > 0.0) || !std::isfinite(x)) {
      return fmt::format("run \"{}\": rebound {} maximum must be > 0, got {}", run.name, i, x);
    }
    if (std::string beyond = SwingAmplitudeProblem(run.pendulum, x); !beyond.empty()) {
      return fmt::format("run \"{}\": rebound {}: {}", run.name, i, beyond);
    }
  }
  if (maxima.empty()) return fmt::format("run \"{}\" has no maxima", run.name);
  return {};
}

// The start: a Kelvin-Voigt model with the data's e and mean tau_c (or peak
// compression), split as K1 = K, K2 = 10 K, C = C; nothing, with `refusal`,
// when the data fix no time scale.
std::optional<PoyntingThomson> DefaultStart(const std::vector<PoyntingThomsonRun>& runs,
                                            const PoyntingThomsonLeastSquaresOptions& options,
                                            std::string* refusal) {
  double log_e = -0.2;  // when no run has two maxima
  for (const PoyntingThomsonRun& run : runs) {
    const auto maxima = UsableMaxima(run);
    if (maxima.size() < 2) continue;
    const double v0 = SpeedFromAmplitude(run.pendulum, maxima.front().second);
    const double v1 = SpeedFromAmplitude(run.pendulum, maxima.back().second);
    const double q = std::log(v1 / v0) / (maxima.back().first - maxima.front().first);
    if (q < 0.0) log_e = q;
    break;
  }
  const double zeta = DampingRatioFromLogRestitution(log_e, options.separation);
  double tau_sum = 0.0;
  int tau_count = 0;
  for (const PoyntingThomsonRun& run : runs) {
    if (run.measured.contact_time) {
      tau_sum += *run.measured.contact_time;
      ++tau_count;
    }
  }
  double k = 0.0;
  if (tau_count > 0) {
    k = StiffnessFromContactTime(options.mass, tau_sum / tau_count, zeta, options.separation);
  } else {
    for (const PoyntingThomsonRun& run : runs) {
      if (!run.peak_compression) continue;
      // x_peak ~ (v/wn) e^(ln e/2): wn from the peak per unit speed.
      const auto maxima = UsableMaxima(run);
      const double v0 =
          SpeedFromAmplitude(run.pendulum, maxima.front().second) *
          std::exp((run.peak_compression->after_rebound - maxima.front().first) * log_e);
      const double wn = v0 * std::exp(0.5 * log_e) / run.peak_compression->value;
      k = options.mass * wn * wn;
      break;
    }
  }
  if (!(k > 0.0)) {
    *refusal =
        "the runs carry neither contact times nor peak compressions, so the maxima do not fix a "
        "time scale: give options.initial";
    return std::nullopt;
  }
  return PoyntingThomson{options.mass, k, 10.0 * k, 2.0 * zeta * std::sqrt(k * options.mass)};
}

// What the data determine, in words, and what would add the missing number.
std::string Advice(bool has_tau, bool has_peak, int rank) {
  if (!has_tau && !has_peak) {
    return "maxima alone give only e; add contact times and a peak compression, or fit the "
           "compression history";
  }
  if (has_tau && !has_peak && rank == 2) {
    return "maxima and contact times give only e and tau_c, and a linear contact has the same e "
           "and tau_c at every impact speed, so more runs add no third number; add a peak "
           "compression or fit the compression history";
  }
  return "add data that depend on the undetermined combination (peak compressions, the "
         "compression history)";
}

}  // namespace

bool PoyntingThomsonLeastSquaresOptions::Check(std::string* why) const {
  if (!(bound_factor > 1.0)) {
    *why = fmt::format("bound_factor must be > 1, got {}", bound_factor);
    return false;
  }
  if (!(difference_step > 0.0) || !(difference_step < 0.1)) {
    *why = fmt::format("difference_step must be in (0, 0.1), got {}", difference_step);
    return false;
  }
  if (!fit_internal::CheckRelativeSingularValue(min_relative_singular_value, why) ||
      !loss.Check(why) || !solver.Check(why)) {
    return false;
  }
  if (initial) {
    const PoyntingThomson& m = *initial;
    if (!(m.stiffness1 > 0.0) || !(m.stiffness2 > 0.0) || !(m.damping > 0.0)) {
      *why = fmt::format("initial K1, K2, C must be > 0, got {}, {}, {}", m.stiffness1,
                         m.stiffness2, m.damping);
      return false;
    }
  }
  return true;
}

PoyntingThomsonLeastSquaresFit FitPoyntingThomsonLeastSquares(
    const std::vector<PoyntingThomsonRun>& runs,
    const PoyntingThomsonLeastSquaresOptions& options) {
  const fit_internal::Stopwatch stopwatch;
  if (std::string why; !options.Check(&why)) throw std::invalid_argument(why);
  if (!(options.mass > 0.0) || !std::isfinite(options.mass)) {
    throw std::invalid_argument(fmt::format("mass must be > 0, got {}", options.mass));
  }
  PoyntingThomsonLeastSquaresFit fit;
  fit.separation = options.separation;
  // Data the fit cannot take: a fit that did not run, with why.
  const auto refuse = [&](std::string why) {
    fit.reason = std::move(why);
    return fit;
  };
  if (runs.empty()) return refuse("no runs to fit");

  // Uncertainties: all given (weighted) or none (maxima only, unit weights).
  bool any_weighted = false, any_unweighted = false, has_tau = false, has_peak = false;
  std::vector<std::vector<double>> sigmas;
  for (const PoyntingThomsonRun& run : runs) {
    bool weighted = false;
    std::string refusal;
    sigmas.push_back(fit_internal::MaximumSigmas(run.measured.xmax, run.measured.xmax_sigma,
                                                 &weighted, &refusal));
    if (!refusal.empty()) return refuse(refusal);
    (weighted ? any_weighted : any_unweighted) = true;
    if (std::string why = MaximaRefusal(run); !why.empty()) return refuse(why);
    if (run.measured.contact_time) {
      has_tau = true;
      if (!(*run.measured.contact_time > 0.0) || !(run.measured.contact_time_sigma > 0.0)) {
        return refuse(fmt::format(
            "run \"{}\": a fitted contact time needs tau_c > 0 and sigma > 0, got {} +- {}",
            run.name, *run.measured.contact_time, run.measured.contact_time_sigma));
      }
    }
    if (run.peak_compression) {
      has_peak = true;
      if (!(run.peak_compression->value > 0.0) || !(run.peak_compression->sigma > 0.0)) {
        return refuse(
            fmt::format("run \"{}\": a peak compression needs value > 0 and sigma > 0", run.name));
      }
    }
  }
  if (any_weighted && any_unweighted) {
    return refuse("give maxima uncertainties for every run or for none");
  }
  const bool weighted = any_weighted;
  if (!weighted && (has_tau || has_peak)) {
    return refuse(
        "contact times and peak compressions can only be fitted with the maxima's uncertainties "
        "(residuals of different units need sigmas to be weighed)");
  }

  std::string no_start;
  const std::optional<PoyntingThomson> start =
      options.initial ? options.initial : DefaultStart(runs, options, &no_start);
  if (!start) return refuse(no_start);
  const PoyntingThomson& start_model = *start;
  std::array<double, 3> theta = {std::log(start_model.stiffness1), std::log(start_model.stiffness2),
                                 std::log(start_model.damping)};
  const std::array<double, 3> theta0 = theta;
  const ResponseModel model(options.mass, options.separation, options.difference_step);
  const auto finish = [&] {
    fit.status.seconds = stopwatch.Seconds();
    return fit;
  };
  Response at_start;
  if (!model.Value(theta.data(), &at_start)) {
    fit.status.message = fmt::format(
        "contact never ends at the start K1 = {:.6g}, K2 = {:.6g}, C = {:.6g} under {} separation",
        start_model.stiffness1, start_model.stiffness2, start_model.damping,
        SeparationName(options.separation));
    fit.reason = fit.status.message + ": give options.initial or use force separation";
    return finish();
  }

  // Per-run speed at rebound 0, from the first maximum and the start's e.
  std::vector<double> log_speed(runs.size());
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const auto maxima = UsableMaxima(runs[r]);
    log_speed[r] = std::log(SpeedFromAmplitude(runs[r].pendulum, maxima.front().second)) -
                   maxima.front().first * at_start.log_e;
  }

  ceres::Problem problem;
  problem.AddParameterBlock(theta.data(), 3);
  const double spread = std::log(options.bound_factor);
  for (int i = 0; i < 3; ++i) {
    problem.SetParameterLowerBound(theta.data(), i, theta0[static_cast<std::size_t>(i)] - spread);
    problem.SetParameterUpperBound(theta.data(), i, theta0[static_cast<std::size_t>(i)] + spread);
  }
  int residual_count = 0;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const PoyntingThomsonRun& run = runs[r];
    for (const auto& [n, x] : UsableMaxima(run)) {
      problem.AddResidualBlock(
          new PoyntingThomsonMaximumCost(model, run.pendulum, n, x,
                                         sigmas[r][static_cast<std::size_t>(n)]),
          fit_internal::MakeLoss(options.loss), theta.data(), &log_speed[r]);
      ++residual_count;
    }
    if (run.measured.contact_time) {
      problem.AddResidualBlock(
          new ContactTimeCost(model, *run.measured.contact_time, run.measured.contact_time_sigma),
          fit_internal::MakeLoss(options.loss), theta.data());
      ++residual_count;
    }
    if (run.peak_compression) {
      problem.AddResidualBlock(
          new PeakCost(model, run.peak_compression->after_rebound, run.peak_compression->value,
                       run.peak_compression->sigma),
          fit_internal::MakeLoss(options.loss), theta.data(), &log_speed[r]);
      ++residual_count;
    }
  }
  const int parameter_count = 3 + static_cast<int>(runs.size());
  fit.dof = residual_count - parameter_count;

  const bool usable = fit_internal::SolveUsable(problem, options.solver, &fit.status, &fit.reason);
  fit.model = {options.mass, std::exp(theta[0]), std::exp(theta[1]), std::exp(theta[2])};
  if (!usable) return finish();
  for (std::size_t i = 0; i < 3; ++i) {
    fit.at_bound = fit.at_bound || std::abs(theta[i] - theta0[i]) > spread * (1.0 - 1e-9);
  }

  // Residuals, chi^2, identifiability (per-run speeds profiled out).
  std::vector<double*> blocks = {theta.data()};
  for (double& w : log_speed) blocks.push_back(&w);
  Eigen::VectorXd res;
  const Eigen::MatrixXd j = fit_internal::Jacobian(problem, blocks, &res);
  fit.chi2 = res.squaredNorm();
  if (weighted) fit.scatter = CheckScatter(fit.chi2, fit.dof);
  const std::vector<std::string> names = {"log K1", "log K2", "log C"};
  fit.identifiability = fit_internal::Analyse(j, 3, names, options.min_relative_singular_value);
  Identifiability& id = fit.identifiability;

  // Covariance: the pseudo-inverse without the undetermined directions.
  Eigen::MatrixXd cov;
  const int null_rank = 3 - id.rank;
  const bool have_cov = fit_internal::Covariance(problem, blocks, null_rank, &cov);
  if (have_cov && !weighted) cov *= fit.dof > 0 ? fit.chi2 / fit.dof : 0.0;
  std::vector<std::string> cov_names = names;
  for (const PoyntingThomsonRun& run : runs) cov_names.push_back("ln v0 " + run.name);
  if (have_cov) fit.covariance = fit_internal::MakeCovariance(cov_names, cov, !weighted);

  // A quantity with gradient g over theta is determined unless g has a
  // component along an undetermined direction.
  const auto sigma_of = [&](const Eigen::Vector3d& g) {
    if (!have_cov) return kInf;
    for (std::size_t k = static_cast<std::size_t>(id.rank); k < id.directions.size(); ++k) {
      const Eigen::Vector3d n(id.directions[k][0], id.directions[k][1], id.directions[k][2]);
      if (std::abs(g.dot(n)) > 1e-6 * g.norm()) return kInf;
    }
    return std::sqrt(std::max(0.0, g.dot(cov.topLeftCorner<3, 3>() * g)));
  };
  const auto unit = [](int i) { return Eigen::Vector3d::Unit(i); };
  fit.stiffness1 = {fit.model.stiffness1, fit.model.stiffness1 * sigma_of(unit(0))};
  fit.stiffness2 = {fit.model.stiffness2, fit.model.stiffness2 * sigma_of(unit(1))};
  fit.damping = {fit.model.damping, fit.model.damping * sigma_of(unit(2))};
  Response resp;
  ResponseSlopes d{};
  if (model.ValueAndSlopes(theta.data(), &resp, &d)) {
    const auto grad = [&](double Response::*q) {
      return Eigen::Vector3d(d[0].*q, d[1].*q, d[2].*q);
    };
    fit.log_restitution = {resp.log_e, sigma_of(grad(&Response::log_e))};
    fit.restitution = {std::exp(resp.log_e), std::exp(resp.log_e) * fit.log_restitution.sigma};
    fit.contact_time = {resp.contact_time, sigma_of(grad(&Response::contact_time))};
    fit.peak_per_speed = {resp.peak, sigma_of(grad(&Response::peak))};
  }

  // Per-run results, in the order the residuals were added.
  Eigen::Index row = 0;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const PoyntingThomsonRun& run = runs[r];
    PoyntingThomsonRunFit out;
    out.name = run.name;
    const double sw = have_cov ? std::sqrt(std::max(0.0, cov(3 + static_cast<Eigen::Index>(r),
                                                             3 + static_cast<Eigen::Index>(r))))
                               : kInf;
    out.rebound0_speed = {std::exp(log_speed[r]), std::exp(log_speed[r]) * sw};
    for (const auto& [n, x] : UsableMaxima(run)) {
      MaximumResidual m;
      m.run = static_cast<int>(r);
      m.rebound = n;
      m.measured = x;
      m.sigma = sigmas[r][static_cast<std::size_t>(n)];
      m.model = x + res[row] * m.sigma;
      m.normalized = -res[row++];
      fit.residuals.push_back(m);
    }
    if (run.measured.contact_time) out.contact_time_normalized = -res[row++];
    if (run.peak_compression) out.peak_normalized = -res[row++];
    fit.runs.push_back(out);
  }

  // The verdict.
  if (id.identifiable) {
    id.message = "K1, K2 and C are all determined";
  } else {
    std::string determined, undetermined;
    for (std::size_t k = 0; k < id.directions.size(); ++k) {
      std::string& into = static_cast<int>(k) < id.rank ? determined : undetermined;
      if (!into.empty()) into += "; ";
      into += FormatCombination(id.directions[k], names);
    }
    std::string what = fmt::format("ln e = {:.6g} +- {:.2g}", fit.log_restitution.value,
                                   fit.log_restitution.sigma);
    if (std::isfinite(fit.contact_time.sigma)) {
      what += fmt::format(", tau_c = {:.6g} +- {:.2g} s", fit.contact_time.value,
                          fit.contact_time.sigma);
    }
    id.message = fmt::format(
        "not identifiable: the data determine {} of 3 combinations of (log K1, log K2, log C): "
        "{} ({}); undetermined: {}. {}",
        id.rank, determined.empty() ? "none" : determined, what, undetermined,
        Advice(has_tau, has_peak, id.rank));
  }
  if (!fit.status.converged) {
    fit.reason = "the solver did not converge: " + fit.status.message;
  } else if (!id.identifiable) {
    fit.reason = id.message;
  } else if (fit.at_bound) {
    fit.reason = fmt::format(
        "a parameter ended on its bound (a factor {} from the start): widen bound_factor or give a "
        "better options.initial",
        options.bound_factor);
  } else if (!have_cov) {
    fit.reason = "the covariance could not be computed";
  }
  fit.ok = fit.status.converged && id.identifiable && !fit.at_bound && have_cov;
  return finish();
}

}  // namespace impactlab
