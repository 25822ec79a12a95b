#include "pipeline/trace_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "calibration/displacement.h"
#include "io/errors.h"
#include "io/session_file.h"
#include "io/trace.h"
#include "pipeline/photo_traces.h"
#include "rebounds/bar_rebounds.h"
#include "rebounds/rebound_extraction.h"

namespace impactlab {
namespace {

std::string RunKey(const Run& run) { return fmt::format("run \"{}\"", run.id); }

// A CSV trace the manifest names, read as every session file is
// (io/session_file.h): from inside the session folder, a regular file only.
Trace ReadSessionTraceCsv(const Session& session, const std::filesystem::path& file) {
  const std::vector<unsigned char> bytes = ReadSessionFile(session.folder, file);
  std::istringstream in(std::string(bytes.begin(), bytes.end()));
  return ParseTraceCsv(in, file);
}

// Where and why a step stopped a measurement: the file, and the manifest
// key a user can fix.
struct StepFailure {
  InputLocation at;
  std::string reason;
};

// Records `failure` in `result` (a CalibratedCell, a MeasuredTraceRun): it is
// the result's failure. Returns false, for the step that stops to return.
template <typename Result>
bool Stopped(Result& result, StepFailure failure) {
  result.ok = false;
  result.failed_at = std::move(failure.at);
  result.reason = std::move(failure.reason);
  return false;
}

// A photo's trace, before the photo is read: its sweep (time_per_div times
// the horizontal divisions) against the pendulum's swings; empty when it
// fits them. `limits`: the run's rebound extraction's, which every trace's
// time axis is held to.
std::string PhotoSweepProblem(const TraceSettings& settings, const Session& session,
                              const Pendulum& pendulum, const TraceSpanLimits& limits) {
  const double sweep_s = settings.time_per_div * session.divisions[0];
  const std::string problem = TraceSpanProblem(sweep_s, 0.0, 0, pendulum, limits);
  if (problem.empty()) return {};
  return fmt::format("time_per_div = {:g} s over {} divisions: {}", settings.time_per_div,
                     session.divisions[0], problem);
}

// A trace as read (a CSV, or a photo digitized): its span against the
// pendulum's swings and its sample interval; `rebounds`: a trace the
// rebounds are read from, which must also resolve each swing. Empty when
// the trace fits them.
std::string TraceSpanProblemOf(const Trace& trace, const Pendulum& pendulum, bool rebounds,
                               const TraceSpanLimits& limits) {
  if (trace.time_s.size() < 2) return {};  // the stages say why
  const double span_s = trace.time_s.back() - trace.time_s.front();
  std::vector<double> steps;
  steps.reserve(trace.time_s.size() - 1);
  for (std::size_t i = 1; i < trace.time_s.size(); ++i) {
    steps.push_back(trace.time_s[i] - trace.time_s[i - 1]);
  }
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  const double interval_s = steps[steps.size() / 2];
  return TraceSpanProblem(span_s, interval_s, rebounds ? trace.time_s.size() : 0, pendulum, limits);
}

// Why a run trace's volts may miss its calibration's range, where the two
// ranges say so: the run and its calibration swing between the same two
// places (X = 0 at the impacts, about X0 at release), so their voltage
// ranges' ends should agree. Both ends k times the calibration's is one
// voltage scale off (volts_per_div, here or in the calibration's trace);
// both shifted by one voltage is the zero's place (zero_div). Empty when
// the ends tell neither apart from a misread trace (within 6 %: a photo
// loses the trace's lowest stretches at the impacts).
std::string VoltageScaleHint(const Trace& trace, const PhotocellCurve& curve,
                             const TraceSettings& settings, const std::string& calibration_id) {
  if (trace.volts.empty()) return {};
  const auto [lo, hi] = std::minmax_element(trace.volts.begin(), trace.volts.end());
  const double c = curve.volts_min(), d = curve.volts_max(), range = d - c;
  if (!(range > 0.0)) return {};
  constexpr double kAgree = 0.06;
  const double k_lo = *lo / c, k_hi = *hi / d;
  if (c * d > 0.0 && std::abs(k_lo - k_hi) < kAgree * std::abs(k_hi) &&
      std::abs(k_hi - 1.0) > kAgree) {
    const double k = 0.5 * (k_lo + k_hi);
    if (settings.csv) {
      return fmt::format(
          " (its volts span {:.4g} .. {:.4g} V, {:.3g} times the calibration's: the CSV's "
          "volts in another unit?)",
          *lo, *hi, k);
    }
    return fmt::format(
        " (its volts span {:.4g} .. {:.4g} V, {:.3g} times the calibration's at both ends: "
        "volts_per_div = {:g} mistyped, where {:.3g} would fit, or calibration \"{}\"'s?)",
        *lo, *hi, k, settings.volts_per_div, settings.volts_per_div / k, calibration_id);
  }
  const double o_lo = *lo - c, o_hi = *hi - d;
  if (std::abs(o_lo - o_hi) < kAgree * range && std::abs(o_hi) > kAgree * range && !settings.csv &&
      settings.volts_per_div > 0.0) {
    const double o = 0.5 * (o_lo + o_hi);
    return fmt::format(
        " (its volts span {:.4g} .. {:.4g} V, {:+.3g} V from the calibration's at both ends: "
        "zero_div = {:g} mistyped, where {:.3g} would fit, or calibration \"{}\"'s?)",
        *lo, *hi, o, settings.zero_div, settings.zero_div + o / settings.volts_per_div,
        calibration_id);
  }
  return {};
}

// Which rebounds (session numbering) each bar's trace shows a maximum of, in
// words: where a run has too few, whether the photo lacks them or one bar's
// reading lost them.
std::string ReboundsShown(const RunMeasurement& measured) {
  std::string said;
  for (const auto& [cell, bar] :
       {std::pair{"right", &measured.right}, std::pair{"left", &measured.left}}) {
    if (!*bar) continue;
    std::string numbers;
    for (std::size_t i = 0; i < (*bar)->xmax.size(); ++i) {
      numbers += fmt::format("{}{}", i == 0 ? "" : ", ", (*bar)->Number(i));
    }
    said += fmt::format("{}the {} bar's trace shows {}", said.empty() ? "" : ", ", cell,
                        numbers.empty() ? "no rebound" : "rebounds " + numbers);
  }
  return said;
}

}  // namespace

std::string CalibratedCell::Failure() const {
  return ok ? std::string() : FormatLocation(failed_at) + ": " + reason;
}

std::string MeasuredTraceRun::Failure() const {
  return ok ? std::string() : FormatLocation(failed_at) + ": " + reason;
}

CellCalibration SummariseCalibration(const std::string& id, const std::string& cell,
                                     double release_x, const CalibratedCell& calibrated) {
  const CalibrationResult& c = calibrated.calibration;
  CellCalibration out;
  out.overlay = calibrated.overlay;
  out.settings = calibrated.settings;
  out.calibration_id = id;
  out.cell = cell;
  out.release_x = release_x;
  out.order = c.curve.order();
  out.chebyshev = c.curve.chebyshev();
  out.chebyshev_covariance.values = c.curve.covariance();
  out.residual_rms_volts = c.residual_rms_volts;
  out.residual_rms_length = c.residual_rms_length;
  out.samples_used = c.samples_used;
  out.volts_min = c.curve.volts_min();
  out.volts_max = c.curve.volts_max();
  for (const auto& [from, to] : c.left_out_s) {
    out.left_out_from_s.push_back(from);
    out.left_out_to_s.push_back(to);
  }
  const std::size_t stride = std::max<std::size_t>(1, c.volts.size() / 500);
  for (std::size_t i = 0; i < c.volts.size(); i += stride) {
    out.points_x.push_back(c.ideal_displacement[i]);
    out.points_volts.push_back(c.volts[i]);
  }
  return out;
}

namespace {

// Adds the seconds `work` takes to `total`.
template <class Work>
auto Timed(double& total, Work&& work) {
  const auto start = std::chrono::steady_clock::now();
  struct Add {
    double& total;
    std::chrono::steady_clock::time_point start;
    ~Add() {
      total += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
  } add{total, start};
  return work();
}

}  // namespace

const CalibratedCell& CalibrationCache::Get(const std::string& id, StageSeconds* charge) {
  std::promise<std::shared_ptr<const CalibratedCell>> promise;
  std::unique_lock lock(mutex_);
  const auto [it, first] = entries_.try_emplace(id);
  if (first) it->second = promise.get_future().share();
  const Entry entry = it->second;
  lock.unlock();
  if (first) {
    try {
      promise.set_value(Compute(id));
    } catch (const InputError& error) {
      // A file that cannot be read, or the entry's own settings: the
      // calibration's failure, said with the file and key.
      auto failed = std::make_shared<CalibratedCell>();
      Stopped(*failed, {error.where(), error.problem()});
      promise.set_value(std::move(failed));
    } catch (...) {
      promise.set_exception(std::current_exception());  // a programming error
    }
  }
  const CalibratedCell& cell = *entry.get();  // rethrows a programming error
  if (charge != nullptr) {
    const std::lock_guard guard(mutex_);
    if (charged_.insert(id).second) {
      charge->load += cell.cost.load;
      charge->calibrate += cell.cost.calibrate;
    }
  }
  return cell;
}

std::shared_ptr<const CalibratedCell> CalibrationCache::Compute(const std::string& id) const {
  const auto calibration = std::find_if(session_.calibrations.begin(), session_.calibrations.end(),
                                        [&](const Calibration& c) { return c.id == id; });
  const std::string key = fmt::format("calibration \"{}\"", id);
  auto cell = std::make_shared<CalibratedCell>();
  if (calibration == session_.calibrations.end()) {
    Stopped(*cell, {{session_.manifest, key, std::nullopt}, "no such calibration"});
    return cell;
  }
  const StageOptions options = options_of_(*calibration);
  const TraceSpanLimits& limits = options.rebound_extraction.limits;
  StageSeconds& seconds = cell->cost;
  cell->settings = calibration->trace.csv ? SettingsOfStages(options, {"photocell"})
                                          : SettingsOfStages(options, {"digitize", "photocell"});
  // Its CSV when given, otherwise its photo digitized (the overlay kept).
  Trace trace;
  double shared_sigma_volts = 0.0;  // a photo's mapping error, shared by its samples
  if (calibration->trace.csv) {
    trace =
        Timed(seconds.load, [&] { return ReadSessionTraceCsv(session_, *calibration->trace.csv); });
    if (std::string problem = TraceSpanProblemOf(trace, pendulum_, false, limits);
        !problem.empty()) {
      Stopped(*cell, {{*calibration->trace.csv, key + ".trace", std::nullopt}, std::move(problem)});
      return cell;
    }
  } else if (calibration->photo) {
    if (std::string problem = PhotoSweepProblem(calibration->trace, session_, pendulum_, limits);
        !problem.empty()) {
      Stopped(*cell,
              {{session_.manifest, key + ".trace.time_per_div", std::nullopt}, std::move(problem)});
      return cell;
    }
    DigitizedPhoto digitized = Timed(seconds.load, [&] {
      return DigitizeSessionPhoto(*calibration->photo, session_, {{"trace", calibration->trace}},
                                  options.digitize, options.products.thumbnails);
    });
    cell->overlay = std::move(digitized.overlay);  // kept when not read too: it shows why not
    if (!digitized.ok) {
      Stopped(*cell, {digitized.failed_at, digitized.reason});
      return cell;
    }
    trace = std::move(digitized.traces.at("trace"));
    shared_sigma_volts = digitized.mapping_sigma_volts.at("trace");
  } else {
    Stopped(*cell, {{session_.manifest, key + ".trace", std::nullopt},
                    "the trace has neither a csv nor a photo"});
    return cell;
  }
  cell->calibration = Timed(seconds.calibrate, [&] {
    return CalibratePhotocell(trace, pendulum_, calibration->initial_displacement,
                              options.photocell, shared_sigma_volts);
  });
  if (!cell->calibration.ok) {
    Stopped(*cell,
            {{calibration->trace.csv.value_or(calibration->photo.value_or(session_.manifest)), key,
              std::nullopt},
             cell->calibration.reason});
    return cell;
  }
  cell->ok = true;
  return cell;
}

namespace {

// The run's contact time from its contact trace (`settings`), into `out`;
// the failure when the trace cannot be read: not found on the photo, a CSV
// that cannot be read or whose span does not fit (`span_failure`), or no
// pulse on it. `trace_of` reads a trace, as MeasureInto does.
template <typename TraceOf, typename SpanFailure>
std::optional<StepFailure> MeasureContactTime(const Run& run, const Session& session,
                                              const TraceSettings& settings,
                                              const std::optional<DigitizedPhoto>& photo,
                                              const TraceOf& trace_of,
                                              const SpanFailure& span_failure,
                                              RunMeasurement& out) {
  const std::string key = RunKey(run) + ".traces.contact";
  // On a photo the edges are measured on the image itself; a CSV step by
  // its samples.
  ContactPulseMeasurement pulse;
  if (!settings.csv && photo) {
    if (const auto lost = photo->lost.find("contact"); lost != photo->lost.end()) {
      // The photo's key for the trace, said as the run's.
      const InputLocation& at = lost->second.at;
      return StepFailure{{at.file, RunKey(run) + "." + at.key, at.line}, lost->second.reason};
    }
  }
  if (!settings.csv && photo && photo->pulse) {
    pulse = {true, "", *photo->pulse};
  } else {
    Trace trace;
    try {
      trace = trace_of("contact", settings);
    } catch (const InputError& error) {
      InputLocation at = error.where();
      if (at.key.empty()) at.key = key;
      return StepFailure{std::move(at), error.problem()};
    }
    if (std::optional<StepFailure> failure = span_failure("contact", settings, trace)) {
      return failure;
    }
    pulse = MeasureContactPulse(trace);
  }
  if (!pulse.ok) {
    return StepFailure{
        {settings.csv.value_or(run.photo.value_or(session.manifest)), key, std::nullopt},
        pulse.reason};
  }
  out.contact_time = pulse.pulse.width_s.value;
  out.contact_time_sigma = pulse.pulse.width_s.sigma;
  out.contact_time_source = "contact trace";
  return std::nullopt;
}

// Measures the run into `result` step by step, so that what was measured
// before a failure (the photo's overlay, the calibrations) stays there.
// Returns false at the first step that stops it, `result` saying where and
// why; throws InputError only for a file that cannot be read.
bool MeasureInto(const Run& run, const Session& session, const Pendulum& pendulum,
                 const StageOptions& options, CalibrationCache& calibrations,
                 MeasuredTraceRun& result) {
  const TraceSpanLimits& limits = options.rebound_extraction.limits;
  RunMeasurement& out = result.measured;
  StageSeconds& seconds = result.seconds;
  out.source = run.photo ? "photo" : "csv";
  // Every trace the run reads from its photo, in one pass over the photo.
  std::map<std::string, TraceSettings> from_photo;
  for (const auto& [name, settings] : run.traces) {
    if (settings.csv) continue;
    // Before the photo is read: nothing may grow with a sweep of 1e300 s.
    if (std::string problem = PhotoSweepProblem(settings, session, pendulum, limits);
        !problem.empty()) {
      return Stopped(
          result, {{session.manifest, fmt::format("{}.traces.{}.time_per_div", RunKey(run), name),
                    std::nullopt},
                   std::move(problem)});
    }
    from_photo[name] = settings;
  }
  std::optional<DigitizedPhoto> photo;
  if (!from_photo.empty()) {
    if (!run.photo) {
      return Stopped(result,
                     {{session.manifest, RunKey(run) + ".photo", std::nullopt},
                      "traces without `csv` are read from the run's photo, and it has none"});
    }
    photo = Timed(seconds.load, [&] {
      return DigitizeSessionPhoto(*run.photo, session, from_photo, options.digitize,
                                  options.products.thumbnails);
    });
    // Kept when the photo was not read too: it shows what was found and why not.
    out.overlays.push_back(photo->overlay);
    if (!photo->ok) return Stopped(result, {photo->failed_at, photo->reason});
  }
  // A trace as read: its CSV, or its samples from the photo (throws
  // InputError for a CSV that cannot be read).
  const auto trace_of = [&](const std::string& name, const TraceSettings& settings) {
    return settings.csv
               ? Timed(seconds.load, [&] { return ReadSessionTraceCsv(session, *settings.csv); })
               : photo->traces.at(name);
  };
  // Every trace checked as read: its span against the pendulum's swings, and
  // (right, left) that it resolves them. The failure when the check refuses it.
  const auto span_failure = [&](const std::string& name, const TraceSettings& settings,
                                const Trace& trace) -> std::optional<StepFailure> {
    std::string problem = TraceSpanProblemOf(trace, pendulum, name != "contact", limits);
    if (problem.empty()) return std::nullopt;
    const std::string key = fmt::format("{}.traces.{}", RunKey(run), name);
    return StepFailure{{settings.csv.value_or(run.photo.value_or(session.manifest)),
                        settings.csv ? key : key + ".time_per_div", std::nullopt},
                       std::move(problem)};
  };
  // A bar's trace read and checked; false when the check stops the run.
  const auto read_trace = [&](const std::string& name, const TraceSettings& settings,
                              Trace& trace) {
    trace = trace_of(name, settings);
    if (std::optional<StepFailure> failure = span_failure(name, settings, trace)) {
      return Stopped(result, std::move(*failure));
    }
    return true;
  };
  std::map<std::string, DisplacementHistory> histories;
  std::map<std::string, const PhotocellCurve*> curves;
  // Per bar, the volts its run trace's samples share through the run photo's
  // mapping (0 for a CSV): a maximum carries it whole, through the curve's
  // slope there, as it carries the curve's own error.
  std::map<std::string, double> mapping_sigma_volts;
  // Per bar, the stretches of its trace left out as misread (far outside its
  // calibrated voltages), which its rebounds report.
  std::map<std::string, std::vector<std::pair<double, double>>> left_out_s;
  for (const char* cell : {"right", "left"}) {
    const auto trace_it = run.traces.find(cell);
    if (trace_it == run.traces.end()) continue;
    const std::string key = fmt::format("{}.traces.{}", RunKey(run), cell);
    const auto cal_it = run.calibration.find(cell);
    if (cal_it == run.calibration.end()) {
      return Stopped(result, {{session.manifest, key, std::nullopt},
                              fmt::format("no calibration is named for the {} cell", cell)});
    }
    const CalibratedCell& calibrated = calibrations.Get(cal_it->second, &seconds);
    if (!calibrated.ok) return Stopped(result, {calibrated.failed_at, calibrated.reason});
    const CalibrationResult& calibration = calibrated.calibration;
    const auto cal = std::find_if(session.calibrations.begin(), session.calibrations.end(),
                                  [&](const Calibration& c) { return c.id == cal_it->second; });
    out.calibrations.push_back(
        SummariseCalibration(cal_it->second, cell, cal->initial_displacement, calibrated));
    Trace trace;
    if (!read_trace(cell, trace_it->second, trace)) return false;
    DisplacementConversion converted = Timed(seconds.extract, [&] {
      return DisplacementFromVolts(trace, calibration, {}, run.initial_displacement);
    });
    const std::string hint =
        converted.ok && converted.left_out == 0
            ? std::string()
            : VoltageScaleHint(trace, calibration.curve, trace_it->second, cal_it->second);
    // Stretches far outside are a line that is not the trace, unless both
    // ends of the ranges say that a voltage scale or zero is off: then every
    // sample is, and none can be read.
    if (!converted.ok || !hint.empty()) {
      return Stopped(
          result,
          {{trace_it->second.csv.value_or(run.photo.value_or(session.manifest)), key, std::nullopt},
           (converted.ok ? fmt::format("{} of {} samples lie far outside the calibrated range "
                                       "{:.4g} .. {:.4g} V: the calibration does not cover what "
                                       "this run needs",
                                       converted.left_out, trace.volts.size(),
                                       calibration.curve.volts_min(), calibration.curve.volts_max())
                         : converted.reason) +
               hint});
    }
    left_out_s[cell] = std::move(converted.left_out_s);
    histories[cell] = std::move(converted.history);
    curves[cell] = &calibration.curve;
    mapping_sigma_volts[cell] = trace_it->second.csv ? 0.0 : photo->mapping_sigma_volts.at(cell);
  }
  if (histories.empty()) {
    return Stopped(result, {{session.manifest, RunKey(run) + ".traces", std::nullopt},
                            "the run has no right or left displacement trace"});
  }

  // A history's rebounds in the session's numbering; nullopt when the
  // extraction refuses the history, `result` saying why.
  const auto extract = [&](const DisplacementHistory& h) {
    return Timed(seconds.extract, [&]() -> std::optional<BarRebounds> {
      const ReboundExtraction extracted = ExtractRebounds(h, pendulum, options.rebound_extraction);
      if (!extracted.ok) {
        Stopped(result,
                {{session.manifest, RunKey(run) + ".traces", std::nullopt}, extracted.reason});
        return std::nullopt;
      }
      return InSessionNumbering(extracted, run.first_rebound);
    });
  };
  // What a reading at displacement x shares with its neighbours: the curve's
  // error there and the run photo's mapping error through the curve's slope.
  const auto shared_sigma_at = [&](const std::string& cell, double x) {
    const PhotocellCurve& curve = *curves.at(cell);
    const double slope = std::abs(curve.SlopeAt(std::clamp(x, 0.0, curve.x_max())));
    const double mapping = slope > 0.0 ? mapping_sigma_volts.at(cell) / slope : 0.0;
    return std::hypot(curve.DisplacementSigmaAt(x), mapping);
  };
  const auto curve_sigma = [&](const char* cell) {
    return
        [&shared_sigma_at, cell = std::string(cell)](double x) { return shared_sigma_at(cell, x); };
  };
  const auto report_left_out = [&](BarRebounds& bar, const std::string& cell) {
    for (const auto& [from, to] : left_out_s[cell]) {
      bar.left_out_from_s.push_back(from);
      bar.left_out_to_s.push_back(to);
    }
  };
  if (histories.count("right")) {
    out.right = extract(histories["right"]);
    if (!out.right) return false;
    AddCurveSigma(*out.right, curve_sigma("right"));
    report_left_out(*out.right, "right");
  }
  if (histories.count("left")) {
    out.left = extract(histories["left"]);
    if (!out.left) return false;
    AddCurveSigma(*out.left, curve_sigma("left"));
    report_left_out(*out.left, "left");
  }
  // Gaps up to a tenth of a half swing (18 degrees of phase) are bridged: a
  // cubic carries the swing across one to a millionth of its amplitude.
  const double max_bridge_s = 0.1 * HalfPeriod(pendulum, 0.0);
  const DisplacementHistory average =
      histories.size() == 2 ? AverageHistories(histories["right"], histories["left"], max_bridge_s)
                            : histories.begin()->second;
  // Bars drawn in alternate chopper slots longer than a bridge have no time
  // both can be read at: the mean of the bars' own maxima then stands alone.
  const bool averaged = histories.size() == 1 || average.time_s.size() >= kMinHistorySamples;
  BarRebounds from_average;
  if (averaged) {
    std::optional<BarRebounds> extracted = extract(average);
    if (!extracted) return false;
    from_average = std::move(*extracted);
  }
  if (histories.size() == 2) {
    // The average of the two histories reads through both curves.
    AddCurveSigma(from_average, [&](double x) {
      return 0.5 * std::hypot(shared_sigma_at("right", x), shared_sigma_at("left", x));
    });
  } else {
    AddCurveSigma(from_average, curve_sigma(histories.begin()->first.c_str()));
  }
  const BarRebounds both = histories.size() == 2
                               ? MeanOfBars(*out.right, *out.left, from_average,
                                            {run.initial_displacement, run.first_rebound})
                               : GapFree(std::move(from_average));
  if (both.xmax.size() < 2) {
    std::optional<BarDisagreement> disagreement;
    if (histories.size() == 2) {
      disagreement = FirstDisagreement(*out.right, *out.left);
      if (!disagreement) disagreement = AverageSlip(*out.right, *out.left, from_average);
      if (!disagreement) disagreement = OffTheClock(*out.right, *out.left, both.xmax.size());
    }
    return Stopped(result,
                   {{session.manifest, RunKey(run), std::nullopt},
                    fmt::format("only {} rebound(s) from rebound 0 (first_rebound = {}) are "
                                "complete in the traces ({}{}); at least 2 are needed",
                                both.xmax.size(), run.first_rebound, ReboundsShown(out),
                                disagreement ? "; " + disagreement->why : "")});
  }
  const std::size_t stride = std::max<std::size_t>(1, average.time_s.size() / 4000);
  for (std::size_t i = 0; i < average.time_s.size(); i += stride) {
    out.measured_displacement.time_s.push_back(average.time_s[i]);
    out.measured_displacement.value.push_back(average.displacement[i]);
  }
  out.xmax = both.xmax;
  out.xmax_sigma = both.xmax_sigma;
  out.t_peak = both.t_peak;
  out.t_peak_sigma = both.t_peak_sigma;
  out.rebound_duration = both.duration;
  out.rebound_duration_sigma = both.duration_sigma;
  out.release = both.release;

  if (const auto contact = run.traces.find("contact"); contact != run.traces.end()) {
    // Only the contact time needs the contact trace: one that cannot be read
    // fails alone, the maxima standing without a contact time (the results
    // then hold none, as for a run without a contact trace), and a warning
    // names its file, key and why.
    if (std::optional<StepFailure> lost =
            MeasureContactTime(run, session, contact->second, photo, trace_of, span_failure, out)) {
      result.warnings.push_back(
          fmt::format("{}: {}; the run's maxima are kept without its contact time",
                      FormatLocation(lost->at), lost->reason));
    }
  }
  result.ok = true;
  return true;
}

}  // namespace

std::string RunFailureReason(const std::exception_ptr& error, const Session& session,
                             const Run& run) {
  try {
    std::rethrow_exception(error);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return fmt::format("{}: {}: {}", session.manifest.string(), RunKey(run), e.what());
  }
}

MeasuredTraceRun MeasureTraceRun(const Run& run, const Session& session, const Pendulum& pendulum,
                                 const StageOptions& options, CalibrationCache& calibrations) {
  MeasuredTraceRun result;
  try {
    MeasureInto(run, session, pendulum, options, calibrations, result);
  } catch (const InputError& error) {
    // A file that cannot be read (a CSV trace, the photo): the run's failure,
    // what was measured before it kept.
    Stopped(result, {error.where(), error.problem()});
  }
  return result;
}

}  // namespace impactlab
