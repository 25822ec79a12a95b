// What reducing a session produces: one RunResult per run, the cross-run
// Kelvin-Voigt analysis and the predictions, the stages' results as they
// return them where they have field lists (the least-squares fits, the
// contact laws, the restitution models, the log channels' analyses). The results file
// (results_file.h) stores what each result's list keeps (options/result_fields.h; a list says what
// it leaves out); the report formats it and never recomputes it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "fit/contact_law_fit.h"
#include "fit/joint_fits.h"
#include "fit/kelvin_voigt_least_squares.h"
#include "fit/kelvin_voigt_session.h"
#include "fit/kelvin_voigt_two_point.h"
#include "fit/poynting_thomson_least_squares.h"
#include "io/rgb_image.h"
#include "io/session.h"
#include "io/units.h"
#include "model/pendulum.h"
#include "options/settings.h"
#include "pipeline/products.h"
#include "rebounds/bar_rebounds.h"
#include "signal/log_analysis.h"

namespace impactlab {

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

  // What the results file keeps as fields (options/result_fields.h); the
  // images, the processing time (in s) and the traces' dimension scale are
  // stored by the file's own layout.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("photo", self.photo, Quantity::kDimensionless, "the photo, relative to the session");
    visit("hints", IfAny(self.hints), Quantity::kDimensionless,
          "the manifest's manual hints the digitizing used (absent: none)");
    visit("graticule_residual", self.graticule_residual_px, Quantity::kPixels,
          "RMS residual of the grid fit");
    visit("trace_names", self.trace_names, Quantity::kDimensionless, "the traces found");
    visit("trace_coverage", EvenEmpty(self.trace_coverage), Quantity::kDimensionless,
          "per trace: the fraction of the sweep with samples");
    visit("trace_spread", EvenEmpty(self.trace_spread_px2), Quantity::kPixelsSquared,
          "per trace: the spread s^2 whose curvature pull was undone (0: not measured)");
    visit("trace_spread_std_error", EvenEmpty(self.trace_spread_sigma_px2),
          Quantity::kPixelsSquared, "its standard error");
    visit("hand_marks", self.hand_marks, Quantity::kDimensionless,
          "hand marks kept from the traces");
    visit("mark_stretch_trace", EvenEmpty(self.mark_stretch_trace), Quantity::kDimensionless,
          "per stretch dropped on a hand mark: its trace's index in trace_names");
    visit("mark_stretch_from", EvenEmpty(self.mark_stretch_from_div), Quantity::kDivisions,
          "the stretch's first x");
    visit("mark_stretch_to", EvenEmpty(self.mark_stretch_to_div), Quantity::kDivisions,
          "its last x");
  }
};

// A sampled curve for the report's figures (decimated to a few thousand points).
struct Curve {
  std::vector<double> time_s;
  std::vector<double> value;
};

// `measured` less `model` (increasing times, linearly interpolated) at
// `measured`'s times within `model`'s span: a fit's residual history.
Curve ResidualCurve(const Curve& measured, const Curve& model);

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
  // Stretches of the swing left out as misread (photocell_calibration.h), s.
  std::vector<double> left_out_from_s, left_out_to_s;
  std::optional<PhotoOverlay> overlay;  // a photo calibration: its photo, digitized
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
    visit("left_out_from", EvenEmpty(self.left_out_from_s), Quantity::kSeconds,
          "stretches of the swing left out as misread: their starts");
    visit("left_out_to", EvenEmpty(self.left_out_to_s), Quantity::kSeconds, "and their ends");
  }
};

