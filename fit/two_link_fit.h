// The two-link manipulator's simulation fitted to an experiment's logs
// (docs/two-link-fit.md): the parameters the user frees are adjusted by
// Levenberg-Marquardt (Ceres) so that the simulated encoder angles and
// accelerations match the logged ones sample by sample, with the ring-down
// frequency of the first mid-beam accelerometer as one more datum.
//
// Each residual is (simulated - measured) / sigma, sigma the channel's noise
// estimated from the record itself (second differences, robust; an encoder's
// at least its count / sqrt 12). An encoder's reading is taken at the centre
// of its count. Accelerometer samples within five samples of a simulated
// impact or separation, or within two of a spike in the record, are left out: a
// one-sample spike's height says where in the sample the impact fell, not
// how the arm moves. Positive parameters are fitted as logarithms;
// derivatives are forward differences of whole simulations run side by side.
// The fit runs in stages, because the whole record's cost has side minima:
// the encoders in free flight (with a weak prior at the start), the encoders
// in windows from the impact that double until they reach the record's end,
// then every channel. For the covariance each channel's rows are weighted
// down by its residuals' correlation inflation (model/estimate.h), and the
// response along each singular direction of the weighted Jacobian is
// measured again by secants spanning about two of its standard errors
// (fit/secant_covariance.h): after the impact the fixed-step differences
// misjudge it along the weak directions.
//
// The answer says which combinations the data determine: the singular vectors
// of the weighted Jacobian (central differences) whose singular values fall
// below `undetermined_ratio` of the largest are directions along which the
// fit does not change, named as combinations of log parameters (freeing a
// motor's K_t and R, which enter only as K_t / R: "0.71 ln K_t + 0.71 ln R");
// a parameter in one of them has no standard error of its own.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "model/estimate.h"
#include "multibody/two_link_parameters.h"

namespace impactlab {

// An experiment's record in SI on a uniform grid starting at t = 0: the
// encoders' angles (rad) and the accelerometers' accelerations (m/s^2), each
// present or not, in the simulator's order (a1 mid beam 1, a2 RB2, a3 mid
// beam 2, a4 RB4).
struct TwoLinkMeasurement {
  std::vector<double> time_s;
  std::optional<std::vector<double>> q1_rad, q4_rad;
  std::optional<std::vector<double>> acceleration_m_s2[4];
  double encoder_a_step_rad = 0.0, encoder_b_step_rad = 0.0;  // one count, for the noise floor
};

// Where a fit is, after each Levenberg-Marquardt iteration and before the
// final covariance (docs/two-link-fit.md, "Stages").
struct TwoLinkFitProgress {
  int start = 0, starts = 1;  // this start (from 0) of how many
  int stage = 0, stages = 1;  // this stage (from 0) of how many; stage == stages: the uncertainty
  std::string stage_name;     // "free flight", "encoders to 1.859 s", "encoders", "all channels",
                              // "uncertainty" (the final central differences)
  int iteration = 0;          // within the stage
  double chi2 = 0.0;          // the stage's cost at that iteration, 2 F (prior included)
  int simulations = 0;        // so far
  double seconds = 0.0;       // since the fit began
};

struct TwoLinkFitOptions {
  std::vector<std::string> free;  // keys of the parameter file, "section.key"
  int case_number = 1;
  int max_iterations = 40;
  int starts = 1;  // > 1: also from each free parameter moved +-20 % (a time +-30 ms), best
                   // chi2 kept (docs/two-link-fit.md)
  double relative_step = 1e-4;          // forward difference in log parameters
  double absolute_step = 1e-5;          // ... for a parameter that may be <= 0
  double undetermined_ratio = 1e-3;     // singular value / largest below this: not
                                        // determined (forward differences of adaptive
                                        // simulations resolve no finer)
  bool use_ring_down_frequency = true;  // a1's post-impact damped frequency as a datum
  double ring_down_delay_s = 0.005;     // the ring-down window starts this long after the impact
  double ring_down_duration_s = 1.0;
  double tolerance = 1e-8;  // the simulation's relative tolerance
  int threads = 2;
  // Called on the calling thread; empty: no reports.
  std::function<void(const TwoLinkFitProgress&)> on_progress;

