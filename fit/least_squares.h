// What the least-squares fits (Kelvin-Voigt and Poynting-Thomson, with Ceres)
// share: solver controls, the robust loss, and the parts of a result that
// report on the fit itself: convergence, covariance, identifiability.
// Ceres stays out of this header (fit/least_squares_internal.h has it).
//
// Conventions (docs/fitting.md):
//  - Residuals are whitened, (model - measured)/sigma, so the covariance is
//    (J^T J)^-1 at the solution (Ceres, DENSE_SVD). Without uncertainties
//    every maximum weighs 1 (length units) and the covariance is scaled by
//    s^2 = chi^2/(N - p): `scaled_by_residuals` says which.
//  - Identifiability is judged on the whitened Jacobian in log-parameter space:
//    its singular values are the inverse standard errors along principal
//    directions; a direction whose singular value is below
//    `min_relative_singular_value` times the largest is not determined, and the
//    result names it instead of printing confident numbers.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "options/result_fields.h"
#include "options/settings.h"

namespace impactlab {

// A robust loss for outlier rebounds, applied to whitened residuals.
enum class RobustLoss { kNone, kHuber, kCauchy };
const char* RobustLossName(RobustLoss loss);  // "none", "huber", "cauchy"
constexpr std::array<SettingName<RobustLoss>, 3> SettingNames(RobustLoss) {
  return {{{RobustLoss::kNone, "none"},
           {RobustLoss::kHuber, "huber"},
           {RobustLoss::kCauchy, "cauchy"}}};
}

struct LossOptions {
  RobustLoss kind = RobustLoss::kNone;
  double scale_sigmas = 2.0;  // where the loss turns from quadratic, in sigmas (> 0)

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("kind", self.kind, "robust loss on whitened residuals");
    visit("scale_sigmas", self.scale_sigmas, "where the loss turns from quadratic, sigmas");
  }
  bool Check(std::string* why) const;
};

struct SolverControl {
  int max_iterations = 200;           // Levenberg-Marquardt iterations (> 0)
  double function_tolerance = 1e-12;  // stop when |d cost|/cost below (Ceres default 1e-6 is loose)
  double gradient_tolerance = 1e-14;  // stop when the max-norm of the projected gradient is below
  double parameter_tolerance = 1e-12;  // stop when |dx| < tol (|x| + tol)

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("max_iterations", self.max_iterations, "Levenberg-Marquardt iterations");
    visit("function_tolerance", self.function_tolerance, "stop below this relative cost change");
    visit("gradient_tolerance", self.gradient_tolerance, "stop below this projected gradient");
    visit("parameter_tolerance", self.parameter_tolerance, "stop below this relative step");
  }
  bool Check(std::string* why) const;
};

// How the solve went. A fit that does not converge is a result with
// `converged` false and the reason in `message`, not an exception.
struct FitStatus {
  bool converged = false;  // Ceres reported CONVERGENCE
  bool usable = false;     // the parameters are the solver's best point (also after NO_CONVERGENCE)
  std::string message;     // Ceres's termination message, or why the solve did not start
  int iterations = 0;      // successful + unsuccessful steps
  double initial_cost = 0;  // (1/2) sum of squared (robustified) whitened residuals
  double final_cost = 0;
  double seconds = 0;  // wall time of the whole fit (solve, covariance, checks)

  // Whether the fit took its inputs: one that returned always says how it
  // ended; one they refused (it throws) has no message, only its caller's reason.
  bool Ran() const { return !message.empty(); }

  // What the results file keeps of it, as a fit's list takes it in
  // (options/result_fields.h). Not kept: `usable` (a fit that is not says so
  // in its reason), the iterations and the costs (docs/results.md: each
  // dataset or attribute more lengthens every reduce).
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("converged", self.converged, Quantity::kDimensionless, "1 when the solver converged");
    visit("termination", self.message, Quantity::kDimensionless,
          "the solver's termination message, or why it did not start");
    visit("seconds", self.seconds, Quantity::kSeconds, "the fit's wall time");
  }
};

// A covariance over named parameters, row-major n x n.
struct ParameterCovariance {
  std::vector<std::string> names;
  std::vector<double> matrix;        // in the parameters' own units
  std::vector<double> correlation;   // matrix_ij / sqrt(matrix_ii matrix_jj); 0 where undefined
  bool scaled_by_residuals = false;  // multiplied by s^2 = chi^2/(N - p) (no uncertainties given)
  double At(std::size_t i, std::size_t j) const { return matrix[i * names.size() + j]; }
  double Correlation(std::size_t i, std::size_t j) const {
    return correlation[i * names.size() + j];
  }
};

