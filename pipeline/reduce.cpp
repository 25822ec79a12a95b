#include "pipeline/reduce.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <utility>

#include <fmt/chrono.h>
#include <fmt/format.h>

#include "fit/kelvin_voigt_response.h"
#include "io/errors.h"
#include "pipeline/least_squares_runs.h"
#include "pipeline/log_results.h"
#include "pipeline/material_constants.h"
#include "pipeline/run_fingerprint.h"
#include "pipeline/trace_run.h"
#include "rebounds/rebound_anomalies.h"

namespace impactlab {
namespace {

// Which session rebound each run's measured contact time follows: its contact
// trace's `impact` (counted from the first impact, which follows the release),
// else the impact after rebound 0. Impact N follows rebound N - 1 counted from
// the first impact, i.e. session rebound N - 1 - first_rebound.
std::map<std::string, int> ContactRebounds(const Session& session) {
  std::map<std::string, int> out;
  for (const Run& run : session.runs) {
    const auto contact = run.traces.find("contact");
    const int impact = contact != run.traces.end() && contact->second.impact
                           ? *contact->second.impact
                           : run.first_rebound + 1;
    out[run.id] = impact - 1 - run.first_rebound;
  }
  return out;
}

std::string NowIso8601() {
  const auto now = std::chrono::system_clock::now();
  return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}",
                     fmt::gmtime(std::chrono::system_clock::to_time_t(now)));
}

RunMeasurement MeasureTypedRun(const Run& run) {
  RunMeasurement out;
  out.source = "typed-in";
  out.xmax = run.rebounds;
  out.xmax_sigma.assign(run.rebounds.size(), run.rebound_uncertainty.value_or(0.0));
  if (run.contact_time) {
    out.contact_time = run.contact_time;
    out.contact_time_sigma = run.contact_time_uncertainty.value_or(0.0);
    out.contact_time_source = "typed-in";
  }
  return out;
}

// What the fits are fitted to: the run's maxima, and its own contact time
// unless the session gives one for every run (the thesis's procedure, Table 3).
RunFits FitInputs(const RunMeasurement& measured, const Session& session) {
  RunFits fits;
  fits.fitted = {measured.xmax, measured.xmax_sigma, measured.contact_time,
                 measured.contact_time_sigma};
  fits.contact_time_source = measured.contact_time_source;
  if (session.reduction.contact_time) {
    fits.fitted.contact_time = session.reduction.contact_time;
    fits.fitted.contact_time_sigma = 0.0;
    fits.contact_time_source = "session";
  }
  return fits;
}

// Why a measured run cannot be fitted as its manifest entry asks, said with
// the manifest and the key ("FILE: KEY: problem"); empty when it can be.
// The fit's model figures simulate every rebound from the release: a
// first_rebound of 2e8 with a restitution near 1 once took 50 s and
// bad_alloc. Rebounds die out within tens; refused before any work.
std::string FitProblem(const Run& run, const RunMeasurement& measured, const Session& session) {
  constexpr int kMaxModelRebounds = 1000;
  const std::size_t measured_rebounds = measured.xmax.size();
  if (run.first_rebound > kMaxModelRebounds - static_cast<int>(measured_rebounds)) {
    return fmt::format(
        "{}: run \"{}\".first_rebound: first_rebound = {}: the fit's model would simulate {} "
        "rebounds from the release; at most {} are expected",
        session.manifest.string(), run.id, run.first_rebound,
        static_cast<long long>(run.first_rebound) + measured_rebounds, kMaxModelRebounds);
  }
  if (run.fit_rebounds[1] >= static_cast<int>(measured_rebounds)) {
    return fmt::format(
        "{}: run \"{}\": fit_rebounds = [{}, {}] but only rebounds 0 .. {} were measured",
        session.manifest.string(), run.id, run.fit_rebounds[0], run.fit_rebounds[1],
        measured_rebounds - 1);
  }
  return {};
}

// A run's fits, or why the fit and the model refuse its data ("FILE: KEY:
// reason", `fits` then empty); a pair without dissipation is not a refusal
// but a two-point fit that is not ok, with its reason.
struct RunFitting {
  bool refused = false;
  std::string reason;
  RunFits fits;
};

