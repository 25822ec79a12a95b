// Poynting-Thomson by least squares: K1, K2 and C (M known) from the rebound
// maxima, contact times and, optionally, peak compressions of one run or
// several runs jointly. The thesis gave up here ("no closed form"); this is the
// computer curve fit it called for.
//
// Model (docs/fitting.md): a linear contact keeps the fraction e(K1, K2, C) of
// the speed at every impact and lasts tau_c(K1, K2, C) whatever the speed, so
//   maximum of rebound n of run r:  A_r(v_r exp(n ln e))      (model/pendulum.h)
//   contact time of run r:          tau_c
//   peak compression of the impact after rebound k of run r: (x_peak/v0) v_r e^k
// with one speed v_r (at rebound 0) per run. Parameters: log K1, log K2, log C
// (bounded to a factor `bound_factor` either side of the start, so the solver
// is well conditioned across orders of magnitude) and ln v_r per run.
// Derivatives: e, tau_c and x_peak/v0 come from model/poynting_thomson.h (a
// root search inside); their derivatives in (log K1, log K2, log C) are central
// differences with step `difference_step` (1e-5: truncation ~1e-10, rounding
// ~2e-11 relative), computed once per parameter point and shared by all
// residuals; the pendulum part is analytic.
//
// Identifiability (the main finding, docs/fitting.md): maxima give ln e only;
// contact times add tau_c; because a linear model gives the same e and tau_c
// at every speed, more runs at other speeds add no third number, and K1, K2, C
// stay undetermined along one direction. A peak compression (or a fit of the
// compression history) supplies the third number. The result names the
// undetermined combination and reports e, tau_c and x_peak/v0, which stay
// determined, instead of confident K1, K2, C.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "fit/kelvin_voigt_least_squares.h"
#include "fit/least_squares.h"
#include "model/contact.h"
#include "model/pendulum.h"
#include "model/poynting_thomson.h"

namespace impactlab {

// The peak compression of one impact, read from a trace during contact.
struct PeakCompressionMeasurement {
  int after_rebound = 0;  // the impact that ends rebound `after_rebound` (session numbering)
  double value = 0.0;     // length units
  double sigma = 0.0;     // length units, > 0
};

struct PoyntingThomsonRun {
  std::string name;
  Pendulum pendulum;
  ReboundMeasurements measured;  // maxima (NaN = unread), optional contact time and sigma
  std::optional<PeakCompressionMeasurement> peak_compression;
};

struct PoyntingThomsonLeastSquaresOptions {
  double mass = 0.0;  // M, mass units (known)
  Separation separation = Separation::kKinematic;
  // Where the solver starts (its mass is ignored). Default: K1 = K, K2 = 10 K,
  // C = C of the Kelvin-Voigt model with the data's e and mean tau_c (or peak
  // compression). Required when the runs carry neither.
  std::optional<PoyntingThomson> initial;
  double bound_factor = 1e4;      // K1, K2, C stay within this factor of the start (> 1)
  double difference_step = 1e-5;  // central-difference step in log K1, log K2, log C
  double min_relative_singular_value = 1e-6;  // below: that direction is not determined
  LossOptions loss;                           // robust loss on whitened residuals
  SolverControl solver;

  // The settings: the mass, separation and start are the session's and the runs'.
  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("bound_factor", self.bound_factor, "K1, K2, C stay within this factor of the start");
    visit("difference_step", self.difference_step, "central-difference step in log K1, K2, C");
    visit("min_relative_singular_value", self.min_relative_singular_value,
          "directions below this are not determined");
    visit("loss", self.loss, "");
    visit("solver", self.solver, "");
  }
  // False with `why` naming the bad field (the settings and the start; the
  // mass is checked by the fit).
  bool Check(std::string* why) const;
};

