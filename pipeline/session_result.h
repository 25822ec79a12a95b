// What reducing a session produces: one RunResult per run, the cross-run
// Kelvin-Voigt analysis and the predictions. The results file (results_file.h)
// stores exactly this; the report formats it and never recomputes it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "fit/contact_law_fit.h"
#include "fit/kelvin_voigt_session.h"
#include "fit/kelvin_voigt_two_point.h"
#include "io/rgb_image.h"
#include "io/session.h"
#include "io/units.h"
#include "model/pendulum.h"
#include "options/settings.h"
#include "pipeline/products.h"
#include "rebounds/bar_rebounds.h"

namespace impactlab {

// A least-squares fit as the results file keeps it (fit/least_squares.h has
// the full result): named estimates, fit quality and what the data determine.
struct LeastSquaresSummary {
  std::string model;  // group name: "kelvin_voigt_least_squares" or "poynting_thomson"
  bool converged = false;
  bool ok = false;          // usable, dissipative and identifiable
  std::string reason;       // why not, when !ok
  std::string termination;  // the solver's, when ok
  bool identifiable = false;
  int rank = 0;
  std::string identifiability;  // in words: which combination is not determined
  std::vector<NamedEstimate> parameters;
  double chi2 = 0.0;
  int dof = 0;
  // chi^2 against its dof (weighted fits only): the Birge ratio that scales
  // the stated standard errors where the scatter exceeds them.
  ScatterCheck scatter;
  double seconds = 0.0;
  std::vector<double> predicted_xmax;        // rebound 0, 1, ... (when the model predicts them)
  std::vector<double> normalized_residuals;  // (measured - model)/sigma per maximum
  // The rows of `correlation`: the fit's free parameters as fit/ names them
  // ("log K1"), or, read from a results file, named as the estimates they are
  // ("stiffness_1"; the results file names them so).
  std::vector<std::string> covariance_names;
  std::vector<double> correlation;  // n x n, row-major

  std::string Status() const { return ok ? "ok" : "failed: " + reason; }

  // What the results file keeps as fields of a fit that ran
  // (options/result_fields.h). The status, the solver's termination (only
  // when ok), the parameters by name and the correlation with its names are
  // stored by the file's own layout.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("converged", self.converged, Quantity::kDimensionless, "1 when the solver converged");
    visit("identifiable", self.identifiable, Quantity::kDimensionless,
          "1 when the data determine every parameter");
    visit("rank", self.rank, Quantity::kDimensionless, "the Jacobian's numerical rank");
    visit("identifiability", self.identifiability, Quantity::kDimensionless,
          "which combination is not determined, in words");
    visit("dof", self.dof, Quantity::kDimensionless, "degrees of freedom");
    visit("chi2", self.chi2, Quantity::kDimensionless, "chi-square");
    visit("excess_scatter", self.scatter.excess, Quantity::kDimensionless,
          "1 when chi2's p-value < 0.001: the errors are Birge-scaled");
    visit("birge_ratio", self.scatter.birge_ratio, Quantity::kDimensionless, "sqrt(chi2 / dof)");
    visit("chi2_p_value", self.scatter.p_value, Quantity::kDimensionless, "P(chi2_dof >= chi2)");
    visit("seconds", self.seconds, Quantity::kSeconds, "the fit's wall time");
    visit("predicted_xmax", self.predicted_xmax, Quantity::kLength,
          "the fitted model's maxima, rebound 0, 1, ...");
    visit("normalized_residuals", self.normalized_residuals, Quantity::kDimensionless,
          "(measured - model) / sigma per maximum");
  }
};

// A digitized photo as the report shows it: the photo with the grid and
// traces found drawn on it (a downscaled JPEG) and how well they were found.
struct PhotoOverlay {
  std::string photo;                // the file, relative to the session
  std::vector<unsigned char> jpeg;  // the overlay image, encoded
  // The overlay at a quarter of its width, for the results file's HDF5 image (which
  // HDFView shows; it cannot decode a JPEG). Made while digitizing, on the
  // reduce's threads; not read back from a results file.
  RgbImage preview;
  double graticule_residual_px = 0;  // RMS residual of the grid fit, photo pixels
  std::vector<std::string> trace_names;
  std::vector<double> trace_coverage;  // fraction of the sweep with samples, per trace
  // Per trace, the spread s^2 whose curvature pull was undone, and its sigma,
  // px^2 (0: not measured; digitize/beam_spread.h).
  std::vector<double> trace_spread_px2, trace_spread_sigma_px2;
  // Stretches of the sweep whose samples lay on a hand mark and were dropped:
  // the trace's index in trace_names, from and to, divisions.
  std::vector<double> mark_stretch_trace, mark_stretch_from_div, mark_stretch_to_div;
  int hand_marks = 0;        // marks kept from the traces
  double processing_ms = 0;  // digitizing beyond decoding
  // The manual hints of the manifest the digitizing used, e.g.
  // "graticule_corners, left.points" (empty: none; digitize/digitize.h HintsUsed).
  std::string hints;
};