// The closed-form Kelvin-Voigt fit of a measured run with Table 2's
// deviations and the model's figures, then its least-squares fits, for a
// run FitProblem passes.
RunFitting FitRun(const Run& run, const RunMeasurement& measured, const Session& session,
                  const Pendulum& pendulum, Separation separation, const FitOptions& fit_options) {
  RunFitting result;
  const auto refuse = [&](const std::string& why) {
    result.refused = true;
    result.reason = fmt::format("{}: run \"{}\": {}", session.manifest.string(), run.id, why);
    return result;
  };
  RunFits out = FitInputs(measured, session);
  TwoPointOptions options;
  options.rebounds = run.fit_rebounds;
  options.separation = separation;
  const double mass = session.apparatus->mass;
  if (std::string why = TwoPointRefusal(pendulum, out.fitted, options); !why.empty()) {
    return refuse(why);
  }
  KelvinVoigtTwoPointFit fit = FitKelvinVoigtTwoPoint(pendulum, mass, out.fitted, options);
  if (!fit.ok) {
    out.kelvin_voigt = std::move(fit);
    result.fits = std::move(out);
    return result;
  }
  for (std::size_t n = 0; n < measured.xmax.size(); ++n) {
    const double deviation = fit.predicted_xmax[n].value - measured.xmax[n];
    out.deviation.push_back(deviation);
    out.deviation_pct_peak.push_back(100.0 * deviation / measured.xmax[n]);
    out.deviation_pct_x0.push_back(100.0 * deviation / run.initial_displacement);
  }
  const FittedRun fitted_run{measured.xmax, run.initial_displacement, run.first_rebound};
  if (measured.t_peak.empty()) {
    if (std::string why = ModelPeakTimesProblem(pendulum, fitted_run, fit); !why.empty()) {
      return refuse(why);
    }
    out.model_peak_times = ModelPeakTimes(pendulum, fitted_run, fit);
  }
  if (fit.stiffness) {
    if (std::string why = ModelResponseProblem(pendulum, fitted_run, fit); !why.empty()) {
      return refuse(why);
    }
    const SampledHistory response = ModelResponse(pendulum, mass, fitted_run, fit);
    out.model_response = {response.time, response.displacement};
    out.model_residual = ResidualCurve(measured.measured_displacement, out.model_response);
  }
  out.kelvin_voigt = std::move(fit);
  FitRunLeastSquares(pendulum, mass, separation, fit_options, run.id, out);
  result.fits = std::move(out);
  return result;
}

// A previous result's measurement, when the run's inputs are unchanged and
// the file's values pass ReuseProblem (a hand-edited or corrupted file is
// never trusted). Typed-in runs never reuse: their maxima are read from the
// manifest, cheaper than validating the file's.
const RunResult* Reusable(const ReduceOptions& options, const Run& run,
                          const std::string& fingerprint) {
  if (options.previous == nullptr || run.HasTypedRebounds()) return nullptr;
  const RunResult* old = options.previous->FindRun(run.id);
  if (old == nullptr || old->fingerprint != fingerprint) return nullptr;
  return ReuseProblem(old->measured).empty() ? old : nullptr;
}

// `fingerprint`: the run's, when already worked out. What its measurement
// could not measure while the run stands (a contact trace that cannot be
// read) is added to `warnings`.
RunResult ReduceRun(const Run& run, const Session& session, const Pendulum& pendulum,
                    Separation separation, CalibrationCache& calibrations,
                    const ReduceOptions& options, const StageOptions& session_options,
                    const std::optional<std::string>& fingerprint,
                    std::vector<std::string>& warnings) {
  const StageOptions run_options =
      EntryStageOptions(session_options, run.settings, options.overrides);
  RunResult out;
  out.id = run.id;
  out.initial_displacement = run.initial_displacement;
  out.first_rebound = run.first_rebound;
  out.specimen = run.specimen;
  const bool from_photo = run.photo && std::any_of(run.traces.begin(), run.traces.end(),
                                                   [](const auto& t) { return !t.second.csv; });
  out.settings = run.HasTypedRebounds() ? SettingsOfStages(run_options, {"fit"})
                 : from_photo
                     ? SettingsOfStages(run_options, {"digitize", "rebound_extraction", "fit"})
                     : SettingsOfStages(run_options, {"rebound_extraction", "fit"});
  out.fingerprint = fingerprint ? *fingerprint : RunFingerprint(run, session, options);
  if (run.HasTypedRebounds()) {
    out.measured = MeasureTypedRun(run);
  } else if (const RunResult* old = Reusable(options, run, out.fingerprint)) {
    out.measured = old->measured;
    out.reused = true;
  } else {
    MeasuredTraceRun measured = MeasureTraceRun(run, session, pendulum, run_options, calibrations);
    out.measured = std::move(measured.measured);
    out.seconds = measured.seconds;
    if (!measured.warnings.empty()) {
      // Measured in part (no contact time): measured again by a later
      // reduce, which says why again, rather than reused.
      warnings = std::move(measured.warnings);
      out.fingerprint.clear();
    }
    if (!measured.ok) {
      // What was measured before the failure (the photo's overlay, the
      // calibrations) stays, for the report; without a fingerprint, so that
      // a later reduce measures the run again rather than reuse a part.
      out.reason = measured.Failure();
      out.fingerprint.clear();
      return out;
    }
  }
  if (options.products == Products::kFit) {
    // The run was measured: its measurement stays, with why it cannot be fitted.
    if (std::string problem = FitProblem(run, out.measured, session); !problem.empty()) {
      out.reason = std::move(problem);
      return out;
    }
    const auto start = std::chrono::steady_clock::now();
    RunFitting fitting = FitRun(run, out.measured, session, pendulum, separation, run_options.fit);
    if (fitting.refused) {
      // The fit's and the model's own refusals of the data: the measurement
      // stays, with why it cannot be fitted.
      out.reason = std::move(fitting.reason);
      return out;
    }
    out.fits = std::move(fitting.fits);
    out.seconds.fit =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const KelvinVoigtTwoPointFit& fit = *out.fits.kelvin_voigt;
    out.ok = fit.ok;
    if (!fit.ok) {
      out.reason = fmt::format("{}: run \"{}\".fit_rebounds: {}", session.manifest.string(), run.id,
                               fit.reason);
    }
  } else {
    out.ok = true;
  }
  return out;
}