// One run of the fit (its maxima's residuals are the fit's, by run index).
struct PoyntingThomsonRunFit {
  std::string name;
  Estimate rebound0_speed;                        // v_r, length/s
  std::optional<double> contact_time_normalized;  // (measured - model)/sigma
  std::optional<double> peak_normalized;          // (measured - model)/sigma
};

struct PoyntingThomsonLeastSquaresFit {
  FitStatus status;
  // True when the solve converged to a usable point and K1, K2, C are all
  // determined; otherwise `reason` says why (non-identifiable: which
  // combination is undetermined).
  bool ok = false;
  std::string reason;
  Separation separation = Separation::kKinematic;
  PoyntingThomson model;  // the solution point (with the given mass)

  // sigma = +infinity for a parameter with a component along an undetermined
  // direction: the value is then one arbitrary point of a valley.
  Estimate stiffness1, stiffness2, damping;
  // What the data determine even when K1, K2, C are not (sigma infinite when
  // not): ln e, e, tau_c (s), x_peak/v0 (s).
  Estimate log_restitution, restitution, contact_time, peak_per_speed;
  bool at_bound = false;  // some parameter ended on its bound (covariance not meaningful there)

  std::vector<PoyntingThomsonRunFit> runs;
  std::vector<MaximumResidual> residuals;  // every run's maxima, the runs in turn
  // Over log K1, log K2, log C, then ln v_r per run (Moore-Penrose
  // pseudo-inverse when not identifiable: meaningful only along determined
  // directions).
  ParameterCovariance covariance;
  double chi2 = 0.0;  // sum of squared normalized residuals (no robust loss)
  int dof = 0;        // residuals - parameters
  // Weighted fits: chi^2 against its dof; the estimates keep their stated
  // standard errors.
  ScatterCheck scatter;
  Identifiability identifiability;  // of (log K1, log K2, log C), per-run speeds profiled out

  // What the results file keeps of a fit that ran (options/result_fields.h,
  // docs/results.md's <least-squares fit>); the status (ok and reason) by
  // the file's own layout. Not kept, as they follow from what is: the
  // separation (the session's), the model (K1, K2, C are the estimates';
  // M the session's), the residuals but their normalized values; nor are the
  // runs' speeds, contact-time and peak residuals, the covariance (the
  // correlation is), whether it ended on a bound (its reason says so), and
  // the solver's and identifiability's details (FitStatus,
  // Identifiability): each dataset more lengthens every reduce, about half
  // of which, for a typed-in session, is writing the file.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    VisitLeastSquaresFields(self, visit);
    visit("stiffness_1", EvenEmpty(self.stiffness1), Quantity::kStiffness, "K1");
    visit("stiffness_2", EvenEmpty(self.stiffness2), Quantity::kStiffness, "K2");
    visit("damping", EvenEmpty(self.damping), Quantity::kDamping, "C");
    visit("log_restitution", EvenEmpty(self.log_restitution), Quantity::kDimensionless, "ln e");
    visit("restitution", EvenEmpty(self.restitution), Quantity::kDimensionless, "e");
    visit("contact_time", EvenEmpty(self.contact_time), Quantity::kSeconds, "tau_c");
    visit("peak_per_speed", EvenEmpty(self.peak_per_speed), Quantity::kSeconds,
          "the peak compression per impact speed");
  }
};

// Data it cannot take (no runs, a run without a usable maximum or with one
// not in 0 < X < L, inconsistent uncertainties: all observations need
// sigma > 0, or none may and then only maxima are fitted; no time scale to
// start from) is a fit that did not run (status.Ran() false) with the
// reason. Throws std::invalid_argument only for bad options or mass (the
// caller checks them before any work). Everything else, including a start
// where contact never ends, is a result with a status.
PoyntingThomsonLeastSquaresFit FitPoyntingThomsonLeastSquares(
    const std::vector<PoyntingThomsonRun>& runs, const PoyntingThomsonLeastSquaresOptions& options);

}  // namespace impactlab