// Wall time spent per stage of one run, s (for benchmarks; a reused run's
// measurement took none).
struct StageSeconds {
  double load = 0.0;       // reading traces: CSV parsing, or photo decoding and digitizing
  double calibrate = 0.0;  // photocell calibrations first computed by this run
  double extract = 0.0;    // conversion to displacement and rebound extraction
  double fit = 0.0;        // the closed-form fit and the model response

  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("load", self.load, Quantity::kSeconds,
          "reading traces: CSV parsing, or photo decoding and digitizing");
    visit("calibrate", self.calibrate, Quantity::kSeconds,
          "photocell calibrations first computed by this run");
    visit("extract", self.extract, Quantity::kSeconds,
          "conversion to displacement and rebound extraction");
    visit("fit", self.fit, Quantity::kSeconds, "the closed-form fit and the model response");
  }
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

  // What the results file keeps as fields of the run's group
  // (options/result_fields.h). When the maxima fall (with the fitted model's
  // times for typed-in runs), the bars, the calibrations, the displacement and
  // the photos are stored by the file's own layout.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("source", IfAny(self.source), Quantity::kDimensionless,
          "where the maxima came from: typed-in, csv or photo");
    visit("rebounds/xmax", self.xmax, Quantity::kLength,
          "Xmax of rebound 0, 1, ... (session numbering)");
    visit("rebounds/xmax_std_error", self.xmax_sigma, Quantity::kLength, "its standard error");
    visit("rebounds/t_peak_std_error", self.t_peak_sigma, Quantity::kSeconds,
          "trace runs: each peak time's standard error");
    visit("rebounds/duration", self.rebound_duration, Quantity::kSeconds,
          "trace runs: each rebound's impact-to-impact time");
    visit("rebounds/duration_std_error", self.rebound_duration_sigma, Quantity::kSeconds,
          "its standard error");
    visit("rebounds/release_x", self.release, Quantity::kLength, "X0 as the traces show it");
    visit("contact_time", self.contact_time, Quantity::kSeconds, "the run's own contact time");
    if (self.contact_time) {
      visit("contact_time_std_error", self.contact_time_sigma, Quantity::kSeconds,
            "its standard error");
      visit("contact_time@source", self.contact_time_source, Quantity::kDimensionless,
            "typed-in or contact trace");
    }
  }
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
  // Figures 16-18: the fitted Kelvin-Voigt model's response, and the
  // measured displacement less it at the measured times, length units.
  Curve model_response;
  Curve model_residual;
  // The least-squares fits as fit/ returns them; one its inputs refused
  // holds only its reason (FitStatus::Ran). None: the run's fits were not made.
  std::optional<KelvinVoigtLeastSquaresFit> kelvin_voigt_least_squares;
  std::optional<PoyntingThomsonLeastSquaresFit> poynting_thomson;

  // What the results file keeps beside the two-point fit's fields, in its
  // group, when it succeeded (options/result_fields.h); the model's peak
  // times are stored as the run's, the fits and the response by the file's
  // own layout.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("contact_time_used@source", self.contact_time_source, Quantity::kDimensionless,
          "typed-in, contact trace (the run's own) or session");
    visit("deviation", self.deviation, Quantity::kLength, "predicted - measured (Table 2)");
    visit("deviation_pct_peak", self.deviation_pct_peak, Quantity::kPercent,
          "the same, % of the measured peak");
    visit("deviation_pct_x0", self.deviation_pct_x0, Quantity::kPercent, "the same, % of X0");
  }
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
  // Its own [run.specimen]: the keys in which its bars differ from the
  // session's (empty: none; SpecimenOf in io/session.h merges them).
  Specimen specimen;

  std::string Status() const { return ok ? "ok" : "failed: " + reason; }

  // What the results file keeps as the run's own fields, in its group
  // (options/result_fields.h), read after the status and the measurement;
  // the status, the stage timings and the settings are stored by the file's
  // own layout.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("input_fingerprint", IfAny(self.fingerprint), Quantity::kDimensionless,
          "hash of the run's inputs");
    // A run the manifest rejected has neither X0 nor its numbering, and was not measured.
    visit("initial_displacement", IfAny(self.initial_displacement), Quantity::kLength, "X0");
    if (self.initial_displacement > 0.0) {
      visit("reused", self.reused, Quantity::kDimensionless, "1 when its measurement was reused");
      visit("first_rebound", self.first_rebound, Quantity::kDimensionless,
            "which rebound after the first impact the tables call 0");
    }
    if (self.ok && !self.measured.xmax.empty()) {
      visit("rebounds/anomalies", self.anomalies, Quantity::kDimensionless,
            "rebounds the free pendulum cannot explain, one sentence each");
    }
  }

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

  // What the results file keeps as fields (options/result_fields.h); the
  // damping line is a group of its own, and which stiffness the C are from
  // an attribute of the file's layout.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("run_ids", self.run_ids, Quantity::kDimensionless, "the runs in the analysis");
    visit("sqrt_restitution", self.sqrt_restitution, Quantity::kDimensionless,
          "sqrt(xi), xi = the run's fitted e");
    visit("stiffness", self.stiffness, Quantity::kStiffness, "each run's own K");
    visit("stiffness_average", self.spread.average, Quantity::kStiffness, "K avg");
    visit("stiffness_deviation", self.spread.deviation, Quantity::kStiffness, "K - K avg");
    visit("stiffness_pct_variation", self.spread.pct_variation, Quantity::kPercent,
          "100 |K - K avg| / K avg");
    visit("damping", self.damping, Quantity::kDamping,
          "C per run: from its own K, or from K avg with the average option");
    visit("damping_std_error", self.damping_sigma, Quantity::kDamping, "its standard error");
    visit("average_stiffness", self.average_stiffness, Quantity::kStiffness,
          "K avg with the average option, which every run's C is from");
  }
};