// One run, never throwing: a failure becomes the run's status.
RunResult ReduceRunOrFail(const Run& run, const Session& session, const Pendulum& pendulum,
                          Separation separation, CalibrationCache& calibrations,
                          const ReduceOptions& options, const StageOptions& session_options,
                          const std::optional<std::string>& fingerprint,
                          std::vector<std::string>& warnings) {
  try {
    return ReduceRun(run, session, pendulum, separation, calibrations, options, session_options,
                     fingerprint, warnings);
  } catch (const std::exception&) {
    RunResult failed;
    failed.id = run.id;
    failed.initial_displacement = run.initial_displacement;
    failed.first_rebound = run.first_rebound;
    failed.specimen = run.specimen;
    failed.reason = RunFailureReason(std::current_exception(), session, run);
    return failed;
  }
}

// A calibration's failure as the user reads it ("FILE: KEY: reason"), empty
// when it was made. An exception no stage made a value (a programming error)
// is said by its message: the calibration fails alone, as a run does
// (ReduceRunOrFail), and no worker thread lets it out.
std::string CalibrationFailure(CalibrationCache& calibrations, const std::string& id) {
  try {
    return calibrations.Get(id).Failure();
  } catch (const std::exception& error) {
    return error.what();
  }
}

// What the runs' reduce will measure: each run's fingerprint (none when its
// inputs cannot be read: the run fails with the reason when it comes), and
// the calibrations the runs to be measured name. Reused and typed-in runs
// need none.
struct MeasurementPlan {
  std::vector<std::optional<std::string>> fingerprints;
  std::vector<std::string> calibrations;
};

MeasurementPlan PlanMeasurement(const Session& session, const ReduceOptions& options) {
  MeasurementPlan plan;
  std::set<std::string> named;
  for (const Run& run : session.runs) {
    std::optional<std::string> fingerprint;
    try {
      fingerprint = RunFingerprint(run, session, options);
    } catch (const std::exception&) {
      // Reported by the run itself.
    }
    plan.fingerprints.push_back(fingerprint);
    if (!fingerprint || run.HasTypedRebounds() || Reusable(options, run, *fingerprint)) continue;
    for (const auto& [cell, id] : run.calibration) {
      if (named.insert(id).second) plan.calibrations.push_back(id);
    }
  }
  return plan;
}

// Calls `work(i)` for i in [0, count) on `jobs` threads.
void ForEachInParallel(std::size_t count, int jobs, const std::function<void(std::size_t)>& work) {
  std::atomic<std::size_t> next{0};
  const auto worker = [&] {
    for (std::size_t i = next++; i < count; i = next++) work(i);
  };
  std::vector<std::jthread> threads;
  for (int k = 1; k < std::min<int>(jobs, static_cast<int>(count)); ++k)
    threads.emplace_back(worker);
  worker();
}

