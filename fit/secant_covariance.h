// A least-squares fit's parameter covariance from secants of its residuals
// along the Jacobian's singular directions, each secant spanning a few of the
// standard errors it yields (docs/two-link-fit.md, "Uncertainty").
//
// The usual covariance, (J^T J)^-1 from the Jacobian at the minimum, holds
// when the residuals respond linearly over the scale on which noise moves the
// minimum. A simulated history after an impact does not: its difference
// quotients over a fixed step carry the response's curvature and roughness,
// and in a weak direction v, where J v is what remains after the columns
// cancel, those errors make |J v| wrong by factors. The secant
// (r(x + h v) - r(x - h v)) / 2h with h a few standard errors along v
// measures the response on the scale that matters. The steps start from the
// Jacobian's own sigma along each direction and are iterated until each is
// the chosen multiple of the sigma its secants give.
//
// Where the residuals are linear over the steps, the secants equal J v and
// the covariance is (J^T J)^-1 exactly.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Dense>

namespace impactlab {

struct SecantCovarianceOptions {
  double step_in_sigmas = 2.0;       // each secant spans +- this many of its direction's sigma
  double undetermined_ratio = 1e-3;  // singular value / largest below this: left out
  int max_rounds = 4;                // rounds of secants (the first from the Jacobian's sigma)
  double step_tolerance = 0.25;      // a direction is settled when its step is within this
                                     // fraction of step_in_sigmas x its sigma
  // The first round's half-spans, per direction (e.g. a previous call's
  // `steps`, 0 where none); empty: step_in_sigmas / singular value.
  std::vector<double> first_steps;
};

// The residual vectors at several points, in order; nullopt where a point
// cannot be evaluated. The same weighting as the Jacobian's rows.
using ResidualsAtPoints = std::function<std::vector<std::optional<Eigen::VectorXd>>(
    const std::vector<Eigen::VectorXd>& points)>;

struct SecantCovariance {
  Eigen::MatrixXd covariance;       // p x p, from the determined directions only
  Eigen::MatrixXd directions;       // the Jacobian's right singular vectors, as columns
  Eigen::VectorXd singular_values;  // the Jacobian's, largest first
  std::vector<bool> determined;     // per direction: singular value ratio >= undetermined_ratio
  // Per direction: the secants' sigma over the Jacobian's (1 / singular
  // value); 1 where the response is linear over the steps; 0 if undetermined.
  std::vector<double> sigma_ratios;
  std::vector<double> steps;        // per direction, the last secants' half-span
  std::vector<bool> secant_failed;  // per direction: a secant point could not be evaluated,
                                    // the Jacobian's J v kept
  int evaluations = 0;              // residual vectors asked for
  int rounds = 0;
  Eigen::MatrixXd basis;    // p x d: the determined directions, as columns
  Eigen::MatrixXd secants;  // rows x d: the residuals' response along each, per unit step
};

// `jacobian` is the residuals' Jacobian at the minimum `x`, its rows weighted
// as `residuals_at` weights them.
SecantCovariance SecantCovarianceAt(const Eigen::VectorXd& x, const Eigen::MatrixXd& jacobian,
                                    const ResidualsAtPoints& residuals_at,
                                    const SecantCovarianceOptions& options = {});

// The sandwich B M B, B = (A^T A)^-1, A the secants with each row multiplied
// by `row_scale` (empty: as they are), for an estimator that minimises the
// so-scaled residuals' squares when the errors behind them are not
// independent with unit variance: `meat` is M = cov(A^T e) for the error e,
// in the determined directions' coordinates (d x d). Returned p x p.
Eigen::MatrixXd SecantSandwich(const SecantCovariance& secant, const Eigen::VectorXd& row_scale,
                               const Eigen::MatrixXd& meat);

// The Gauss-Newton step that the secants give towards the least-squares
// minimum from a point with `residuals`: -B (A^T A)^-1 A^T r over the
// determined directions B, A the secants with each row multiplied by
// `row_scale` (to undo the covariance's row weights, say; empty: as they are).
// A minimiser that found its way with differences over a fixed step stops
// where those differences, not the secants, say the gradient vanishes; along
// a weak direction that can be several sigma from the minimum.
Eigen::VectorXd SecantStep(const SecantCovariance& secant, const Eigen::VectorXd& residuals,
                           const Eigen::VectorXd& row_scale = {});

}  // namespace impactlab