// Which combinations of the parameters the data determine.
struct Identifiability {
  bool identifiable = false;
  int rank = 0;                              // directions determined
  std::vector<std::string> parameter_names;  // e.g. "log K1", "log K2", "log C"
  std::vector<double> singular_values;       // whitened Jacobian (after profiling out nuisance
                                        // parameters), descending: 1/sigma along each direction
  std::vector<std::vector<double>> directions;  // unit right singular vectors, same order
  double relative_smallest = 0;                 // smallest / largest singular value
  std::string message;  // the verdict in words (which combination is undetermined)

  // What the results file keeps of it, as a fit's list takes it in
  // (options/result_fields.h): the verdict. Not kept: the singular values and
  // directions, which the message states in words where they matter.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("identifiable", self.identifiable, Quantity::kDimensionless,
          "1 when the data determine every parameter");
    visit("rank", self.rank, Quantity::kDimensionless, "the combinations they determine");
    visit("identifiability", self.message, Quantity::kDimensionless,
          "which combinations are determined and which not, in words");
  }
};

// Whether the scatter about a fit is what the stated sigmas promise: chi^2
// against its distribution with `dof` degrees of freedom. Far above it the
// sigmas understate the scatter, and the standard errors scaled by the Birge
// ratio sqrt(chi^2/dof) are the honest ones (docs/contact-laws.md, "Honest
// uncertainty"). Scaled only when the excess is significant (p < 1e-3), so
// that a fit whose sigmas are right keeps its stated errors and their coverage.
struct ScatterCheck {
  double birge_ratio = 1.0;  // sqrt(chi^2/dof); 1 when dof <= 0
  double p_value = 1.0;      // P(chi^2_dof >= chi^2)
  bool excess = false;       // p < 1e-3
  // The factor the stated standard errors are multiplied by: the Birge ratio
  // when the excess is significant, else 1.
  double Scale() const { return excess ? birge_ratio : 1.0; }

  // Its fields, as a fit's list takes them in (options/result_fields.h).
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("excess_scatter", self.excess, Quantity::kDimensionless,
          "1 when chi2's p-value < 0.001: the errors are Birge-scaled");
    visit("birge_ratio", self.birge_ratio, Quantity::kDimensionless, "sqrt(chi2 / dof)");
    visit("chi2_p_value", self.p_value, Quantity::kDimensionless, "P(chi2_dof >= chi2)");
  }
};
ScatterCheck CheckScatter(double chi2, int dof);

// One maximum's fit residual.
struct MaximumResidual {
  int run = 0;              // its run's index among the fit's runs (a joint fit's; else 0)
  int rebound = 0;          // session numbering
  double measured = 0.0;    // length units
  double model = 0.0;       // length units
  double sigma = 0.0;       // the uncertainty used (1 when unweighted)
  double normalized = 0.0;  // (measured - model)/sigma
};

// What the Kelvin-Voigt and Poynting-Thomson fits' field lists share
// (options/result_fields.h): how the solve went, what the data determine,
// the fit's quality, each maximum's normalized residual (the runs' in turn)
// and the correlation of the parameters fitted (the results file names its
// rows, docs/results.md).
template <typename Fit, typename Visit>
void VisitLeastSquaresFields(Fit& fit, Visit&& visit) {
  FitStatus::VisitFields(fit.status, visit);
  Identifiability::VisitFields(fit.identifiability, visit);
  visit("dof", fit.dof, Quantity::kDimensionless, "degrees of freedom");
  visit("chi2", fit.chi2, Quantity::kDimensionless, "sum of the squared normalized residuals");
  ScatterCheck::VisitFields(fit.scatter, visit);
  visit("normalized_residuals", Column(fit.residuals, &MaximumResidual::normalized),
        Quantity::kDimensionless, "(measured - model) / sigma of each maximum fitted");
  visit("correlation", Square(fit.covariance.correlation), Quantity::kDimensionless,
        "the correlation of the parameters fitted");
}

// The Ceres Solver the fits were built with, e.g. "2.1.0".
std::string CeresVersion();

// "0.577 log K1 - 0.707 log K2 + 0.408 log C" (terms below 0.005 dropped).
std::string FormatCombination(const std::vector<double>& direction,
                              const std::vector<std::string>& names);

}  // namespace impactlab