// Table 3 and eq. 40 over the runs with a Kelvin-Voigt stiffness; with
// [reduction] average_stiffness, every run's C from the runs' mean K.
std::optional<SessionKelvinVoigt> AnalyseAcrossRuns(const std::vector<RunResult>& runs,
                                                    bool average_stiffness, double mass) {
  SessionKelvinVoigt out;
  std::vector<const KelvinVoigtTwoPointFit*> fits;
  for (const RunResult& run : runs) {
    if (!run.ok || !run.fits.kelvin_voigt->stiffness) continue;
    const KelvinVoigtTwoPointFit& fit = *run.fits.kelvin_voigt;
    fits.push_back(&fit);
    out.run_ids.push_back(run.id);
    out.sqrt_restitution.push_back(std::sqrt(fit.restitution.value));
    out.stiffness.push_back(fit.stiffness->value);
    out.damping.push_back(fit.damping->value);
    out.damping_sigma.push_back(fit.damping->sigma);
  }
  if (out.run_ids.empty()) return std::nullopt;
  if (average_stiffness) {
    const AverageStiffness average = AverageStiffnessOf(fits, mass);
    out.average_stiffness = average.stiffness;
    for (std::size_t i = 0; i < fits.size(); ++i) {
      out.damping[i] = average.damping[i].value;
      out.damping_sigma[i] = average.damping[i].sigma;
    }
  }
  out.spread = SpreadOf(out.stiffness);
  if (out.run_ids.size() >= 2) {
    // Runs of equal restitution give no line: the table stands without it.
    if (DampingLineFit line = FitDampingLine(out.sqrt_restitution, out.damping); line.ok) {
      out.damping_line = std::move(line.line);
    }
  }
  return out;
}

// `entries`, with a failed one made by `fail(rejected)` at the manifest
// position of each rejected entry, so results list in manifest order.
template <typename Result, typename MakeFailed>
std::vector<Result> WithRejected(std::vector<Result> entries,
                                 const std::vector<RejectedEntry>& rejected,
                                 const MakeFailed& fail) {
  std::vector<Result> merged;
  auto next = entries.begin();
  std::size_t position = 0;
  for (const RejectedEntry& entry : rejected) {
    for (; position < entry.position && next != entries.end(); ++position) {
      merged.push_back(std::move(*next++));
    }
    merged.push_back(fail(entry));
    ++position;
  }
  for (; next != entries.end(); ++next) merged.push_back(std::move(*next));
  return merged;
}

// The manifest's rejected entries in the results: a run or a log fails with
// its reason, as if it had failed while reducing; a calibration or a
// prediction, which has no place of its own there, becomes a warning.
void KeepRejectedEntries(const Session& session, const ReduceOptions& options,
                         SessionResult& result) {
  if (options.products != Products::kCalibration) {
    result.runs = WithRejected(std::move(result.runs), session.Rejected("run"),
                               [](const RejectedEntry& entry) {
                                 RunResult failed;
                                 failed.id = entry.id;
                                 failed.reason = entry.Reason();
                                 return failed;
                               });
  }
  if (options.products == Products::kFit) {
    result.logs = WithRejected(std::move(result.logs), session.Rejected("log"),
                               [](const RejectedEntry& entry) {
                                 LogResult failed;
                                 failed.id = entry.id;
                                 failed.reason = entry.Reason();
                                 return failed;
                               });
  }
  for (const std::string_view table : {"calibration", "prediction"}) {
    for (const RejectedEntry& entry : session.Rejected(table)) {
      result.warnings.push_back(fmt::format("{} {} skipped: {}", table, entry.id, entry.Reason()));
    }
  }
}

// Thumbnails: made when asked for and some photo was digitized (or reused).
void RecordThumbnails(const ProductOptions& asked, SessionResult& result) {
  bool photos = false;
  for (const RunResult& run : result.runs) {
    photos = photos || !run.measured.overlays.empty();
    for (const CellCalibration& c : run.measured.calibrations) photos = photos || c.overlay;
  }
  for (const CellCalibration& c : result.calibrations) photos = photos || c.overlay;
  ProductRecord record{"thumbnails", asked.thumbnails && photos, ""};
  if (!asked.thumbnails) {
    record.reason = kNotAsked;
  } else if (!photos) {
    record.reason = std::string(kUninformed) + "the session has no digitized photo";
  }
  result.products.push_back(std::move(record));
}

// `reduce --only calibration|rebounds`: no session-level fit is asked for.
void RecordNotAsked(const ProductOptions& asked, SessionResult& result) {
  ForEachSetting(asked, [&](const std::string& key, const auto&, const char*) {
    if (key == "thumbnails") return;
    result.products.push_back({key, false, std::string(kNotAsked) + " (reduce --only)"});
  });
  RecordThumbnails(asked, result);
}

// Rebounds the free pendulum cannot explain, at a threshold that keeps the
// whole session's false alarms at kAnomalyFalseAlarmRate when the errors are
// honest (docs/reduction.md, "Anomalies").
constexpr double kAnomalyFalseAlarmRate = 0.01;