// A sampled curve for the report's figures (decimated to a few thousand points).
struct Curve {
  std::vector<double> time_s;
  std::vector<double> value;
};

// A photocell calibration as used by a run (Figures 13-14).
struct CellCalibration {
  std::string calibration_id;
  std::string cell;                   // "right" or "left"
  double release_x = 0.0;             // X0 of the calibration swing
  int order = 0;                      // of the Chebyshev series V(X)
  std::vector<double> chebyshev;      // in u = 2X/X0 - 1, V
  SquareMatrix chebyshev_covariance;  // (order+1)^2, V^2 (empty: not known)
  double residual_rms_volts = 0.0, residual_rms_length = 0.0;
  int samples_used = 0;
  double volts_min = 0.0, volts_max = 0.0;
  std::vector<double> points_x, points_volts;  // the pairs the fit used (decimated to <= 500)
  std::optional<PhotoOverlay> overlay;         // a photo calibration: its photo, digitized
  SettingValues settings;  // the stage settings it was made with (photocell, digitize for a photo)

  // What the results file keeps as fields (options/result_fields.h); the overlay
  // and the settings are stored by their own layout, the order follows from
  // the series.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("calibration_id", self.calibration_id, Quantity::kDimensionless,
          "the [[calibration]] entry's id");
    visit("cell", self.cell, Quantity::kDimensionless, "right or left");
    visit("release_x", self.release_x, Quantity::kLength, "X0 of the calibration swing");
    visit("chebyshev", self.chebyshev, Quantity::kVolts,
          "V(X) = sum c_k T_k(2X/X0 - 1), its coefficients c_k");
    visit("chebyshev_covariance", self.chebyshev_covariance, Quantity::kVoltsSquared,
          "their covariance");
    visit("residual_rms_volts", self.residual_rms_volts, Quantity::kVolts,
          "the fit's residual RMS in volts");
    visit("residual_rms_length", self.residual_rms_length, Quantity::kLength,
          "the same in displacement");
    visit("volts_min", self.volts_min, Quantity::kVolts, "the calibrated range's lower end");
    visit("volts_max", self.volts_max, Quantity::kVolts, "its upper end");
    visit("samples_used", self.samples_used, Quantity::kDimensionless, "samples the fit used");
    visit("points_x", self.points_x, Quantity::kLength, "the fit's pairs (decimated): X");
    visit("points_volts", self.points_volts, Quantity::kVolts, "and V");
  }
};

// Wall time spent per stage of one run, s (for benchmarks; not in the results file).
struct StageSeconds {
  double load = 0.0;       // reading traces: CSV parsing, or photo decoding and digitizing
  double calibrate = 0.0;  // photocell calibrations first computed by this run
  double extract = 0.0;    // conversion to displacement and rebound extraction
  double fit = 0.0;        // the closed-form fit and the model response
};

// What measuring a run gave, its stages' results composed: its traces'
// calibrations, rebounds and contact pulse (MeasureTraceRun), or the maxima
// typed into the manifest. A run whose inputs are unchanged takes it whole
// from the earlier results file.
struct RunMeasurement {
  std::string source;  // where the maxima came from: "typed-in", "csv" or "photo"

  std::vector<double> xmax;          // rebound 0, 1, ... (session numbering)
  std::vector<double> xmax_sigma;    // one-sigma, same length (0 where unknown)
  std::vector<double> t_peak;        // s since release (trace runs; empty when typed in)
  std::vector<double> t_peak_sigma;  // one-sigma, same length as t_peak

  std::optional<double> contact_time;  // s, the run's own
  double contact_time_sigma = 0.0;
  std::string contact_time_source;  // "typed-in" or "contact trace"

