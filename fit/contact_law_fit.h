// Contact laws fitted across a session's runs: maxima at the several impact
// speeds of every run, and the runs' measured contact times (docs/contact-laws.md).
//
// Run r's rebound 0 swings through equilibrium at v_{r,0} = exp(w_r) (a
// nuisance parameter, as in the joint fits); each impact keeps the fraction
// e(v) of the speed it meets, v_{r,n+1} = e(v_{r,n}) v_{r,n}, and the maxima are
// X_{r,n} = A_r(v_{r,n}). A run's measured contact time belongs to the impact
// at v_{r,c} (c = its `contact_rebound`; -1: the release's impact, at the
// known speed of the release from X0). Residuals are whitened by the
// measurements' sigmas; derivatives are exact (ceres::Jet through the laws'
// closed forms and the Hunt-Crossley quadrature, whose restitution enters by
// the implicit-function theorem; at n = 3/2 through the Chebyshev tables of
// Hunt-Crossley's and the damper's e and contact time and their derivative
// series, model/power_law_tables.h); parameters are fitted as logarithms.
//
// The laws and what fixes their parameters:
//   kelvin-voigt     e and tau_c the same at every speed: zeta from the maxima,
//                    K from the contact times (K = M (pi/tau_c)^2/(1 - zeta^2), kinematic)
//   hertz            elastic (e = 1): the maxima cannot decay; k from the contact times
//   hunt-crossley    e = e(chi v) from the maxima alone; k from the contact times; n = 3/2
//   hunt-crossley-n  n free as well: tau_c ~ v^(-(n-1)/(n+1)) needs contact times
//                    at two or more speeds
//   hertz-damper     F = k x^n + c x' (n fixed): e depends on c k^(-1/(n+1)) and the
//                    speed, so the maxima fix that combination and the contact
//                    times k; without contact times it is not fitted. Its
//                    derivatives come from the variational equations of the
//                    integration (model/contact_integration.h)
// A parameter the data cannot fix is left out of the fit and named in the
// `identifiability` sentence.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "fit/kelvin_voigt_two_point.h"
#include "fit/least_squares.h"
#include "model/contact.h"
#include "model/pendulum.h"
#include "options/result_fields.h"

namespace impactlab {

enum class ContactLawKind {
  kKelvinVoigt,
  kHertz,
  kHuntCrossley,
  kHuntCrossleyExponent,
  kHertzDamper
};
const char* ContactLawName(ContactLawKind kind);  // "kelvin-voigt", "hertz", ...

struct LawRun {
  std::string name;
  Pendulum pendulum;
  double mass = 0.0;                  // M of the impacting body, mass units
  double initial_displacement = 0.0;  // X0
  // Maxima in session numbering with sigmas > 0 (NaN = unread); the contact
  // time with its sigma when the run has its own (sigma > 0), else none.
  ReboundMeasurements measured;
  int contact_rebound = 0;  // the contact time's impact follows this rebound (-1: the release)
};

struct ContactLawFitOptions {
  Separation separation = Separation::kKinematic;  // Kelvin-Voigt's convention
  double exponent = 1.5;                           // n where it is not fitted
  bool use_contact_times = true;                   // false: the maxima alone
  bool leave_one_out = true;                       // also refit without each run (3 runs or more)
  bool intervals = true;                           // each parameter's 68 % interval
  // Where the chi^2 profile's rise at the linearised ends (1 sigma out) is off
  // 1 by more than this fraction, the interval comes from the profile.
  double profile_tolerance = 0.2;
  SolverControl solver;
  double min_relative_singular_value = 1e-8;

  // The settings: the separation is the session's; what data to use, and
  // whether to refit without each run or give intervals, is the pipeline's
  // (the products asked for, pipeline/products.h).
  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("exponent", self.exponent, "n of the Hertz and Hunt-Crossley laws where not fitted");
    visit("profile_tolerance", self.profile_tolerance,
          "profile-likelihood interval where the chi2 rise at 1 sigma is off 1 by more");
    visit("solver", self.solver, "");
    visit("min_relative_singular_value", self.min_relative_singular_value,
          "directions below this are not determined");
  }
  bool Check(std::string* why) const;
};

// A parameter's 68 % interval: the linearised value ± sigma (Birge-scaled
// where the scatter is in excess) where the chi^2 profile agrees with it, else
// the profile-likelihood interval, where the profile min chi^2(theta_i) rises
// by s^2 (s the Birge scale) above its minimum.
struct ParameterInterval {
  std::string name;
  double lower = 0.0, upper = 0.0;  // in the parameter's own units
  bool profile = false;             // from the profile (the linearisation was off)
  // The profile's rise at the linearised ends, in units of s^2 (1 where the
  // chi^2 is quadratic there); NaN where not evaluated.
  double rise_at_lower = 0.0, rise_at_upper = 0.0;
  bool at_bound = false;  // an end stopped at a bound of the parameter (n in [0.5, 5])
};

struct ContactLawFit {
  std::string law;  // ContactLawName
  bool ok = false;
  std::string reason;           // why not, when !ok
  std::string identifiability;  // one sentence: which data fix which parameter
  FitStatus status;             // seconds: the whole fit, leave-one-out included

  // The law's parameters with their stated standard errors (from the
  // measurements' sigmas) and, in `scatter`, the Birge ratio that scales them.
  std::vector<NamedEstimate> parameters;
  ParameterCovariance covariance;  // of the fitted logarithms (and n)
  ScatterCheck scatter;
  std::vector<Estimate> run_rebound0_speed;  // fitted v_{r,0}
  std::vector<ParameterInterval> intervals;  // one per parameter, same order