void MarkAnomalies(const Pendulum& pendulum, std::vector<RunResult>& runs) {
  int tests = 0;
  for (const RunResult& run : runs) {
    if (!run.ok) continue;
    const RunMeasurement& m = run.measured;
    tests += CountReboundTests(m.xmax, m.rebound_duration, m.rebound_duration_sigma);
  }
  const ReboundAnomalyOptions options{AnomalyThreshold(kAnomalyFalseAlarmRate, tests)};
  for (RunResult& run : runs) {
    if (!run.ok) continue;
    const RunMeasurement& m = run.measured;
    for (const ReboundAnomaly& a :
         FindReboundAnomalies(pendulum, m.xmax, m.xmax_sigma, m.rebound_duration,
                              m.rebound_duration_sigma, options)) {
      run.anomalies.push_back(a.why);
    }
  }
}

// A typed X0 that the traces' own release contradicts: a warning naming the
// run, the key and both values. The typed X0 is half the gap between the
// bars at release, read off a scale: the bars' mean release is held to
// kTypedReleaseShare of X0 beyond kTypedReleaseSigmas of its error (on the
// external sessions the two agree to 0.14 % median, 0.63 % at most, at
// 0.18 % median standard error; a 10 % slip is flagged wherever the release
// is read to 1.6 %).
//
// Each bar's release is read through its own trace's voltage scale
// (volts_per_div, zero_div) and its own calibration, so a slip in one of
// those moves one bar's release alone, where a slip in X0 moves both. A bar
// is held to kBarReleaseShare of X0 (the bars may be let go a little
// asymmetrically: on the external sessions each bar's release lies within
// 1.3 % of X0, the two within 2.2 % of each other); one bar off while the
// other agrees names that bar's trace and calibration, not X0.
constexpr double kTypedReleaseSigmas = 5.0;
constexpr double kTypedReleaseShare = 0.02;
constexpr double kBarReleaseShare = 0.03;

bool ReleaseDisagrees(const Estimate& seen, double typed, double share) {
  return seen.sigma > 0.0 &&
         std::abs(typed - seen.value) > kTypedReleaseSigmas * seen.sigma + share * typed;
}

// The warning for a bar whose release alone disagrees with X0.
std::string OneBarOff(const Session& session, const Run& run, const char* cell, const Estimate& bar,
                      const Estimate& other) {
  const char* other_cell = std::string_view(cell) == "right" ? "left" : "right";
  std::string scale;
  if (const auto trace = run.traces.find(cell); trace != run.traces.end()) {
    scale = trace->second.csv
                ? fmt::format(" (the volts of {})", trace->second.csv->filename().string())
                : fmt::format(" (volts_per_div = {:g}, zero_div = {:g})",
                              trace->second.volts_per_div, trace->second.zero_div);
  }
  const auto calibration = run.calibration.find(cell);
  return fmt::format(
      "{}: run \"{}\": the {} bar's trace releases at {:.4g} ± {:.2g} ({:+.1f} % of "
      "initial_displacement = {:.4g}) where the {} bar's releases at {:.4g} ± {:.2g} ({:+.1f} %): "
      "traces.{}'s voltage scale{} mistyped, here or in calibration \"{}\"'s trace, or that "
      "trace misread? Its maxima read through the same scale",
      session.manifest.string(), run.id, cell, bar.value, bar.sigma,
      100.0 * (bar.value - run.initial_displacement) / run.initial_displacement,
      run.initial_displacement, other_cell, other.value, other.sigma,
      100.0 * (other.value - run.initial_displacement) / run.initial_displacement, cell, scale,
      calibration != run.calibration.end() ? calibration->second : std::string("?"));
}

void CheckTypedReleases(const Session& session, SessionResult& result) {
  for (const RunResult& result_run : result.runs) {
    const RunMeasurement& m = result_run.measured;
    if (!result_run.ok || !(m.release.sigma > 0.0)) continue;
    const auto run = std::find_if(session.runs.begin(), session.runs.end(),
                                  [&](const Run& r) { return r.id == result_run.id; });
    if (run == session.runs.end()) continue;
    const double typed = result_run.initial_displacement;
    // One bar off, the other with X0: that bar's voltage scale, not X0.
    if (m.right && m.left) {
      const bool right_off = ReleaseDisagrees(m.right->release, typed, kBarReleaseShare);
      const bool left_off = ReleaseDisagrees(m.left->release, typed, kBarReleaseShare);
      if (right_off != left_off && m.right->release.sigma > 0.0 && m.left->release.sigma > 0.0) {
        result.warnings.push_back(
            right_off ? OneBarOff(session, *run, "right", m.right->release, m.left->release)
                      : OneBarOff(session, *run, "left", m.left->release, m.right->release));
        continue;
      }
    }
    if (ReleaseDisagrees(m.release, typed, kTypedReleaseShare)) {
      result.warnings.push_back(fmt::format(
          "{}: run \"{}\": initial_displacement = {:.4g}, but its traces release at {:.4g} ± "
          "{:.2g} ({:+.1f} %): X0 mistyped here or in a calibration it reads through? The fits "
          "and the % of X0 columns use the typed value",
          session.manifest.string(), result_run.id, typed, m.release.value, m.release.sigma,
          100.0 * (typed - m.release.value) / m.release.value));
    }
  }
}

