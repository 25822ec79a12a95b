#include "fit/joint_fits.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "fit/least_squares_internal.h"

namespace impactlab {
namespace {

enum class Kind { kPerRun, kCommon, kLinear };

const char* KindName(Kind kind) {
  switch (kind) {
    case Kind::kPerRun:
      return "per-run";
    case Kind::kCommon:
      return "common";
    case Kind::kLinear:
      return "linear-in-speed";
  }
  return "";
}

// One run's read maxima.
struct Prepared {
  std::string name;
  Pendulum pendulum;
  std::vector<int> rebounds;  // session numbering of the read maxima
  std::vector<double> x, sigma;
  double initial_displacement = 0.0;
  double speed = 0.0;  // u_r
};

// (A(exp(w + n q)) - X)/sigma with q = c . theta; blocks (w [1], theta [m]).
class JointMaximumCost final : public ceres::CostFunction {
 public:
  JointMaximumCost(const Pendulum& pendulum, int rebound, double measured, double sigma,
                   std::vector<double> coefficients)
      : pendulum_(pendulum),
        n_(rebound),
        measured_(measured),
        sigma_(sigma),
        c_(std::move(coefficients)) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(1);
    mutable_parameter_block_sizes()->push_back(static_cast<int>(c_.size()));
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    double q = 0.0;
    for (std::size_t i = 0; i < c_.size(); ++i) q += c_[i] * parameters[1][i];
    const double speed = std::exp(parameters[0][0] + n_ * q);
    if (!std::isfinite(speed)) return false;
    fit_internal::AmplitudeSlope a;
    try {
      a = fit_internal::AmplitudeAndSlope(pendulum_, speed);
    } catch (const std::domain_error&) {
      return false;  // past the horizontal: Ceres shrinks the step
    }
    residuals[0] = (a.amplitude - measured_) / sigma_;
    if (jacobians) {
      const double d = a.slope * speed / sigma_;  // dr / d ln v
      if (jacobians[0]) jacobians[0][0] = d;
      if (jacobians[1]) {
        for (std::size_t i = 0; i < c_.size(); ++i) jacobians[1][i] = d * n_ * c_[i];
      }
    }
    return true;
  }

