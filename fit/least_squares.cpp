#include "fit/least_squares.h"

#include <cmath>
#include <stdexcept>

#include <ceres/version.h>
#include <fmt/format.h>
#include <boost/math/distributions/chi_squared.hpp>

#include "fit/least_squares_internal.h"

namespace impactlab {
namespace fit_internal {

bool CheckRelativeSingularValue(double value, std::string* why) {
  if (value > 0.0 && value < 1.0) return true;
  *why = fmt::format("min_relative_singular_value must be in (0, 1), got {}", value);
  return false;
}

}  // namespace fit_internal

// The words are the settings' (SettingNames in least_squares.h), written once.
const char* RobustLossName(RobustLoss loss) {
  for (const auto& [value, name] : SettingNames(loss)) {
    if (value == loss) return name.data();
  }
  return "none";
}

bool LossOptions::Check(std::string* why) const {
  if (scale_sigmas > 0.0 && std::isfinite(scale_sigmas)) return true;
  *why = fmt::format("loss.scale_sigmas must be > 0, got {}", scale_sigmas);
  return false;
}

bool SolverControl::Check(std::string* why) const {
  if (max_iterations <= 0) {
    *why = fmt::format("solver.max_iterations must be > 0, got {}", max_iterations);
    return false;
  }
  if (!(function_tolerance > 0.0) || !(gradient_tolerance > 0.0) || !(parameter_tolerance > 0.0)) {
    *why = "solver tolerances must be > 0";
    return false;
  }
  return true;
}

std::string FormatCombination(const std::vector<double>& direction,
                              const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < direction.size() && i < names.size(); ++i) {
    const double c = direction[i];
    if (std::abs(c) < 0.005) continue;
    if (out.empty()) {
      out += fmt::format("{:.3f} {}", c, names[i]);
    } else {
      out += fmt::format(" {} {:.3f} {}", c < 0 ? '-' : '+', std::abs(c), names[i]);
    }
  }
  return out.empty() ? "0" : out;
}

namespace fit_internal {

ceres::Solver::Options SolverOptions(const SolverControl& control) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.max_num_iterations = control.max_iterations;
  options.function_tolerance = control.function_tolerance;
  options.gradient_tolerance = control.gradient_tolerance;
  options.parameter_tolerance = control.parameter_tolerance;
  options.minimizer_progress_to_stdout = false;
  options.logging_type = ceres::SILENT;
  options.num_threads = 1;
  return options;
}

ceres::LossFunction* MakeLoss(const LossOptions& loss) {
  switch (loss.kind) {
    case RobustLoss::kHuber:
      return new ceres::HuberLoss(loss.scale_sigmas);
    case RobustLoss::kCauchy:
      return new ceres::CauchyLoss(loss.scale_sigmas);
    case RobustLoss::kNone:
      break;
  }
  return nullptr;
}

void Solve(ceres::Problem& problem, const SolverControl& control, FitStatus* status) {
  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptions(control), &problem, &summary);
  status->converged = summary.termination_type == ceres::CONVERGENCE;
  status->usable = summary.IsSolutionUsable();
  status->message = summary.message;
  status->iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  status->initial_cost = summary.initial_cost;
  status->final_cost = summary.final_cost;
}

bool SolveUsable(ceres::Problem& problem, const SolverControl& control, FitStatus* status,
                 std::string* reason) {
  Solve(problem, control, status);
  if (!status->usable) *reason = "the solver failed: " + status->message;
  return status->usable;
}

Eigen::MatrixXd Jacobian(ceres::Problem& problem, const std::vector<double*>& blocks,
                         Eigen::VectorXd* residuals) {
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = blocks;
  options.apply_loss_function = false;
  std::vector<double> r;
  ceres::CRSMatrix crs;
  double cost = 0.0;
  problem.Evaluate(options, &cost, &r, nullptr, &crs);
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[static_cast<std::size_t>(row)];
         k < crs.rows[static_cast<std::size_t>(row) + 1]; ++k) {
      j(row, crs.cols[static_cast<std::size_t>(k)]) = crs.values[static_cast<std::size_t>(k)];
    }
  }
  if (residuals)
    *residuals = Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
  return j;
}

bool Covariance(ceres::Problem& problem, const std::vector<double*>& blocks, int null_space_rank,
                Eigen::MatrixXd* covariance) {
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.null_space_rank = null_space_rank;
  options.num_threads = 1;
  ceres::Covariance cov(options);
  const std::vector<const double*> const_blocks(blocks.begin(), blocks.end());
  if (!cov.Compute(const_blocks, &problem)) return false;
  int n = 0;
  for (const double* b : blocks) n += problem.ParameterBlockSize(b);
  covariance->resize(n, n);
  return cov.GetCovarianceMatrix(const_blocks,
                                 covariance->data());  // row-major = col-major (symmetric)
}