// A run whose rebounds all last longer (or shorter) than the pendulum's half
// period at their amplitudes by a common factor: its time axis (a photo's
// time_per_div, a CSV's time unit) or the apparatus's pendulum_length or
// gravity is off, not its swings. A voltage scale off moves the traces'
// X = 0, and with it every crossing the durations are read between (on the
// external sessions a volts_per_div 10 % low fired this warning on 8 of 72
// run traces), so the message names it too. The durations' weighted mean ratio to the
// half period, beyond 5 of its errors plus 0.5 % (a 1 % error in L moves the
// period by 0.5 %), is named with the figures.
constexpr double kSweepSigmas = 5.0;
constexpr double kSweepShare = 0.005;

void CheckSweepsAgainstPendulum(const Session& session, const Pendulum& pendulum,
                                SessionResult& result) {
  for (const RunResult& run : result.runs) {
    const RunMeasurement& m = run.measured;
    if (!run.ok) continue;
    double sum_w = 0.0, sum_wr = 0.0;
    int used = 0;
    for (std::size_t n = 0; n < m.rebound_duration.size() && n < m.xmax.size(); ++n) {
      if (n >= m.rebound_duration_sigma.size() || !(m.rebound_duration_sigma[n] > 0.0)) continue;
      const std::optional<double> half_period = HalfPeriodIfSwings(pendulum, m.xmax[n]);
      if (!half_period) continue;  // no swing reaches it: its duration says nothing of L or g
      const double half = *half_period;
      const double sigma = m.rebound_duration_sigma[n] / half;
      sum_w += 1.0 / (sigma * sigma);
      sum_wr += m.rebound_duration[n] / half / (sigma * sigma);
      ++used;
    }
    if (used < 3) continue;
    const double ratio = sum_wr / sum_w, sigma = 1.0 / std::sqrt(sum_w);
    if (std::abs(ratio - 1.0) > kSweepSigmas * sigma + kSweepShare) {
      result.warnings.push_back(fmt::format(
          "{}: run \"{}\": its {} rebounds last {:.4f} ± {:.4f} times the pendulum's half "
          "period at their amplitudes: the time axis of its traces (time_per_div, a CSV's time "
          "unit), [apparatus] pendulum_length or gravity mistyped? Or a trace's voltage scale "
          "(volts_per_div, zero_div, here or in its calibration's trace): it moves X = 0, which "
          "lengthens or shortens the smaller rebounds most",
          session.manifest.string(), run.id, used, ratio, sigma));
    }
  }
}

// A calibration that failed is reported by the runs that name it; one whose
// runs all failed before they asked for it (a run's other bar first) would
// go unreported. Its failure is a warning then: every broken entry is said,
// with its file, key and reason.
void WarnOfUnreachedFailures(const MeasurementPlan& plan, CalibrationCache& calibrations,
                             SessionResult& result) {
  for (const std::string& id : plan.calibrations) {
    const std::string reason = CalibrationFailure(calibrations, id);
    if (reason.empty()) continue;
    const bool said = std::any_of(result.runs.begin(), result.runs.end(), [&](const RunResult& r) {
      return !r.ok && r.reason.find(reason) != std::string::npos;
    });
    if (!said) result.warnings.push_back(reason);
  }
}

// Counts the work done for ReduceOptions::on_progress, from any thread.
class ProgressCounter {
 public:
  explicit ProgressCounter(const ReduceOptions& options) : report_(options.on_progress) {}
  void Expect(std::size_t more) {
    const std::lock_guard lock(mutex_);
    total_ += more;
  }
  void Done(std::string item, bool ok, bool reused = false) {
    if (!report_) return;
    const std::lock_guard lock(mutex_);
    report_({std::move(item), ok, reused, ++done_, total_});
  }

 private:
  const std::function<void(const ReduceProgress&)>& report_;
  std::mutex mutex_;
  std::size_t done_ = 0, total_ = 0;
};

// A calibration that left a misread stretch of its swing out
// (photocell_calibration.h) is worth a look at its overlay: said once per
// calibration.
void WarnOfLeftOutStretches(SessionResult& result) {
  std::vector<const CellCalibration*> calibrations;
  for (const CellCalibration& c : result.calibrations) calibrations.push_back(&c);
  for (const RunResult& run : result.runs) {
    for (const CellCalibration& c : run.measured.calibrations) calibrations.push_back(&c);
  }
  std::set<std::string> warned;
  for (const CellCalibration* c : calibrations) {
    if (c->left_out_from_s.empty() || !warned.insert(c->calibration_id).second) continue;
    std::string stretches;
    for (std::size_t i = 0; i < c->left_out_from_s.size(); ++i) {
      stretches += fmt::format("{}{:.4g} .. {:.4g} s", i == 0 ? "" : ", ", c->left_out_from_s[i],
                               c->left_out_to_s[i]);
    }
    result.warnings.push_back(fmt::format(
        "calibration \"{}\": its trace is far off the curve through the rest at t = {}, "
        "left out as misread (a mark or a scratch followed?): see its overlay",
        c->calibration_id, stretches));
  }
}