// An encoder/accelerometer log's source (signal/log_analysis.h): its own
// impact instant (its strongest jump, which places its segments) and its
// channels' analyses as the log stage returns them (ChannelAnalysis lists
// what the file keeps of one). The instants the sources' comparison
// compares are the comparison's (LogComparison).
struct LogSourceResult {
  std::string source;  // "experiment" or "simulation"
  std::optional<Estimate> impact_time_s;
  std::string impact_method;  // the channel that found it, or why no impact was found
  std::vector<ChannelAnalysis> channels;

  // What the results file keeps as fields (options/result_fields.h); the
  // source names the group, and each channel is a group of its own.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("impact_method", self.impact_method, Quantity::kDimensionless,
          "the channel whose jump places the impact, or why none was found");
    visit("impact_time", self.impact_time_s, Quantity::kSeconds,
          "the source's own impact instant, when found");
  }
};

struct LogResult {
  SettingValues settings;  // the log_analysis settings it was analysed with
  std::string id;
  bool ok = false;
  std::string reason;  // why, when !ok (file, line and key where they apply)
  std::vector<LogSourceResult> sources;
  std::optional<LogComparison> comparison;  // with a simulation, as the log stage returns it

  std::string Status() const { return ok ? "ok" : "failed: " + reason; }
};

// A restitution model fitted jointly to the runs' maxima (fit/joint_fits.h),
// as CompareRestitutionModels returns it, and the comparison's verdict on it.
struct ComparedRestitutionModel {
  JointModelFit fit;
  // How the model fares against the best of every model compared (lowest
  // BIC): "best", "comparable", "disfavoured" or "rejected" with its BIC
  // difference (Kass-Raftery's 2, 10); "failed".
  std::string verdict;

  const std::string& Name() const { return fit.name; }
  // Whether it was fitted (every model that reached the solver counts its maxima).
  bool Ran() const { return fit.maxima > 0; }

  // What the results file keeps as fields of a model that ran
  // (options/result_fields.h): the verdict and the fit's own list; the
  // status by the file's own layout.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("verdict", self.verdict, Quantity::kDimensionless,
          "best, comparable, disfavoured or rejected with the BIC difference; failed");
    JointModelFit::VisitFields(self.fit, visit);
  }
};

// A contact law's prediction of the same maxima (fit/contact_law_fit.h,
// fitted to the maxima alone, without intervals), as FitContactLaw returns
// it; what the comparison measures of it beside the restitution models' own;
// and the verdict.
struct ComparedContactLaw {
  ContactLawFit fit;
  // The standard deviation of the law's ln e over the runs' fitted rebound-0
  // speeds, the restitution models' log_restitution_spread for a law (0 for
  // one whose e is the same at every speed, as elastic Hertz's 1). Set where
  // the law is fitted for the comparison (pipeline/least_squares_runs.cpp).
  double log_restitution_spread = 0.0;
  std::string verdict;  // as ComparedRestitutionModel's