 private:
  Pendulum pendulum_;
  int n_;
  double measured_, sigma_;
  std::vector<double> c_;
};

// Inverse-variance weighted mean and standard deviation (unweighted when a
// sigma is zero, e.g. noiseless data).
void WeightedMeanStd(const std::vector<Estimate>& values, double* mean, double* spread) {
  bool weighted = true;
  for (const Estimate& e : values) weighted = weighted && e.sigma > 0.0 && std::isfinite(e.sigma);
  double sw = 0.0, sx = 0.0;
  for (const Estimate& e : values) {
    const double w = weighted ? 1.0 / (e.sigma * e.sigma) : 1.0;
    sw += w;
    sx += w * e.value;
  }
  *mean = sx / sw;
  double ss = 0.0;
  for (const Estimate& e : values) {
    const double w = weighted ? 1.0 / (e.sigma * e.sigma) : 1.0;
    ss += w * (e.value - *mean) * (e.value - *mean);
  }
  *spread = std::sqrt(ss / sw);
}

// q_r = c_r . theta for the model `kind`.
std::vector<double> Coefficients(Kind kind, std::size_t run, std::size_t runs, double speed,
                                 double reference_speed) {
  switch (kind) {
    case Kind::kPerRun: {
      std::vector<double> c(runs, 0.0);
      c[run] = 1.0;
      return c;
    }
    case Kind::kCommon:
      return {1.0};
    case Kind::kLinear:
      return {1.0, speed - reference_speed};
  }
  return {};
}

JointModelFit FitModel(Kind kind, const std::vector<const Prepared*>& runs,
                       const JointFitOptions& options) {
  const fit_internal::Stopwatch stopwatch;
  JointModelFit fit;
  fit.name = KindName(kind);
  const std::size_t nr = runs.size();
  const std::size_t m = kind == Kind::kPerRun ? nr : kind == Kind::kCommon ? 1 : 2;

  if (kind == Kind::kLinear) {
    double s = 0.0;
    for (const Prepared* r : runs) s += r->speed;
    fit.reference_speed = s / static_cast<double>(nr);
  }

  // Starting values: each run's two-point ln e from its first and last maxima.
  std::vector<double> q0(nr);
  for (std::size_t i = 0; i < nr; ++i) {
    const Prepared& r = *runs[i];
    const double va = SpeedFromAmplitude(r.pendulum, r.x.front());
    const double vb = SpeedFromAmplitude(r.pendulum, r.x.back());
    q0[i] = std::log(vb / va) / (r.rebounds.back() - r.rebounds.front());
  }
  double q_mean = 0.0;
  for (const double q : q0) q_mean += q / static_cast<double>(nr);
  std::vector<double> theta(m, 0.0);
  if (kind == Kind::kPerRun) {
    theta = q0;
  } else {
    theta[0] = q_mean;
  }
  std::vector<std::vector<double>> c(nr);
  std::vector<double> w(nr);
  for (std::size_t i = 0; i < nr; ++i) {
    c[i] = Coefficients(kind, i, nr, runs[i]->speed, fit.reference_speed);
    double q = 0.0;
    for (std::size_t j = 0; j < m; ++j) q += c[i][j] * theta[j];
    const Prepared& r = *runs[i];
    w[i] = std::log(SpeedFromAmplitude(r.pendulum, r.x.front())) - r.rebounds.front() * q;
  }

  ceres::Problem problem;
  int count = 0;
  for (std::size_t i = 0; i < nr; ++i) {
    const Prepared& r = *runs[i];
    for (std::size_t k = 0; k < r.x.size(); ++k) {
      problem.AddResidualBlock(
          new JointMaximumCost(r.pendulum, r.rebounds[k], r.x[k], r.sigma[k], c[i]), nullptr, &w[i],
          theta.data());
      ++count;
    }
  }
  fit.maxima = count;
  fit.parameter_count = static_cast<int>(m + nr);
  fit.dof = fit.maxima - fit.parameter_count;

  const auto finish = [&] {
    fit.status.seconds = stopwatch.Seconds();
    return fit;
  };
  if (!fit_internal::SolveUsable(problem, options.solver, &fit.status, &fit.reason)) {
    return finish();
  }

  std::vector<double*> blocks{theta.data()};
  for (std::size_t i = 0; i < nr; ++i) blocks.push_back(&w[i]);
  Eigen::VectorXd res;
  const Eigen::MatrixXd j = fit_internal::Jacobian(problem, blocks, &res);
  fit.chi2 = res.squaredNorm();
  const double k = fit.parameter_count;
  fit.scatter = CheckScatter(fit.chi2, fit.dof);
  fit.aic = fit.chi2 + 2.0 * k;
  fit.bic = fit.chi2 + k * std::log(static_cast<double>(fit.maxima));

  // Covariance (J^T J)^-1 by SVD of the whitened Jacobian.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(j, Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();
  if (s.size() < j.cols() || !(s[s.size() - 1] > options.min_relative_singular_value * s[0])) {
    fit.reason = fmt::format(
        "not identifiable: the whitened Jacobian's smallest singular value is {:.3g} of the "
        "largest",
        s.size() > 0 && s[0] > 0 ? s[s.size() - 1] / s[0] : 0.0);
    return finish();
  }
  const Eigen::MatrixXd v = svd.matrixV();
  const Eigen::MatrixXd cov = v * s.cwiseInverse().cwiseAbs2().asDiagonal() * v.transpose();

  std::vector<std::string> names;
  for (std::size_t i = 0; i < m; ++i) {
    std::string name;
    switch (kind) {
      case Kind::kPerRun:
        name = "log_restitution_" + runs[i]->name;
        break;
      case Kind::kCommon:
        name = "log_restitution";
        break;
      case Kind::kLinear:
        name = i == 0 ? "a" : "b";
        break;
    }
    names.push_back(name);
    // ln e = a + b (u - u_ref): b is per unit of impact speed.
    const std::string units = name == "b" ? "inverse_speed" : "1";
    fit.parameters.push_back(
        {name,
         units,
         {theta[i], std::sqrt(cov(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)))}});
  }
  const auto mi = static_cast<Eigen::Index>(m);
  fit.covariance = fit_internal::MakeCovariance(names, cov.topLeftCorner(mi, mi), false);
  for (std::size_t i = 0; i < nr; ++i) {
    const Eigen::Map<const Eigen::VectorXd> ci(c[i].data(), mi);
    const double q = ci.dot(Eigen::Map<const Eigen::VectorXd>(theta.data(), mi));
    fit.run_log_restitution.push_back(
        {q, std::sqrt(std::max(0.0, ci.dot(cov.topLeftCorner(mi, mi) * ci)))});
    const auto wi = static_cast<Eigen::Index>(m + i);
    fit.run_rebound0_speed.push_back({std::exp(w[i]), std::exp(w[i]) * std::sqrt(cov(wi, wi))});
  }
  if (kind == Kind::kCommon) {
    fit.log_restitution_mean = theta[0];
    fit.log_restitution_spread = 0.0;
  } else {
    WeightedMeanStd(fit.run_log_restitution, &fit.log_restitution_mean,
                    &fit.log_restitution_spread);
  }
  fit.ok = true;
  return finish();
}