  // Trace-based runs: each bar's rebounds (the run's xmax is their average,
  // as the thesis did) and the calibrations used.
  std::optional<BarRebounds> right, left;
  std::vector<double> rebound_duration;        // s, of the average, session numbering
  std::vector<double> rebound_duration_sigma;  // s, one-sigma (empty: not known)
  // X0 as the traces show it (the release swing's fitted amplitude, the mean
  // of the bars'), to check the typed X0 against; sigma 0: not measured.
  Estimate release;
  std::vector<CellCalibration> calibrations;
  // Figures 16-18: the measured displacement (the average of the bars), length units.
  Curve measured_displacement;
  std::vector<PhotoOverlay> overlays;  // photo runs: the run photo, digitized
};

// The run's own fits (FitRun): what they were fitted to, the closed-form
// Kelvin-Voigt fit with Table 2's deviations, and the least-squares fits.
struct RunFits {
  // The maxima and contact time the fits used: the run's own, or the
  // session's one contact time when [reduction] gives it (Table 3).
  ReboundMeasurements fitted;
  std::string contact_time_source;  // "typed-in", "contact trace" or "session"
  std::optional<KelvinVoigtTwoPointFit> kelvin_voigt;
  // Table 2: predicted - measured, in length units, % of the measured peak and % of X0.
  std::vector<double> deviation, deviation_pct_peak, deviation_pct_x0;
  // Typed-in runs: when the fitted model's maxima fall, s since release.
  std::vector<double> model_peak_times;
  // Figures 16-18: the fitted Kelvin-Voigt model's response, length units.
  Curve model_response;
  std::vector<LeastSquaresSummary> least_squares;  // Kelvin-Voigt and Poynting-Thomson
};

// A run's result: what it is, whether it reduced (and the reason when not),
// and its stages' results.
struct RunResult {
  std::string id;
  StageSeconds seconds;
  std::string fingerprint;  // hash of the run's inputs (run_fingerprint.h)
  bool reused = false;      // measurement taken from the previous results file
  bool ok = false;
  std::string reason;  // why, when !ok (file, key and reason where they apply)

  double initial_displacement = 0.0;  // X0, length units
  int first_rebound = 1;

  RunMeasurement measured;
  RunFits fits;  // empty unless fitted
  // Rebounds the free pendulum cannot explain (rebounds/rebound_anomalies.h),
  // one sentence each; marked, not dropped.
  std::vector<std::string> anomalies;

  // The stage settings its measurement and fits used, of the stages that
  // apply to it (pipeline/stage_options.h), by key.
  SettingValues settings;

  std::string Status() const { return ok ? "ok" : "failed: " + reason; }
  // When the maxima fall: measured on the traces, else the fitted model's
  // ("trace" or "model"; empty when neither is known).
  const std::vector<double>& PeakTimes() const {
    return measured.t_peak.empty() ? fits.model_peak_times : measured.t_peak;
  }
  const char* PeakTimesSource() const {
    return !measured.t_peak.empty() ? "trace" : !fits.model_peak_times.empty() ? "model" : "";
  }
};

// Table 3 and eq. 40 over the runs with a Kelvin-Voigt fit and a contact time.
struct SessionKelvinVoigt {
  std::vector<std::string> run_ids;
  std::vector<double> sqrt_restitution;  // sqrt(xi), xi = the run's fitted e
  std::vector<double> stiffness;         // each run's own K
  // C per run: from the run's own K, or from the average when there is one.
  std::vector<double> damping, damping_sigma;
  StiffnessSpread spread;
  std::optional<DampingLine> damping_line;
  // [reduction] average_stiffness: K_avg, which every run's C above is from.
  std::optional<Estimate> average_stiffness;
};

// An encoder/accelerometer log (signal/log_analysis.h), as the results file keeps it.
struct LogChannelResult {
  std::string channel;  // the manifest's name, e.g. "a1"
  std::string units;    // of the channel's values: "rad", "m/s^2" or "SI"
  std::optional<Estimate> dominant_frequency_hz;
  std::optional<Estimate> damping_ratio;
  std::string frequency_source;     // "fit", "fft post_impact" or "fft whole"
  bool frequency_mismatch = false;  // the FFT peak and the fitted frequency disagree
  std::vector<double> spectrum_frequency_hz, spectrum_psd;  // post-impact (or whole), for plots
  std::vector<double> series_time_s, series_value;          // the channel over time, decimated
  std::vector<std::string> notes;

