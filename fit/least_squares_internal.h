// Ceres-side helpers shared by the least-squares fits. Private to fit/: only
// .cpp files include it, so Ceres stays out of the public headers.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <ceres/ceres.h>
#include <Eigen/Dense>

#include "fit/least_squares.h"
#include "model/pendulum.h"

namespace impactlab::fit_internal {

// The options' min_relative_singular_value lies in (0, 1); else false with `why`.
bool CheckRelativeSingularValue(double value, std::string* why);

// Levenberg-Marquardt with dense QR, silent (no logging, no progress output),
// single-threaded (the Poynting-Thomson residuals share a response cache).
ceres::Solver::Options SolverOptions(const SolverControl& control);

// nullptr for RobustLoss::kNone (Ceres then uses the squared loss).
ceres::LossFunction* MakeLoss(const LossOptions& loss);

// Solves `problem` with the project's silent solver settings and records how
// it went in `status` (convergence, usability, message, iterations, costs).
void Solve(ceres::Problem& problem, const SolverControl& control, FitStatus* status);

// Solve(), and false with `reason` set ("the solver failed: ...") when Ceres
// leaves no usable solution: every fit refuses such a solution the same way.
bool SolveUsable(ceres::Problem& problem, const SolverControl& control, FitStatus* status,
                 std::string* reason);

// The wall time since a fit began, for its status's `seconds`.
class Stopwatch {
 public:
  double Seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// The whitened Jacobian at the current parameters (robust loss not applied),
// columns in the order of `blocks`, and the raw residuals.
Eigen::MatrixXd Jacobian(ceres::Problem& problem, const std::vector<double*>& blocks,
                         Eigen::VectorXd* residuals);

// The covariance of `blocks` (concatenated) by ceres::Covariance with DENSE_SVD,
// dropping `null_space_rank` directions (Moore-Penrose pseudo-inverse).
// Returns false when Ceres cannot compute it.
bool Covariance(ceres::Problem& problem, const std::vector<double*>& blocks, int null_space_rank,
                Eigen::MatrixXd* covariance);

// Identifiability of the first `p` columns of the whitened Jacobian J after
// projecting out the remaining (nuisance) columns: SVD of (I - Qn Qn^T) J_p.
Identifiability Analyse(const Eigen::MatrixXd& jacobian, int p,
                        const std::vector<std::string>& names, double min_relative_singular_value);

// Fills a ParameterCovariance (with correlations) from a matrix.
ParameterCovariance MakeCovariance(const std::vector<std::string>& names,
                                   const Eigen::MatrixXd& matrix, bool scaled_by_residuals);

// The horizontal amplitude a swing through equilibrium at `speed` reaches and
// its derivative d amplitude / d speed (model/pendulum.h's AmplitudeFromSpeed;
// exact: X = 2 L k sqrt(1 - k^2), k = v/(2 sqrt(gL)), dX/dk = 2 L (1 - 2k^2)/
// sqrt(1 - k^2); thesis: X = v sqrt(L/g)).
struct AmplitudeSlope {
  double amplitude = 0;
  double slope = 0;
};
AmplitudeSlope AmplitudeAndSlope(const Pendulum& pendulum, double speed);

// Uncertainties of one run's maxima: sigma per maximum, or 1 each when none
// are given (unweighted). Unread maxima (NaN) are ignored. A mixture of zero
// and non-zero sigmas is data no fit can weigh: nothing is returned and
// `refusal` says why. Throws std::invalid_argument for a wrong count (a
// caller's slip).
std::vector<double> MaximumSigmas(const std::vector<double>& xmax,
                                  const std::vector<double>& xmax_sigma, bool* weighted,
                                  std::string* refusal);

}  // namespace impactlab::fit_internal
