// Constants several sessions share, fitted by generalised least squares on
// the sessions' own estimates and their covariances (docs/campaigns.md).
//
// Session i states y_i (d_i numbers) with covariance C_i, and the shared
// constants theta (p of them) predict it as H_i theta. Each session's own
// parameters (its runs' speeds) are already profiled out of C_i by its fit,
// so the sessions are independent and
//   theta = A^-1 sum H_i' C_i^-1 y_i,  A = sum H_i' C_i^-1 H_i,  cov = A^-1,
//   chi^2 = sum r_i' C_i^-1 r_i,  dof = sum d_i - p,  Birge ratio sqrt(chi^2/dof).
// A session's pull is measured against the fit without it (leave one out):
// (y_i - H_i theta_(-i)) / sqrt(diag(C_i + H_i A_(-i)^-1 H_i')), so a session
// far off does not drag the constants towards itself and hide.
//
// Sessions that pull away are set aside one at a time, the farthest first,
// and the constants fitted again without them, until no session left pulls
// beyond the threshold: one far-off session would otherwise drag the fit the
// others are measured against, and make them pull in turn.
#pragma once

#include <string>
#include <vector>

namespace impactlab {

struct SessionStatement {
  std::string session;
  std::vector<double> values;      // y_i
  std::vector<double> covariance;  // C_i, d_i x d_i, row-major
  std::vector<double> design;      // H_i, d_i x p, row-major
  std::vector<int> constants;      // per value, the constant it states (for the pulls' names)
};

struct SharedFit {
  bool ok = false;
  std::string reason;              // why not, when !ok
  std::vector<double> values;      // theta
  std::vector<double> covariance;  // A^-1, p x p
  std::vector<double> sigma;       // sqrt(diag(A^-1))
  double chi2 = 0.0;
  int dof = 0;
  double birge_ratio = 1.0;  // sqrt(chi2 / dof); 1 when dof = 0
  double p_value = 1.0;      // P(chi2_dof >= chi2)
  // One per stated value: the session, the constant and its pull (none where
  // the other sessions alone do not fix the constants: then not computed).
  std::vector<std::string> pull_session;
  std::vector<int> pull_constant;
  std::vector<double> pull;
  // The sessions set aside as pulling away, in the order they were; the
  // constants, chi2 and dof are the others'. Their pulls are against them.
  std::vector<std::string> set_aside;
};

// Throws std::invalid_argument for statements of inconsistent sizes or a
// covariance that is not positive definite. Not ok (with why) when the
// statements do not fix every constant. `pull_threshold`: sessions with a
// |pull| beyond it are set aside (infinite: none is).
SharedFit FitSharedConstants(const std::vector<SessionStatement>& statements, int constants,
                             double pull_threshold);

// The |pull| beyond which a session is said to pull away: the two-sided
// normal quantile that holds the chance of naming any of `pulls` clean
// pulls to `false_alarm` (Bonferroni), and at least 3.
double PullThreshold(std::size_t pulls, double false_alarm);

}  // namespace impactlab