LeaveOneOut LeaveRunsOut(Kind kind, const std::vector<Prepared>& runs,
                         const JointFitOptions& options) {
  LeaveOneOut out;
  out.ok = true;
  double ss_norm = 0.0, ss_len = 0.0;
  for (std::size_t h = 0; h < runs.size(); ++h) {
    std::vector<const Prepared*> training;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      if (i != h) training.push_back(&runs[i]);
    }
    const JointModelFit fit = FitModel(kind, training, options);
    const Prepared& r = runs[h];
    if (!fit.ok) {
      out.ok = false;
      out.run_rms_normalized.push_back(std::numeric_limits<double>::quiet_NaN());
      out.run_log_restitution.push_back(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    const double q = fit.LogRestitutionFor(r.pendulum, r.initial_displacement);
    out.run_log_restitution.push_back(q);
    double run_ss = 0.0;
    int run_n = 0;
    for (std::size_t k = 1; k < r.x.size(); ++k) {
      double predicted = 0.0;
      try {
        predicted = PredictMaximum(r.pendulum, r.x.front(), r.rebounds.front(), r.rebounds[k], q);
      } catch (const std::domain_error&) {
        out.ok = false;
        continue;
      }
      const double d = predicted - r.x[k];
      run_ss += (d / r.sigma[k]) * (d / r.sigma[k]);
      ss_len += d * d;
      ++run_n;
    }
    ss_norm += run_ss;
    out.maxima += run_n;
    out.run_rms_normalized.push_back(run_n > 0 ? std::sqrt(run_ss / run_n) : 0.0);
  }
  if (out.maxima > 0) {
    out.rms_normalized = std::sqrt(ss_norm / out.maxima);
    out.rms_length = std::sqrt(ss_len / out.maxima);
  }
  return out;
}

}  // namespace

double JointModelFit::LogRestitutionFor(const Pendulum& pendulum,
                                        double initial_displacement) const {
  if (name == "linear-in-speed") {
    const double u = SpeedFromAmplitude(pendulum, initial_displacement);
    return parameters.at(0).estimate.value +
           parameters.at(1).estimate.value * (u - reference_speed);
  }
  if (name == "common") return parameters.at(0).estimate.value;
  return log_restitution_mean;  // per-run: an unseen run gets the runs' weighted mean
}

bool JointFitOptions::Check(std::string* why) const {
  return solver.Check(why) &&
         fit_internal::CheckRelativeSingularValue(min_relative_singular_value, why);
}

