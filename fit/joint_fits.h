// Joint Kelvin-Voigt fits across the runs of a session, and which restitution
// model predicts unseen runs best (docs/fitting.md, "Joint fits and model
// comparison").
//
// Every model fits ALL maxima of the chosen runs at once, with whitened
// residuals (X_model - X_measured)/sigma and one nuisance parameter per run,
// w_r = ln v_r (the speed through equilibrium at the run's rebound 0):
//   X_{r,n} = A_r(exp(w_r + n q_r)),   q_r = ln e of run r,
// A_r = AmplitudeFromSpeed of run r's pendulum. The models differ in q_r:
//   "per-run"          q_r free for each run (the same as separate fits);
//   "common"           q_r = q for every run;
//   "linear-in-speed"  q_r = a + b (u_r - u_ref), u_r = SpeedFromAmplitude(X0_r)
//                      the run's impact speed from its initial displacement (a
//                      fixed, exactly known covariate, so the model stays linear
//                      in (a, b) and well-posed; the fitted v_r would make the
//                      covariate depend on the nuisance parameters), u_ref the
//                      mean u_r of the fitted runs.
// Not a model here: the thesis's eq. 40, C linear in sqrt(xi). Per run, C and
// xi (= e) both follow from the same fitted ln e (C = 2 zeta(ln e) sqrt(K M)),
// so the line is a correlation between two functions of one number, not a
// law that predicts e of a new run: to evaluate C at a new run's sqrt(e) one
// needs that run's e, which is what was to be predicted. A predictive form
// must use a quantity known before the impact, such as the impact speed.
//
// Criteria per model: chi^2, dof = N - k, AIC = chi^2 + 2k, BIC = chi^2 + k ln N
// (k counts the nuisance parameters too), and the leave-one-run-out error:
// refit on the other runs, predict the held-out run's maxima from its measured
// rebound 0 through the model's e for that run, and take the RMS of
// (predicted - measured)/sigma (and in length units) over all held-out maxima.
#pragma once

#include <string>
#include <vector>

#include "fit/kelvin_voigt_two_point.h"
#include "fit/least_squares.h"
#include "model/pendulum.h"
#include "options/result_fields.h"

namespace impactlab {

struct JointRun {
  std::string name;
  Pendulum pendulum;
  ReboundMeasurements measured;       // maxima with sigmas (> 0), NaN = unread
  double initial_displacement = 0.0;  // X0 of the release, length units (> 0)
};

struct JointFitOptions {
  std::vector<std::string> runs;  // names of the runs to use; empty = all
  SolverControl solver;
  double min_relative_singular_value = 1e-10;  // below: the model is not identifiable
  bool leave_one_out = true;                   // refit without each run (the pipeline's)

  // The settings: which runs is the session's.
  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("solver", self.solver, "");
    visit("min_relative_singular_value", self.min_relative_singular_value,
          "below this the model is not identifiable");
  }
  bool Check(std::string* why) const;
};

// Leave-one-run-out prediction error of a model.
struct LeaveOneOut {
  bool ok = false;              // every held-out run could be predicted
  double rms_normalized = 0.0;  // RMS of (predicted - measured)/sigma over held-out maxima
  double rms_length = 0.0;      // RMS of predicted - measured, length units
  int maxima = 0;               // held-out maxima predicted (rebound 0 is the start, not counted)
  std::vector<double> run_rms_normalized;   // per held-out run, in run order
  std::vector<double> run_log_restitution;  // ln e used for each held-out run

  // What the results file keeps of it, as a model's list takes it in
  // (options/result_fields.h), under the names a contact law's leave-one-out
  // has. Not kept: the per-run RMS and ln e (the comparison judges by the
  // total; each dataset more lengthens every reduce).
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("leave_one_out_ok", self.ok, Quantity::kDimensionless,
          "1 when every held-out run was predicted");
    visit("leave_one_out_maxima", self.maxima, Quantity::kDimensionless,
          "held-out maxima predicted (0: not made)");
    visit("leave_one_out_rms_normalized", IfAny(self.rms_normalized), Quantity::kDimensionless,
          "leave one run out: RMS of (predicted - measured)/sigma, when made");
    visit("leave_one_out_rms", IfAny(self.rms_length), Quantity::kLength, "the same in length");
  }
};

struct JointModelFit {
  std::string name;  // "per-run", "common", "linear-in-speed"
  FitStatus status;
  bool ok = false;  // usable solve and identifiable; otherwise `reason` says why
  std::string reason;