  bool Check(std::string* error) const;
};

struct FittedParameter {
  std::string name;
  double start = 0.0;
  Estimate value;                 // sigma from secants along the weighted Jacobian's singular
                                  // directions (0 when not determined)
  double std_error_scaled = 0.0;  // times the Birge ratio when that exceeds 1
  double jacobian_sigma = 0.0;    // from the weighted Jacobian alone, (J^T J)^-1, for comparison
  bool determined = true;
};

struct UndeterminedCombination {
  std::string combination;  // e.g. "0.71 ln a - 0.71 ln b"
  double singular_value_ratio = 0.0;
};

struct ChannelMatch {
  std::string channel;
  // RMS misfits at the start and fitted (SI); none in a fit that refused
  // its data, which simulated nothing to compare.
  std::optional<double> rms_start, rms_fitted;
  double sigma = 0.0;  // the noise used
  int samples = 0;
};

// What the fit refused, when it did (TwoLinkFitResult::refused).
enum class TwoLinkFitRefusal {
  kNone,
  kRecord,           // too few samples, a time that does not increase, more samples
                     // than the simulation logs a case (kTwoLinkMaxSamples), a channel
                     // whose sample count is not the record's
  kStartParameters,  // the start parameters' case cannot be simulated (the reason
                     // carries the simulation's: where and why it stopped)
};

struct TwoLinkFitResult {
  // False when the fit refused its data: `reason` says what, `refused` which
  // kind, and only what was measured before the refusal is filled (the free
  // parameters with their starts, fitted = start, none determined; each
  // channel read so far with its noise and samples, without RMS misfits as
  // nothing was simulated; a1's ring-down and the
  // measured impact once the record was read). chi2, the Jacobian's figures
  // and the iterations are then empty or 0.
  bool ok = false;
  std::string reason;
  TwoLinkFitRefusal refused = TwoLinkFitRefusal::kNone;

  TwoLinkParameters fitted;
  std::vector<FittedParameter> parameters;
  std::vector<UndeterminedCombination> undetermined;
  std::vector<double> singular_value_ratios;  // of the weighted Jacobian, largest first
  std::vector<double> secant_sigma_ratios;    // per direction: sigma from its secants over
                                              // the Jacobian's (0: undetermined)
  double iterated_chi2 = 0.0;  // where Levenberg-Marquardt stopped, before the secants' steps
  int secant_simulations = 0;  // the secants' and their steps' (beside the Jacobian's 2p)
  std::vector<ChannelMatch> channels;
  double chi2 = 0.0;
  int dof = 0;
  double birge_ratio = 0.0;
  std::optional<Estimate> measured_frequency_hz;  // a1's ring-down
  double start_frequency_hz = 0.0, fitted_frequency_hz = 0.0;
  double measured_impact_s = -1.0, start_impact_s = -1.0, fitted_impact_s = -1.0;
  std::vector<double> start_costs;  // chi2 reached from each start
  int iterations = 0;
  int simulations = 0;
  double seconds = 0.0;
  std::string termination;

  std::string Summary() const;  // a Markdown report: parameters, combinations, channels
};

// A record of fewer than 10 samples, whose time does not increase, that is
// longer than the simulation logs a case, or with a channel whose sample count
// is not the time's, and start parameters that cannot be simulated (the
// simulation's reason said), are a result with !ok and the reason (data, not
// a caller's mistake). Throws std::invalid_argument for bad options or an
// unknown key (naming it): what the caller asked, not what the data are.
TwoLinkFitResult FitTwoLinkSimulation(const TwoLinkParameters& start,
                                      const TwoLinkMeasurement& measurement,
                                      const TwoLinkFitOptions& options);

}  // namespace impactlab