Identifiability Analyse(const Eigen::MatrixXd& jacobian, int p,
                        const std::vector<std::string>& names, double min_relative_singular_value) {
  Identifiability out;
  out.parameter_names = names;
  Eigen::MatrixXd jp = jacobian.leftCols(p);
  const Eigen::Index nuisance = jacobian.cols() - p;
  if (nuisance > 0) {
    // Project out what the nuisance parameters can absorb (profiling).
    const Eigen::MatrixXd jn = jacobian.rightCols(nuisance);
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(jn);
    const Eigen::MatrixXd q =
        qr.householderQ() * Eigen::MatrixXd::Identity(jacobian.rows(), nuisance);
    jp -= q * (q.transpose() * jp);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(jp, Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();
  const double largest = s.size() > 0 ? s[0] : 0.0;
  for (Eigen::Index i = 0; i < s.size(); ++i) {
    out.singular_values.push_back(s[i]);
    std::vector<double> dir(static_cast<std::size_t>(p));
    // Sign convention: the largest component positive.
    Eigen::Index biggest = 0;
    svd.matrixV().col(i).cwiseAbs().maxCoeff(&biggest);
    const double sign = svd.matrixV()(biggest, i) < 0 ? -1.0 : 1.0;
    for (int k = 0; k < p; ++k) dir[static_cast<std::size_t>(k)] = sign * svd.matrixV()(k, i);
    out.directions.push_back(dir);
    if (largest > 0 && s[i] > min_relative_singular_value * largest) ++out.rank;
  }
  out.relative_smallest = largest > 0 && s.size() > 0 ? s[s.size() - 1] / largest : 0.0;
  out.identifiable = out.rank == p;
  return out;
}

ParameterCovariance MakeCovariance(const std::vector<std::string>& names,
                                   const Eigen::MatrixXd& matrix, bool scaled_by_residuals) {
  ParameterCovariance out;
  out.names = names;
  out.scaled_by_residuals = scaled_by_residuals;
  const auto n = static_cast<Eigen::Index>(names.size());
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j) {
      out.matrix.push_back(matrix(i, j));
      const double d = matrix(i, i) * matrix(j, j);
      out.correlation.push_back(d > 0 && std::isfinite(d) ? matrix(i, j) / std::sqrt(d) : 0.0);
    }
  }
  return out;
}

AmplitudeSlope AmplitudeAndSlope(const Pendulum& pendulum, double speed) {
  AmplitudeSlope out;
  out.amplitude = AmplitudeFromSpeed(pendulum, speed);  // validates
  if (pendulum.convention == PendulumConvention::kThesis) {
    out.slope = 1.0 / NaturalFrequency(pendulum);
    return out;
  }
  const double scale = 2.0 * std::sqrt(pendulum.gravity * pendulum.length);
  const double k = speed / scale;
  out.slope =
      2.0 * pendulum.length * (1.0 - 2.0 * k * k) / std::sqrt((1.0 - k) * (1.0 + k)) / scale;
  return out;
}

std::vector<double> MaximumSigmas(const std::vector<double>& xmax,
                                  const std::vector<double>& xmax_sigma, bool* weighted,
                                  std::string* refusal) {
  if (!xmax_sigma.empty() && xmax_sigma.size() != xmax.size()) {
    throw std::invalid_argument(
        fmt::format("{} maxima but {} uncertainties", xmax.size(), xmax_sigma.size()));
  }
  // Unread maxima (NaN) are not fitted: their sigmas do not matter.
  bool any = false;
  for (std::size_t i = 0; i < xmax_sigma.size(); ++i) {
    any = any || (!std::isnan(xmax[i]) && xmax_sigma[i] != 0.0);
  }
  *weighted = any;
  if (!any) return std::vector<double>(xmax.size(), 1.0);
  for (std::size_t i = 0; i < xmax_sigma.size(); ++i) {
    const double s = xmax_sigma[i];
    if (!std::isnan(xmax[i]) && (!(s > 0.0) || !std::isfinite(s))) {
      *refusal = fmt::format(
          "a least-squares fit needs every maximum's sigma > 0, or none at all; rebound {} has {}",
          i, s);
      return {};
    }
  }
  return xmax_sigma;
}

}  // namespace fit_internal
std::string CeresVersion() { return CERES_VERSION_STRING; }

ScatterCheck CheckScatter(double chi2, int dof) {
  ScatterCheck out;
  if (dof <= 0 || !std::isfinite(chi2) || chi2 < 0.0) return out;
  out.birge_ratio = std::sqrt(chi2 / dof);
  out.p_value = boost::math::cdf(
      boost::math::complement(boost::math::chi_squared_distribution<double>(dof), chi2));
  out.excess = out.p_value < 1e-3 && out.birge_ratio > 1.0;
  return out;
}

}  // namespace impactlab
