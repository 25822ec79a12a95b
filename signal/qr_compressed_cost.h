// A tall least-squares problem (many more residuals than parameters) handed to
// Ceres through the R factor of its Jacobian's QR: signal/damped_modes.cpp's
// fit of thousands of samples for at most 13 parameters.
//
// With [J r] = Q [R Q^T r; 0 rho] (Householder, so as stable as Ceres's own
// dense QR), |r + J d|^2 = |Q^T r + R d|^2 + rho^2 for every step d. Ceres then
// sees p + 1 residuals (Q^T r, rho) and the Jacobian (R; 0): their cost, gradient
// R^T Q^T r = J^T r, column norms (Jacobi scaling), model cost change and
// Levenberg-Marquardt steps are those of the full problem, so it takes the same
// steps to rounding. What it no longer does is copy, scale, check for NaN and
// factorise all N rows each iteration.
//
// With bounds on the parameters Ceres evaluates each trial point three times:
// its projected line search asks for the gradient there, then for the cost,
// then, the step taken, for the Jacobian. The last point factorised is kept
// and answers the later two (the same parameters give the same numbers), so a
// point costs one evaluation of the N rows and one QR.
// A point evaluated without a Jacobian and not the kept one gives
// (0, ..., 0, |r|): Ceres uses only the cost of such a point, and never mixes
// its residuals with another point's Jacobian.
//
// Internal to signal/. Not thread-safe: the scratch and the kept point are the
// object's own, so one problem evaluated on one thread
// (Solver::Options::num_threads = 1).
#pragma once

#include <functional>
#include <vector>

#include <ceres/cost_function.h>

namespace impactlab {

// The full problem: its `rows` residuals into `residuals` and, when `jacobian`
// is not null, their derivatives column-major (rows x parameters, the
// parameter blocks' columns one after another). False: no residuals here (an
// infeasible point).
using TallResiduals =
    std::function<bool(double const* const* parameters, double* residuals, double* jacobian)>;

class QrCompressedCost final : public ceres::CostFunction {
 public:
  // `rows` must be at least the sum of `block_sizes` plus one.
  QrCompressedCost(int rows, const std::vector<int>& block_sizes, TallResiduals residuals);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  // Whether `parameters` are the kept point's, bit for bit.
  bool IsKept(double const* const* parameters) const;
  void Keep(double const* const* parameters) const;
  // The kept point's p + 1 residuals and Jacobian blocks (Ceres's layout).
  void Answer(double* residuals, double** jacobians) const;

  int rows_;
  int parameters_ = 0;
  TallResiduals full_;
  mutable std::vector<double> scratch_;  // [J r], rows x (parameters + 1), column-major
  mutable bool kept_ = false;
  mutable std::vector<double> kept_parameters_;  // the blocks' values one after another
  mutable std::vector<double> kept_triangle_;    // [R Q^T r; 0 rho], column-major
};

}  // namespace impactlab