// A run whose bar's trace had stretches far outside its calibrated voltages,
// left out as misread before its rebounds were read: said, as a calibration's
// are, so that a reader looks at the overlay.
void WarnOfMisreadRunStretches(SessionResult& result) {
  for (const RunResult& run : result.runs) {
    for (const auto& [cell, bar] :
         {std::pair{"right", &run.measured.right}, std::pair{"left", &run.measured.left}}) {
      if (!run.ok || !*bar || (*bar)->left_out_from_s.empty()) continue;
      std::string stretches;
      for (std::size_t i = 0; i < (*bar)->left_out_from_s.size(); ++i) {
        stretches += fmt::format("{}{:.4g} .. {:.4g} s", i == 0 ? "" : ", ",
                                 (*bar)->left_out_from_s[i], (*bar)->left_out_to_s[i]);
      }
      result.warnings.push_back(fmt::format(
          "run \"{}\": its {} trace lies far outside its calibrated voltages at t = {}, left "
          "out as misread (a mark, a scratch or a grid line followed?): see its overlay",
          run.id, cell, stretches));
    }
  }
}

// Every run, calibration and log the manifest could read.
SessionResult ReduceReadableEntries(const Session& session, const ReduceOptions& options) {
  SessionResult result;
  result.title = session.title;
  result.units = session.units;
  result.producer = options.producer;
  result.created = NowIso8601();
  // The folder as the file will be read later, from anywhere: absolute.
  result.session_folder = std::filesystem::absolute(session.folder).lexically_normal().string();
  result.convention = options.convention.value_or(ParseConvention(session.reduction.convention));
  result.separation = options.separation.value_or(ParseSeparation(session.reduction.separation));
  result.session_contact_time = session.reduction.contact_time;
  result.specimen = session.specimen;
  if (options.jobs < 1) throw std::invalid_argument("jobs must be at least 1");
  // The settings are checked before any work; an entry's own with the entry.
  const StageOptions session_options =
      SessionStageOptions(options.stages, session, options.overrides);
  result.settings = SettingsOf(session_options);
  const auto entry_options = [&](const StageSettings& entry) {
    return EntryStageOptions(session_options, entry, options.overrides);
  };
  std::mutex warnings_mutex;
  ProgressCounter progress(options);
  // Logs are independent of the runs: each is analysed whatever else the session has.
  if (options.products == Products::kFit) {
    progress.Expect(session.logs.size());
    for (const Log& log : session.logs) {
      try {
        const StageOptions log_options = entry_options(log.settings);
        result.logs.push_back(ReduceLog(log, log_options.log_analysis));
        result.logs.back().settings = SettingsOfStages(log_options, {"log_analysis"});
      } catch (const InputError& error) {
        LogResult failed;
        failed.id = log.id;
        failed.reason = error.what();
        result.logs.push_back(std::move(failed));
      }
      progress.Done("log " + log.id, result.logs.back().ok);
    }
  }
  if (session.runs.empty() && options.products != Products::kCalibration) return result;
  if (!session.apparatus) {
    throw InputError({session.manifest, "apparatus", std::nullopt},
                     "[apparatus] is required when the session has runs");
  }
  result.apparatus = *session.apparatus;
  const Pendulum pendulum{session.apparatus->pendulum_length, session.apparatus->gravity,
                          result.convention};

  CalibrationCache calibrations(session, pendulum, [&](const Calibration& calibration) {
    return entry_options(calibration.settings);
  });
  if (options.products == Products::kCalibration) {
    std::vector<std::optional<CellCalibration>> done(session.calibrations.size());
    progress.Expect(done.size());
    ForEachInParallel(done.size(), options.jobs, [&](std::size_t i) {
      const Calibration& c = session.calibrations[i];
      if (std::string failure = CalibrationFailure(calibrations, c.id); failure.empty()) {
        done[i] =
            SummariseCalibration(c.id, c.cell, c.initial_displacement, calibrations.Get(c.id));
      } else {
        std::lock_guard lock(warnings_mutex);
        result.warnings.push_back(std::move(failure));
      }
      progress.Done("calibration " + c.id, done[i].has_value());
    });
    for (auto& c : done) {
      if (c) result.calibrations.push_back(std::move(*c));
    }
    WarnOfLeftOutStretches(result);
    RecordNotAsked(session_options.products, result);
    return result;
  }

  // A photo is the unit of work, not a run: the calibrations' photos are
  // tasks of their own, ahead of the runs, so that no run waits long for a
  // calibration and the threads finish within a photo of each other. (A run
  // with its two calibrations is three photos.) Their errors reach the runs.
  const MeasurementPlan plan = PlanMeasurement(session, options);
  std::vector<RunResult> runs(session.runs.size());
  std::vector<std::vector<std::string>> run_warnings(session.runs.size());
  const std::size_t ahead = plan.calibrations.size();
  progress.Expect(ahead + runs.size());
  ForEachInParallel(ahead + runs.size(), options.jobs, [&](std::size_t task) {
    if (task < ahead) {
      // A failure is kept in the cache; every run that names it reports it.
      const bool ok = CalibrationFailure(calibrations, plan.calibrations[task]).empty();
      progress.Done("calibration " + plan.calibrations[task], ok);
      return;
    }
    const std::size_t i = task - ahead;
    runs[i] = ReduceRunOrFail(session.runs[i], session, pendulum, result.separation, calibrations,
                              options, session_options, plan.fingerprints[i], run_warnings[i]);
    progress.Done("run " + runs[i].id, runs[i].ok, runs[i].reused);
  });
  result.runs = std::move(runs);
  for (std::vector<std::string>& said : run_warnings) {
    result.warnings.insert(result.warnings.end(), said.begin(), said.end());
  }
  WarnOfUnreachedFailures(plan, calibrations, result);
  WarnOfLeftOutStretches(result);
  WarnOfMisreadRunStretches(result);
  MarkAnomalies(pendulum, result.runs);
  CheckTypedReleases(session, result);
  CheckSweepsAgainstPendulum(session, pendulum, result);
  for (const RunResult& run : result.runs) {
    if (!run.ok || !run.measured.right || !run.measured.left) continue;
    const auto disagreement = FirstDisagreement(*run.measured.right, *run.measured.left);
    if (disagreement && run.measured.xmax.size() <= disagreement->rebound) {
      result.warnings.push_back(fmt::format("run \"{}\": its maxima stop at rebound {}: {}", run.id,
                                            disagreement->rebound, disagreement->why));
    } else if (disagreement) {
      // The pendulum's clock told the misread bar (MeanOfBars).
      result.warnings.push_back(fmt::format(
          "run \"{}\": {}; that rebound is the other bar's, the one on the pendulum's clock, "
          "less the bars' common swing",
          run.id, disagreement->why));
    } else if (const auto lost = OneBarStretch(*run.measured.right, *run.measured.left,
                                               run.measured.xmax.size())) {
      result.warnings.push_back(fmt::format("run \"{}\": {}", run.id, *lost));
    }
  }
  if (options.products != Products::kFit) {
    RecordNotAsked(session_options.products, result);
    return result;
  }

  const LawInputs law_inputs{pendulum, session.apparatus->mass, result.separation,
                             ContactRebounds(session), options.jobs};
  MakeSessionFits(law_inputs, session_options.fit, session_options.products, result);
  AddMaterialConstants(session.specimen, result.runs, session_options.fit.contact_laws.exponent,
                       result.contact_laws);
  RecordThumbnails(session_options.products, result);
  result.kelvin_voigt =
      AnalyseAcrossRuns(result.runs, session.reduction.average_stiffness, session.apparatus->mass);

  for (const Prediction& p : session.predictions) {
    const auto skipped = [&](const std::string& why) {
      result.warnings.push_back(
          fmt::format("{}: prediction of run \"{}\" from run \"{}\" skipped: {}",
                      session.manifest.string(), p.target_run, p.source_run, why));
    };
    const RunResult* source = result.FindRun(p.source_run);
    const RunResult* target = result.FindRun(p.target_run);
    if (source == nullptr || target == nullptr || !source->ok || !target->ok) {
      skipped("both runs must reduce to a Kelvin-Voigt fit");
      continue;
    }
    PredictedRun predicted =
        PredictRun(pendulum, source->id, *source->fits.kelvin_voigt, target->id,
                   target->measured.xmax, *target->fits.kelvin_voigt, p.start_rebound);
    if (predicted.ok) {
      result.predictions.push_back(std::move(predicted.prediction));
    } else {
      skipped(predicted.reason);
    }
  }
  return result;
}

}  // namespace

SessionResult ReduceSession(const Session& session, const ReduceOptions& options) {
  SessionResult result = ReduceReadableEntries(session, options);
  KeepRejectedEntries(session, options, result);
  return result;
}

}  // namespace impactlab
