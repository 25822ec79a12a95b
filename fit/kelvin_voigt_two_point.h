// The closed-form Kelvin-Voigt fit from two rebound maxima and a contact time
// (thesis eq. 34-38; PENDUL option 1), generalised to any pair a < b.
//
// N = b - a impacts separate the maxima, each keeping the fraction e of the
// speed through equilibrium, so
//   ln e = [ln v(X_b) - ln v(X_a)] / N,   Lambda = 2 N ln e
//   zeta = sqrt(Lambda^2 / (Lambda^2 + 4 N^2 pi^2))         (eq. 36, kinematic)
//   K = M pi^2 / (tau_c^2 (1 - zeta^2)),  C = 2 zeta sqrt(K M)  (eq. 37, 38)
// with v(X) the pendulum's speed through equilibrium (model/pendulum.h: exact,
// or PENDUL's X_a sqrt(g/L) and 2 sqrt(gL) sin(X_b / 2L) in the thesis
// convention). Under force separation zeta and K follow from e and tau_c by
// that convention's relations instead. The predicted maximum of rebound n is
// the amplitude of the speed v(X_a) e^(n - a), also for n < a.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "model/contact.h"
#include "model/estimate.h"
#include "model/pendulum.h"
#include "options/result_fields.h"

namespace impactlab {

// One run's measured maxima in session numbering (rebound 0 is the table's
// first rebound, Figure 15) with their one-sigma uncertainties.
struct ReboundMeasurements {
  std::vector<double> xmax;            // length units
  std::vector<double> xmax_sigma;      // empty, or one per maximum (0 = exact)
  std::optional<double> contact_time;  // s
  double contact_time_sigma = 0.0;     // s
};

struct TwoPointOptions {
  std::array<int, 2> rebounds = {0, 1};  // a < b, session numbering
  Separation separation = Separation::kKinematic;
};

// An estimate with its name and units, as fits report their parameters.
struct NamedEstimate {
  std::string name;   // e.g. "zeta", "stiffness_1", "log_restitution"
  std::string units;  // "1", "s", "1/(in/s)", or a kind the results file resolves per unit
                      // system: "length", "stiffness", "damping", "speed"
  Estimate estimate;  // sigma = +inf along a direction the data do not determine
};

struct KelvinVoigtTwoPointFit {
  // False when the pair shows no dissipation (X_b > X_a): `reason` says
  // why, and no parameter below is meaningful.
  bool ok = false;
  std::string reason;
  std::string note;  // an ok fit's caveat (equal maxima: the elastic limit)
  std::array<int, 2> rebounds_used = {0, 1};
  Separation separation = Separation::kKinematic;

  Estimate log_restitution;  // ln e
  Estimate restitution;      // e
  Estimate damping_ratio;    // zeta
  // Present when a contact time was given.
  std::optional<double> contact_time;  // s, the value used
  std::optional<Estimate> stiffness;   // K, force/length
  std::optional<Estimate> damping;     // C, force*time/length

  std::vector<Estimate> predicted_xmax;  // model's X max of rebound 0, 1, ... (session numbering)

  // What the results file keeps as fields of a fit that succeeded
  // (options/result_fields.h); the status, the pair and the separation are
  // stored by the file's own layout.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("note", IfAny(self.note), Quantity::kDimensionless, "a caveat (equal maxima)");
    visit("zeta", EvenEmpty(self.damping_ratio), Quantity::kDimensionless, "zeta");
    visit("restitution", EvenEmpty(self.restitution), Quantity::kDimensionless, "e");
    visit("log_restitution", EvenEmpty(self.log_restitution), Quantity::kDimensionless, "ln e");
    visit("stiffness", self.stiffness, Quantity::kStiffness,
          "the run's own K, when a contact time is known");
    visit("damping", self.damping, Quantity::kDamping, "its C");
    visit("contact_time_used", self.contact_time, Quantity::kSeconds,
          "the contact time behind K and C");
    visit("predicted_xmax", self.predicted_xmax, Quantity::kLength,
          "the model's Xmax of rebound 0, 1, ...");
  }
};

// Why the measurements cannot be fitted (a maximum that is not a positive
// number, a contact time <= 0, a pair maximum no swing reaches, a model
// rebound 0 that would swing past the horizontal), empty when they can.
// Throws std::invalid_argument for a pair out of range or a sigma count that
// differs from the maxima's (a caller's slip).
std::string TwoPointRefusal(const Pendulum& pendulum, const ReboundMeasurements& measured,
                            const TwoPointOptions& options);

// Returns ok = false with the reason for measurements TwoPointRefusal
// refuses, and when X_b > X_a; throws as TwoPointRefusal does.
KelvinVoigtTwoPointFit FitKelvinVoigtTwoPoint(const Pendulum& pendulum, double mass,
                                              const ReboundMeasurements& measured,
                                              const TwoPointOptions& options);

// Amplitude of rebound `to` predicted from the maximum `from_x` of rebound
// `from` and a restitution: v(from_x) e^(to - from) converted back to an
// amplitude. Throws std::domain_error where PredictMaximumProblem says why.
double PredictMaximum(const Pendulum& pendulum, double from_x, int from, int to,
                      double log_restitution);

// Why PredictMaximum has no amplitude (`from_x` not in 0 <= X < L, a swing
// past the horizontal), in the model's words; empty when it has one.
std::string PredictMaximumProblem(const Pendulum& pendulum, double from_x, int from, int to,
                                  double log_restitution);

}  // namespace impactlab