  const std::string& Name() const { return fit.law; }
  // Whether it was fitted (one whose inputs were refused holds only its reason).
  bool Ran() const { return !fit.parameters.empty() || fit.maxima > 0; }

  // What the results file keeps as fields of a law that ran
  // (options/result_fields.h): the verdict, the spread and the law's own
  // list; the status, the parameters and the leave-one-out RMS as a
  // contact law's layout stores them.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("verdict", self.verdict, Quantity::kDimensionless,
          "best, comparable, disfavoured or rejected with the BIC difference; failed");
    visit("log_restitution_spread", self.log_restitution_spread, Quantity::kDimensionless,
          "the standard deviation of the law's ln e at the runs' fitted rebound-0 speeds");
    ContactLawFit::VisitFields(self.fit, visit);
  }
};

// Which model of the restitution predicts unseen runs best: the restitution
// models and the contact laws' predictions of the same maxima, each as its
// fit returned it with the comparison's verdict, and the comparison's reading.
struct ModelComparison {
  std::vector<std::string> run_ids;
  std::vector<ComparedRestitutionModel> restitution_models;  // per-run, common, linear-in-speed
  std::vector<ComparedContactLaw> contact_laws;              // hunt-crossley, hertz
  std::string best_by_leave_one_out;
  std::string best_by_bic;
  // The reading: sentences on what the data support and reject, with the
  // evidence (e.g. how ln e changes with speed against what a law needs).
  std::vector<std::string> evidence;

  // What the results file keeps as fields (options/result_fields.h); each
  // model is a group of its own.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("best_by_leave_one_out", self.best_by_leave_one_out, Quantity::kDimensionless,
          "the model that predicts held-out runs best (empty: not made)");
    visit("best_by_bic", self.best_by_bic, Quantity::kDimensionless, "the lowest BIC's");
    visit("run_ids", self.run_ids, Quantity::kDimensionless, "the runs fitted");
    visit("evidence", self.evidence, Quantity::kDimensionless,
          "what the data support and reject, in sentences");
  }
};

struct SessionResult {
  std::string title;
  UnitSystem units = UnitSystem::kInLbfS;
  std::string producer;  // "impactlab <version>"
  std::string created;   // ISO 8601
  std::string session_folder;
  Apparatus apparatus;
  Specimen specimen;  // the manifest's [specimen] (empty: not given)
  PendulumConvention convention = PendulumConvention::kExact;
  Separation separation = Separation::kKinematic;
  std::optional<double> session_contact_time;  // [reduction] contact_time, s

  std::vector<RunResult> runs;
  std::vector<CellCalibration> calibrations;  // --only calibration: every calibration
  std::optional<SessionKelvinVoigt> kelvin_voigt;
  // Poynting-Thomson with one parameter set for all runs (empty: not made).
  std::vector<PoyntingThomsonLeastSquaresFit> joint_fits;
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

  // What the results file keeps as the session's own fields, from its root
  // (options/result_fields.h); the layout, the units, the pendulum, the
  // settings and the products are stored by the file's own layout.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("session_title", self.title, Quantity::kDimensionless, "the manifest's title");
    visit("producer", self.producer, Quantity::kDimensionless, "impactlab <version>");
    visit("created", self.created, Quantity::kDimensionless, "when the file was written");
    visit("session_folder", self.session_folder, Quantity::kDimensionless,
          "the session folder reduced");
    visit("session/contact_time", self.session_contact_time, Quantity::kSeconds,
          "[reduction] contact_time, used for every run");
    visit("session/warnings", self.warnings, Quantity::kDimensionless,
          "the manifest's warnings and other non-fatal findings");
  }

  int FailedRuns() const;
  const RunResult* FindRun(const std::string& id) const;
  const ProductRecord* FindProduct(std::string_view name) const;
};

const char* ConventionName(PendulumConvention convention);    // "exact" or "thesis"
PendulumConvention ParseConvention(const std::string& name);  // throws std::invalid_argument

}  // namespace impactlab
