// Kelvin-Voigt parameters across the runs of a session (thesis Tables 3 and 4,
// eq. 40): how K and C vary with the square root of the restitution, and
// predicting one run from another run's parameters.
#pragma once

#include <string>
#include <vector>

#include "fit/kelvin_voigt_two_point.h"

namespace impactlab {

// Table 3: each K against the session's average.
struct StiffnessSpread {
  double average = 0.0;               // K_avg
  std::vector<double> deviation;      // K - K_avg
  std::vector<double> pct_variation;  // 100 |K - K_avg| / K_avg
};
StiffnessSpread SpreadOf(const std::vector<double>& stiffness);

// The thesis's design expedient ([reduction] average_stiffness): one K, the
// runs' mean, for every run, and each run's C from it at the run's own
// damping ratio, C = 2 zeta sqrt(K_avg M). The runs' own fits are unchanged.
struct AverageStiffness {
  Estimate stiffness;             // K_avg; sigma from the runs' own, as independent
  std::vector<Estimate> damping;  // C per fit, in the order given
};
// `fits`: two-point fits that carry a stiffness. Throws std::invalid_argument
// when there are none.
AverageStiffness AverageStiffnessOf(const std::vector<const KelvinVoigtTwoPointFit*>& fits,
                                    double mass);

// Eq. 40: C = a (1 - b sqrt(xi)), fitted by ordinary least squares as
// C = alpha + beta sqrt(xi), a = alpha, b = -beta / alpha. Standard errors
// from the residual scatter (n - 2 degrees of freedom); zero with two runs,
// where the line passes through both points and the scatter is unknown.
struct DampingLine {
  Estimate a;  // damping units
  Estimate b;  // 1
  double correlation_ab = 0.0;
  double rms_residual = 0.0;  // damping units
  int points = 0;

  // What the results file keeps as fields (options/result_fields.h).
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("a", EvenEmpty(self.a), Quantity::kDamping, "a of C = a (1 - b sqrt(xi))");
    visit("b", EvenEmpty(self.b), Quantity::kDimensionless, "b");
    visit("correlation_ab", self.correlation_ab, Quantity::kDimensionless,
          "the correlation of a and b");
    visit("rms_residual", self.rms_residual, Quantity::kDamping, "RMS residual");
    visit("points", self.points, Quantity::kDimensionless, "the runs it was fitted to");
  }
};
// The line, or why the runs give none (fewer than two, or all of one
// restitution): `line` is meaningful only when `ok`.
struct DampingLineFit {
  bool ok = false;
  std::string reason;
  DampingLine line;  // `points` is set either way
};
// Throws std::invalid_argument only for columns of different lengths (a
// caller's slip); runs that give no line are a result that is not ok.
DampingLineFit FitDampingLine(const std::vector<double>& sqrt_restitution,
                              const std::vector<double>& damping);

// Table 4 (PENDUL option 3): a target run's rebounds predicted from a source
// run's restitution, starting at the target's measured `start_rebound`,
// beside the target's own fit ("calculated").
struct RunPrediction {
  std::string source_run;
  std::string target_run;
  int start_rebound = 0;
  double start_xmax = 0.0;         // the target's measured maximum the prediction starts from
  std::vector<double> predicted;   // rebound start_rebound, start_rebound + 1, ...
  std::vector<double> calculated;  // the target's own two-point fit
  std::vector<double> deviation;   // calculated - predicted
  std::vector<double> pct_peak;    // 100 deviation / calculated
  std::vector<double> pct_start;   // 100 deviation / start_xmax (Table 4's "% X0")

  // What the results file keeps as fields (options/result_fields.h); the
  // rebounds' dimension scale is the file's layout.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("source_run", self.source_run, Quantity::kDimensionless, "the run predicted from");
    visit("target_run", self.target_run, Quantity::kDimensionless, "the run predicted");
    visit("start_rebound", self.start_rebound, Quantity::kDimensionless,
          "the target's rebound the prediction starts from");
    visit("start_xmax", self.start_xmax, Quantity::kLength,
          "the target's measured maximum of start_rebound");
    visit("predicted_xmax", self.predicted, Quantity::kLength, "from the source run's restitution");
    visit("calculated_xmax", self.calculated, Quantity::kLength, "the target's own fit");
    visit("deviation", self.deviation, Quantity::kLength, "calculated - predicted");
    visit("deviation_pct_peak", self.pct_peak, Quantity::kPercent, "% of calculated");
    visit("deviation_pct_start", self.pct_start, Quantity::kPercent, "% of start_xmax");
  }
};

// The prediction, or why the runs cannot give it (a run without a
// Kelvin-Voigt fit, a start rebound the target did not measure): then
// `prediction` holds only the runs' names and the start rebound.
struct PredictedRun {
  bool ok = false;
  std::string reason;
  RunPrediction prediction;
};
// Nothing is thrown for runs that cannot give the prediction.
PredictedRun PredictRun(const Pendulum& pendulum, const std::string& source_run,
                        const KelvinVoigtTwoPointFit& source_fit, const std::string& target_run,
                        const std::vector<double>& target_xmax,
                        const KelvinVoigtTwoPointFit& target_fit, int start_rebound);

}  // namespace impactlab