  // The model's parameters (nuisance ln v_r excluded), with standard errors
  // from (J^T J)^-1 of the whitened residuals (nuisance parameters included in J).
  std::vector<NamedEstimate> parameters;
  ParameterCovariance covariance;             // of `parameters`
  double reference_speed = 0.0;               // u_ref (linear-in-speed), length/s
  std::vector<Estimate> run_log_restitution;  // the model's ln e of each run, in run order
  std::vector<Estimate> run_rebound0_speed;   // fitted v_r, length/s

  int maxima = 0;           // N
  int parameter_count = 0;  // k, nuisance included
  int dof = 0;              // N - k
  double chi2 = 0.0;
  // chi^2 against dof: significantly high, the sigmas understate the
  // scatter, and the standard errors are to be multiplied by the Birge ratio.
  ScatterCheck scatter;
  double aic = 0.0;
  double bic = 0.0;
  // Inverse-variance weighted mean and standard deviation across runs of
  // the model's per-run ln e (0 for "common").
  double log_restitution_mean = 0.0;
  double log_restitution_spread = 0.0;
  LeaveOneOut leave_one_out;

  // The model's ln e for a run released from `initial_displacement` on
  // `pendulum` (per-run: the weighted mean of the runs' ln e).
  double LogRestitutionFor(const Pendulum& pendulum, double initial_displacement) const;

  // What the results file keeps of a model that was fitted
  // (options/result_fields.h); the status (ok and reason), the parameters by
  // name are stored by the file's own layout, the covariance as this
  // correlation times the parameters' errors.
  // Not kept: the name (the group's);
  // each run's ln e (per-run's are its parameters; the others' follow from
  // the parameters and the runs' speeds); the runs' fitted speeds (nuisance
  // parameters, left out of the correlation too) and the solver's details
  // (FitStatus: a failed solve's message is its reason), as each dataset
  // more lengthens every reduce.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("maxima", self.maxima, Quantity::kDimensionless, "N, the maxima fitted");
    visit("parameter_count", self.parameter_count, Quantity::kDimensionless,
          "k, the per-run speeds included");
    visit("dof", self.dof, Quantity::kDimensionless, "N - k");
    visit("chi2", self.chi2, Quantity::kDimensionless, "chi-square");
    visit("aic", self.aic, Quantity::kDimensionless, "chi2 + 2 k");
    visit("bic", self.bic, Quantity::kDimensionless, "chi2 + k ln N");
    ScatterCheck::VisitFields(self.scatter, visit);
    visit("log_restitution_spread", self.log_restitution_spread, Quantity::kDimensionless,
          "the weighted standard deviation of the runs' ln e");
    visit("log_restitution_mean", IfAny(self.log_restitution_mean), Quantity::kDimensionless,
          "their weighted mean, which per-run gives an unseen run");
    visit("reference_speed", IfAny(self.reference_speed), Quantity::kSpeed,
          "linear-in-speed: u_ref, the runs' mean impact speed");
    LeaveOneOut::VisitFields(self.leave_one_out, visit);
    visit("correlation", Square(self.covariance.correlation), Quantity::kDimensionless,
          "the correlation of the model's parameters");
    visit("correlation@parameter_names", self.covariance.names, Quantity::kDimensionless,
          "its rows");
  }
};

struct SessionModelComparison {
  // False when the runs cannot be compared: `reason` says why, and nothing
  // below is filled.
  bool ok = false;
  std::string reason;
  std::vector<std::string> run_names;  // the runs used, in input order
  std::vector<double> impact_speeds;   // u_r = SpeedFromAmplitude(X0_r), length/s
  std::vector<JointModelFit> models;   // per-run, common, linear-in-speed
  std::string best_by_leave_one_out;   // lowest LOO rms_normalized ("" if none)
  std::string best_by_bic;
  double seconds = 0.0;  // wall time of the whole comparison
};

// Runs it cannot compare (fewer than two; three for the LOO of
// linear-in-speed to be defined; a run with fewer than two read maxima, or a
// maximum without sigma > 0 or not > 0) are a comparison that is not ok,
// with the reason. Throws std::invalid_argument only for bad options, an
// unknown run name in options.runs, or a non-positive initial displacement
// (the manifest's reader refuses those before any work).
SessionModelComparison CompareRestitutionModels(const std::vector<JointRun>& runs,
                                                const JointFitOptions& options);

// The maxima of rebounds 0 .. count-1 of a run whose rebound 0 reaches
// `start_xmax`, each keeping the fraction exp(log_restitution) of the speed
// through equilibrium (element 0 is start_xmax).
std::vector<double> PredictMaxima(const Pendulum& pendulum, double start_xmax, int count,
                                  double log_restitution);

}  // namespace impactlab