  int maxima = 0;
  int contact_times = 0;
  int parameter_count = 0;  // law parameters fitted + one nuisance per run
  int dof = 0;
  double chi2_maxima = 0.0;
  double chi2_contact = 0.0;
  double chi2 = 0.0;
  double aic = 0.0;  // chi2 + 2 k
  double bic = 0.0;  // chi2 + k ln N

  // Leave-one-run-out: refit without the run, predict its maxima from its
  // measured rebound 0 (and its contact time); RMS of (predicted - measured)/sigma.
  bool loo_ok = false;
  double loo_rms_normalized = 0.0;
  double loo_rms_length = 0.0;
  int loo_maxima = 0;

  // The material constant k holds where the session's specimen makes it
  // identifiable (fit/effective_modulus.h): E* from hertz_stiffness through
  // the ends' sphere radius, the handbook's E* beside it where E and nu are
  // given, and, for a specimen that does not make E* identifiable, why.
  std::optional<Estimate> effective_modulus;
  std::optional<double> handbook_effective_modulus;
  std::string effective_modulus_unidentifiable;

  // What the results file keeps as fields (options/result_fields.h). The
  // parameters, their intervals' ends and methods, and the leave-one-out RMS
  // (only where it ran) are stored by the file's own layout. Not kept: the
  // status but its time (ok and reason are the group's status), the
  // covariance's correlation (its matrix gives it) and whether it was scaled
  // by the residuals (never: the laws' maxima carry their sigmas).
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("identifiability", self.identifiability, Quantity::kDimensionless,
          "which data fix which parameter");
    visit("maxima", self.maxima, Quantity::kDimensionless, "maxima fitted");
    visit("contact_times", self.contact_times, Quantity::kDimensionless, "contact times fitted");
    visit("parameter_count", self.parameter_count, Quantity::kDimensionless,
          "law parameters and one rebound-0 speed per run");
    visit("dof", self.dof, Quantity::kDimensionless, "degrees of freedom");
    visit("rebound0_speed", self.run_rebound0_speed, Quantity::kSpeed,
          "each run's fitted rebound-0 speed, in the runs' order");
    visit("chi2", self.chi2, Quantity::kDimensionless, "chi-square");
    visit("chi2_maxima", self.chi2_maxima, Quantity::kDimensionless, "its maxima's share");
    visit("chi2_contact", self.chi2_contact, Quantity::kDimensionless, "its contact times' share");
    visit("aic", self.aic, Quantity::kDimensionless, "chi2 + 2 k");
    visit("bic", self.bic, Quantity::kDimensionless, "chi2 + k ln N");
    ScatterCheck::VisitFields(self.scatter, visit);
    visit("leave_one_out_ok", self.loo_ok, Quantity::kDimensionless,
          "1 when every run was left out and predicted");
    visit("leave_one_out_maxima", self.loo_maxima, Quantity::kDimensionless,
          "maxima the left-out runs' predictions were compared with");
    visit("seconds", self.status.seconds, Quantity::kSeconds, "the fit's wall time");
    visit("covariance", Square(self.covariance.matrix), Quantity::kDimensionless,
          "the covariance of the law's fitted parameters (their logarithms; n as it is)");
    visit("covariance@parameter_names", self.covariance.names, Quantity::kDimensionless,
          "its rows, e.g. log k, log chi, n");
    visit("interval_rise_at_lower", Column(self.intervals, &ParameterInterval::rise_at_lower),
          Quantity::kDimensionless,
          "per parameter: the chi2 profile's rise at the linear interval's lower end, in s^2");
    visit("interval_rise_at_upper", Column(self.intervals, &ParameterInterval::rise_at_upper),
          Quantity::kDimensionless, "and at its upper end");
    visit("effective_modulus", self.effective_modulus, Quantity::kPressure,
          "E* = 3 k / (8 sqrt(R)) where the ends are spheres of radius R");
    visit("handbook_effective_modulus", self.handbook_effective_modulus, Quantity::kPressure,
          "E / (2 (1 - nu^2)) from the specimen's handbook modulus and Poisson ratio");
    visit("effective_modulus_unidentifiable", IfAny(self.effective_modulus_unidentifiable),
          Quantity::kDimensionless, "why the specimen does not make E* identifiable");
  }
};

// Why the runs' data cannot fix the law's parameters, so that it is not
// fitted; empty when they can. Kelvin-Voigt and Hunt-Crossley (n fixed) are
// fixed by the maxima alone; Hertz and Hertz with a damper need a run's own
// contact time (with a sigma) to fix k; Hunt-Crossley with n free needs
// contact times at impact speeds spread enough that the line of ln tau_c on
// ln v would fix n to +-1 or better (tau_c ~ v^(-(n-1)/(n+1)) at the fixed n).
std::string ContactLawUninformed(ContactLawKind kind, const std::vector<LawRun>& runs,
                                 const ContactLawFitOptions& options);

// Runs it cannot be fitted to (fewer than two, a run without two read
// maxima, a maximum without sigma > 0) are a fit that is not ok, with the
// reason and the law's name, and status.Ran() false. Throws
// std::invalid_argument only for bad options or a non-positive mass or X0
// (the manifest's reader refuses those before any work).
ContactLawFit FitContactLaw(ContactLawKind kind, const std::vector<LawRun>& runs,
                            const ContactLawFitOptions& options);

}  // namespace impactlab