SessionModelComparison CompareRestitutionModels(const std::vector<JointRun>& runs,
                                                const JointFitOptions& options) {
  const fit_internal::Stopwatch stopwatch;
  if (std::string why; !options.Check(&why)) throw std::invalid_argument(why);
  for (const std::string& name : options.runs) {
    if (std::none_of(runs.begin(), runs.end(), [&](const JointRun& r) { return r.name == name; })) {
      throw std::invalid_argument(fmt::format("no run named '{}'", name));
    }
  }
  SessionModelComparison out;
  // Runs the models cannot be compared over: a comparison that is not ok, with why.
  const auto refuse = [&](std::string why) {
    out.reason = std::move(why);
    return out;
  };
  std::vector<Prepared> prepared;
  for (const JointRun& run : runs) {
    if (!options.runs.empty() &&
        std::find(options.runs.begin(), options.runs.end(), run.name) == options.runs.end()) {
      continue;
    }
    if (!(run.initial_displacement > 0.0) || !std::isfinite(run.initial_displacement)) {
      throw std::invalid_argument(fmt::format("run '{}': initial displacement must be > 0, got {}",
                                              run.name, run.initial_displacement));
    }
    bool weighted = false;
    std::string refusal;
    const std::vector<double> sigmas = fit_internal::MaximumSigmas(
        run.measured.xmax, run.measured.xmax_sigma, &weighted, &refusal);
    if (!refusal.empty()) return refuse(refusal);
    if (!weighted) {
      return refuse(fmt::format(
          "run '{}': joint fits compare chi^2 across runs and need every maximum's sigma > 0",
          run.name));
    }
    Prepared p;
    p.name = run.name;
    p.pendulum = run.pendulum;
    p.initial_displacement = run.initial_displacement;
    p.speed = SpeedFromAmplitude(run.pendulum, run.initial_displacement);
    for (std::size_t i = 0; i < run.measured.xmax.size(); ++i) {
      const double x = run.measured.xmax[i];
      if (std::isnan(x)) continue;
      if (!(x > 0.0) || !std::isfinite(x)) {
        return refuse(
            fmt::format("run '{}': rebound {} maximum must be > 0, got {}", run.name, i, x));
      }
      if (std::string beyond = SwingAmplitudeProblem(run.pendulum, x); !beyond.empty()) {
        return refuse(fmt::format("run '{}': rebound {}: {}", run.name, i, beyond));
      }
      p.rebounds.push_back(static_cast<int>(i));
      p.x.push_back(x);
      p.sigma.push_back(sigmas[i]);
    }
    if (p.x.size() < 2) {
      return refuse(
          fmt::format("run '{}': a joint fit needs at least two read maxima per run, got {}",
                      run.name, p.x.size()));
    }
    prepared.push_back(std::move(p));
  }
  if (prepared.size() < 2) {
    return refuse(
        fmt::format("a model comparison needs at least two runs, got {}", prepared.size()));
  }

  out.ok = true;
  std::vector<const Prepared*> all;
  for (const Prepared& p : prepared) {
    out.run_names.push_back(p.name);
    out.impact_speeds.push_back(p.speed);
    all.push_back(&p);
  }
  double best_loo = std::numeric_limits<double>::infinity();
  double best_bic = std::numeric_limits<double>::infinity();
  for (const Kind kind : {Kind::kPerRun, Kind::kCommon, Kind::kLinear}) {
    JointModelFit fit = FitModel(kind, all, options);
    if (options.leave_one_out) fit.leave_one_out = LeaveRunsOut(kind, prepared, options);
    if (fit.ok && fit.bic < best_bic) {
      best_bic = fit.bic;
      out.best_by_bic = fit.name;
    }
    if (fit.leave_one_out.ok && fit.leave_one_out.maxima > 0 &&
        fit.leave_one_out.rms_normalized < best_loo) {
      best_loo = fit.leave_one_out.rms_normalized;
      out.best_by_leave_one_out = fit.name;
    }
    out.models.push_back(std::move(fit));
  }
  out.seconds = stopwatch.Seconds();
  return out;
}

std::vector<double> PredictMaxima(const Pendulum& pendulum, double start_xmax, int count,
                                  double log_restitution) {
  if (count < 0) throw std::invalid_argument(fmt::format("count must be >= 0, got {}", count));
  if (!(start_xmax > 0.0)) {
    throw std::invalid_argument(fmt::format("start maximum must be > 0, got {}", start_xmax));
  }
  std::vector<double> out;
  for (int n = 0; n < count; ++n) {
    out.push_back(n == 0 ? start_xmax
                         : PredictMaximum(pendulum, start_xmax, 0, n, log_restitution));
  }
  return out;
}

}  // namespace impactlab
