// Kelvin-Voigt by least squares: every rebound maximum of a run at once,
// weighted by its uncertainty, with an optional robust loss for outlier
// rebounds. The closed-form two-point fit (fit/kelvin_voigt_two_point.h, thesis
// eq. 34-38) uses two maxima; this uses them all.
//
// Model (docs/fitting.md): the maximum of rebound n (session numbering) is the
// amplitude of a swing through equilibrium at v0 e^n,
//   X_n = A(v0 exp(n ln e)),   A = AmplitudeFromSpeed (model/pendulum.h),
// with two parameters, ln e and ln v0 (v0: the speed at rebound 0, i.e. the
// effective release). Fitting ln e rather than zeta keeps the problem nearly
// linear and unconstrained; zeta follows from the restitution equivalence of
// the chosen separation (thesis eq. 44, model/kelvin_voigt.h), and its
// uncertainty by the derivative of that map. Residuals (X_n - X_n,measured)/sigma_n
// with analytic derivatives (dA/dv in closed form; no templated pendulum
// needed). K follows from the measured contact time (eq. 37 for kinematic
// separation, K = M (2 h(zeta)/tau_c)^2 for force), C = 2 zeta sqrt(K M)
// (eq. 38), with the uncertainties of zeta and tau_c propagated (independent).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "fit/kelvin_voigt_two_point.h"
#include "fit/least_squares.h"
#include "model/contact.h"
#include "model/pendulum.h"

namespace impactlab {

struct KelvinVoigtLeastSquaresOptions {
  Separation separation = Separation::kKinematic;
  LossOptions loss;  // robust loss on whitened residuals (scale in sigmas)
  SolverControl solver;
  // Directions whose singular value is below this times the largest are
  // reported as not determined (two parameters from two or more distinct
  // rebounds are always determined; the check guards degenerate input).
  double min_relative_singular_value = 1e-8;

  // The settings: the separation is the session's ([reduction] separation).
  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("loss", self.loss, "");
    visit("solver", self.solver, "");
    visit("min_relative_singular_value", self.min_relative_singular_value,
          "directions below this are not determined");
  }
  // False with `why` naming the bad field.
  bool Check(std::string* why) const;
};

struct KelvinVoigtLeastSquaresFit {
  FitStatus status;
  // True when the solve is usable, the data show dissipation (ln e < 0) and
  // the parameters are identifiable; otherwise `reason` says why and the
  // physical parameters are not meaningful.
  bool ok = false;
  std::string reason;
  Separation separation = Separation::kKinematic;

  Estimate log_restitution;            // ln e
  Estimate restitution;                // e
  Estimate damping_ratio;              // zeta
  Estimate rebound0_speed;             // v0, speed through equilibrium at rebound 0, length/s
  Estimate rebound0_xmax;              // A(v0): the model's maximum of rebound 0, length units
  std::optional<double> contact_time;  // s, the measured value used
  std::optional<Estimate> stiffness;   // K, force/length
  std::optional<Estimate> damping;     // C, force*time/length

  // Of (zeta, v0) and of the fitted (ln e, ln v0).
  ParameterCovariance covariance;
  ParameterCovariance fitted_covariance;
  std::vector<MaximumResidual> residuals;
  double chi2 = 0.0;  // sum of squared normalized residuals (no robust loss)
  int dof = 0;        // maxima - 2
  // Weighted fits: chi^2 against its dof. The estimates keep their stated
  // standard errors; the predicted maxima's are scaled by scatter.Scale().
  ScatterCheck scatter;
  Identifiability identifiability;  // over (ln e, ln v0)
  std::vector<Estimate>
      predicted_xmax;  // the model's maxima of rebounds 0, 1, ... (Birge-scaled sigma)

  // What the results file keeps of a fit that ran (options/result_fields.h,
  // docs/results.md's <least-squares fit>); the status (ok, and the reason
  // of a fit that failed or of one that holds with a caveat) by the file's
  // own layout. Not kept, as they follow from what is: the separation (the
  // session's), the contact time (the run's), the residuals but their
  // normalized values (the run's maxima and sigmas give the rest), the
  // covariances (the correlation and the estimates' errors give that of
  // (zeta, v0), which holds that of (ln e, ln v0)); nor are the solver's and
  // identifiability's details (FitStatus, Identifiability): each dataset more
  // lengthens every reduce, about half of which, for a typed-in session, is
  // writing the file.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    VisitLeastSquaresFields(self, visit);
    visit("zeta", EvenEmpty(self.damping_ratio), Quantity::kDimensionless, "zeta");
    visit("restitution", EvenEmpty(self.restitution), Quantity::kDimensionless, "e");
    visit("log_restitution", EvenEmpty(self.log_restitution), Quantity::kDimensionless, "ln e");
    visit("rebound0_xmax", EvenEmpty(self.rebound0_xmax), Quantity::kLength,
          "the model's Xmax of rebound 0");
    visit("rebound0_speed", EvenEmpty(self.rebound0_speed), Quantity::kSpeed,
          "v0, the speed through equilibrium at rebound 0");
    visit("stiffness", self.stiffness, Quantity::kStiffness, "K, with a contact time");
    visit("damping", self.damping, Quantity::kDamping, "C, with a contact time");
    visit("predicted_xmax", Column(self.predicted_xmax, &Estimate::value), Quantity::kLength,
          "the model's Xmax of rebound 0, 1, ...");
    visit("predicted_xmax_std_error", Column(self.predicted_xmax, &Estimate::sigma),
          Quantity::kLength, "their standard errors, Birge-scaled where the scatter is in excess");
  }
};

// Data it cannot take (fewer than two usable maxima, NaN entries skipped as
// unread; a maximum not in 0 < X < L; a mixture of zero and non-zero sigmas;
// a contact time <= 0) is a fit that did not run (status.Ran() false) with
// the reason. Throws std::invalid_argument only for bad options or mass
// (checked before any work by the caller) and a sigma count that differs
// from the maxima's. Returns a result with status and reason in every other
// case.
KelvinVoigtLeastSquaresFit FitKelvinVoigtLeastSquares(
    const Pendulum& pendulum, double mass, const ReboundMeasurements& measured,
    const KelvinVoigtLeastSquaresOptions& options);

}  // namespace impactlab