  // What the results file keeps as fields (options/result_fields.h); the
  // spectrum, the series and the notes are stored by the file's own layout.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("channel_units", self.units, Quantity::kDimensionless,
          "the channel's values' units: rad, m/s^2 or SI");
    visit("frequency_source", self.frequency_source, Quantity::kDimensionless,
          "fit, fft post_impact or fft whole");
    visit("frequency_mismatch", self.frequency_mismatch, Quantity::kDimensionless,
          "1 when the FFT peak and the fitted frequency disagree");
    visit("dominant_frequency", self.dominant_frequency_hz, Quantity::kHertz,
          "the channel's dominant frequency (none: no oscillation)");
    visit("damping_ratio", self.damping_ratio, Quantity::kDimensionless,
          "its mode's damping ratio");
  }
};

struct LogSourceResult {
  std::string source;  // "experiment" or "simulation"
  std::optional<Estimate> impact_time_s;
  std::string impact_method;  // or why no impact was found
  std::vector<LogChannelResult> channels;
};

struct LogComparisonRow {
  std::string channel, units;
  Estimate experiment_frequency_hz, simulation_frequency_hz;
  double difference_hz = 0.0, difference_percent = 0.0;  // simulation - experiment
  double rms_difference = 0.0;            // after aligning the impacts, channel units
  double rms_difference_unaligned = 0.0;  // channel units
};

struct LogResult {
  SettingValues settings;  // the log_analysis settings it was analysed with
  std::string id;
  bool ok = false;
  std::string reason;  // why, when !ok (file, line and key where they apply)
  std::vector<LogSourceResult> sources;
  std::optional<Estimate> impact_offset_s;  // simulation - experiment
  std::vector<LogComparisonRow> comparison;

  std::string Status() const { return ok ? "ok" : "failed: " + reason; }
};

// Which restitution model predicts unseen runs best (fit/joint_fits.h).
struct ModelComparisonRow {
  std::string model;  // "per-run", "common", "linear-in-speed"
  bool ok = false;
  std::string reason;                     // why, when !ok
  std::vector<NamedEstimate> parameters;  // per-run speeds excluded
  int maxima = 0, parameter_count = 0, dof = 0;
  double chi2 = 0.0, aic = 0.0, bic = 0.0;
  double log_restitution_spread = 0.0;  // weighted std of the runs' ln e
  double loo_rms_normalized = 0.0;      // leave-one-run-out, RMS (predicted - measured)/sigma
  double loo_rms_length = 0.0;          // the same in length units
  // How the model fares against the best (lowest BIC): "best", "comparable",
  // "disfavoured" or "rejected" with its BIC difference (Kass-Raftery's 2, 10).
  std::string verdict;
};

struct ModelComparison {
  std::vector<std::string> run_ids;
  std::vector<ModelComparisonRow> models;
  std::string best_by_leave_one_out;
  std::string best_by_bic;
  // The reading: sentences on what the data support and reject, with the
  // evidence (e.g. how ln e changes with speed against what a law needs).
  std::vector<std::string> evidence;
};

struct SessionResult {
  std::string title;
  UnitSystem units = UnitSystem::kInLbfS;
  std::string producer;  // "impactlab <version>"
  std::string created;   // ISO 8601
  std::string session_folder;
  Apparatus apparatus;
  PendulumConvention convention = PendulumConvention::kExact;
  Separation separation = Separation::kKinematic;
  std::optional<double> session_contact_time;  // [reduction] contact_time, s

  std::vector<RunResult> runs;
  std::vector<CellCalibration> calibrations;  // --only calibration: every calibration
  std::optional<SessionKelvinVoigt> kelvin_voigt;
  std::vector<LeastSquaresSummary> joint_fits;  // one parameter set for all runs
  std::optional<ModelComparison> model_comparison;
  // The contact laws fitted across the runs, maxima and contact times together
  // (fit/contact_law_fit.h): Kelvin-Voigt, Hertz, Hunt-Crossley (n = 3/2 and free).
  std::vector<ContactLawFit> contact_laws;
  std::vector<RunPrediction> predictions;
  std::vector<LogResult> logs;
  std::vector<std::string> warnings;  // manifest warnings and non-fatal findings
  SettingValues settings;             // every stage setting as the session resolves them
  // The session-level products (pipeline/products.h): each made, or skipped
  // with why; empty in a file written before they were recorded.
  std::vector<ProductRecord> products;

  int FailedRuns() const;
  const RunResult* FindRun(const std::string& id) const;
  const ProductRecord* FindProduct(std::string_view name) const;
};

const char* ConventionName(PendulumConvention convention);    // "exact" or "thesis"
PendulumConvention ParseConvention(const std::string& name);  // throws std::invalid_argument

}  // namespace impactlab
