#include "pipeline/reduce.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include <fmt/chrono.h>
#include <fmt/format.h>

#include "io/errors.h"
#include "model/kelvin_voigt.h"
#include "pipeline/trace_run.h"

namespace impactlab {
namespace {

std::string NowIso8601() {
  const auto now = std::chrono::system_clock::now();
  return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}",
                     fmt::gmtime(std::chrono::system_clock::to_time_t(now)));
}

// Times of the model's maxima since release, for a run whose maxima were typed
// in: a quarter swing from X0, then per impact tau_c and a swing of the model's
// amplitude (exact pendulum: durations depend on amplitude).
std::vector<double> ModelPeakTimes(const Pendulum& pendulum, const RunResult& run,
                                   const KelvinVoigtTwoPointFit& fit) {
  const int a = fit.rebounds_used[0];
  const double xa = run.xmax[a];
  const double tau_c = fit.contact_time.value_or(0.0);
  const double log_e = fit.log_restitution.value;
  double t = 0.5 * HalfPeriod(pendulum, run.initial_displacement);
  std::vector<double> peaks;
  const int last = static_cast<int>(run.xmax.size()) - 1;
  // PENDUL rebound N (N >= 1) is session rebound N - first_rebound.
  for (int n = 1 - run.first_rebound; n <= last; ++n) {
    const double duration = HalfPeriod(pendulum, PredictMaximum(pendulum, xa, a, n, log_e));
    t += tau_c;
    if (n >= 0) peaks.push_back(t + 0.5 * duration);
    t += duration;
  }
  return peaks;
}

void MeasureTypedRun(const Run& run, RunResult& out) {
  out.source = "typed-in";
  out.xmax = run.rebounds;
  out.xmax_sigma.assign(run.rebounds.size(), run.rebound_uncertainty.value_or(0.0));
  if (run.contact_time) {
    out.contact_time = run.contact_time;
    out.contact_time_sigma = run.contact_time_uncertainty.value_or(0.0);
    out.contact_time_source = "typed-in";
  }
}

// The closed-form Kelvin-Voigt fit of a measured run, and Table 2's deviations.
void FitRun(const Run& run, const Session& session, const Pendulum& pendulum, Separation separation,
            RunResult& out) {
  // The session's one contact time, when given, is the thesis's procedure
  // (Table 3): it replaces each run's own.
  if (session.reduction.contact_time) {
    out.contact_time = session.reduction.contact_time;
    out.contact_time_sigma = 0.0;
    out.contact_time_source = "session";
  }
  ReboundMeasurements measured{out.xmax, out.xmax_sigma, out.contact_time, out.contact_time_sigma};
  TwoPointOptions options;
  options.rebounds = run.fit_rebounds;
  options.separation = separation;
  if (options.rebounds[1] >= static_cast<int>(out.xmax.size())) {
    throw std::invalid_argument(
        fmt::format("fit_rebounds = [{}, {}] but only rebounds 0 .. {} were measured",
                    options.rebounds[0], options.rebounds[1], out.xmax.size() - 1));
  }
  KelvinVoigtTwoPointFit fit =
      FitKelvinVoigtTwoPoint(pendulum, session.apparatus->mass, measured, options);
  if (!fit.ok) {
    out.failure = fit.diagnostic;
    out.kelvin_voigt = std::move(fit);
    return;
  }
  for (std::size_t n = 0; n < out.xmax.size(); ++n) {
    const double deviation = fit.predicted_xmax[n].value - out.xmax[n];
    out.deviation.push_back(deviation);
    out.deviation_pct_peak.push_back(100.0 * deviation / out.xmax[n]);
    out.deviation_pct_x0.push_back(100.0 * deviation / out.initial_displacement);
  }
  if (out.t_peak.empty()) {
    out.t_peak = ModelPeakTimes(pendulum, out, fit);
    out.t_peak_source = "model";
  }
  out.stiffness_source = "run";
  out.kelvin_voigt = std::move(fit);
  out.ok = true;
}

RunResult ReduceRun(const Run& run, const Session& session, const Pendulum& pendulum,
                    Separation separation, CalibrationCache& calibrations) {
  RunResult out;
  out.id = run.id;
  out.initial_displacement = run.initial_displacement;
  out.first_rebound = run.first_rebound;
  if (run.HasTypedRebounds()) {
    MeasureTypedRun(run, out);
  } else {
    MeasureTraceRun(run, session, pendulum, calibrations, out);
  }
  FitRun(run, session, pendulum, separation, out);
  return out;
}

// The thesis's design expedient: one K (the runs' mean) for every run, C from it.
void ApplyAverageStiffness(SessionResult& result, double mass) {
  std::vector<double> stiffness;
  double variance_sum = 0.0;
  for (const RunResult& run : result.runs) {
    if (run.ok && run.kelvin_voigt->stiffness) {
      stiffness.push_back(run.kelvin_voigt->stiffness->value);
      variance_sum += std::pow(run.kelvin_voigt->stiffness->sigma, 2);
    }
  }
  if (stiffness.empty()) return;
  const double average = SpreadOf(stiffness).average;
  const double average_sigma = std::sqrt(variance_sum) / static_cast<double>(stiffness.size());
  for (RunResult& run : result.runs) {
    if (!run.ok || !run.kelvin_voigt->stiffness) continue;
    KelvinVoigtTwoPointFit& fit = *run.kelvin_voigt;
    const double zeta = fit.damping_ratio.value;
    const double damping = 2.0 * zeta * std::sqrt(average * mass);
    const double damping_sigma =
        damping *
        std::hypot(fit.damping_ratio.sigma / std::max(zeta, 1e-300), 0.5 * average_sigma / average);
    fit.stiffness = Estimate{average, average_sigma};
    fit.damping = Estimate{damping, damping_sigma};
    run.stiffness_source = "session average";
  }
}

std::optional<SessionKelvinVoigt> AnalyseAcrossRuns(const SessionResult& result,
                                                    bool average_stiffness,
                                                    const std::vector<double>& own_stiffness) {
  SessionKelvinVoigt out;
  out.average_stiffness = average_stiffness;
  for (std::size_t i = 0; i < result.runs.size(); ++i) {
    const RunResult& run = result.runs[i];
    if (!run.ok || !run.kelvin_voigt->stiffness) continue;
    out.run_ids.push_back(run.id);
    out.sqrt_restitution.push_back(std::sqrt(run.kelvin_voigt->restitution.value));
    out.stiffness.push_back(own_stiffness[i]);
    out.damping.push_back(run.kelvin_voigt->damping->value);
  }
  if (out.run_ids.empty()) return std::nullopt;
  out.spread = SpreadOf(out.stiffness);
  if (out.run_ids.size() >= 2) {
    try {
      out.damping_line = FitDampingLine(out.sqrt_restitution, out.damping);
    } catch (const std::invalid_argument&) {
      // Runs of equal restitution: no line, the table stands without it.
    }
  }
  return out;
}

}  // namespace

SessionResult ReduceSession(const Session& session, const ReduceOptions& options) {
  SessionResult result;
  result.title = session.title;
  result.units = session.units;
  result.producer = options.producer;
  result.created = NowIso8601();
  result.session_folder = session.folder.string();
  result.convention = options.convention.value_or(ParseConvention(session.reduction.convention));
  result.separation = options.separation.value_or(ParseSeparation(session.reduction.separation));
  result.session_contact_time = session.reduction.contact_time;
  if (session.runs.empty()) return result;
  if (!session.apparatus) {
    throw std::invalid_argument(fmt::format("{}: [apparatus] is required when the session has runs",
                                            session.manifest.string()));
  }
  result.apparatus = *session.apparatus;
  const Pendulum pendulum{session.apparatus->pendulum_length, session.apparatus->gravity,
                          result.convention};

  CalibrationCache calibrations(session, pendulum);
  for (const Run& run : session.runs) {
    try {
      result.runs.push_back(ReduceRun(run, session, pendulum, result.separation, calibrations));
    } catch (const std::exception& error) {
      RunResult failed;
      failed.id = run.id;
      failed.initial_displacement = run.initial_displacement;
      failed.first_rebound = run.first_rebound;
      // An InputError names its own file and key; anything else gets the run's.
      failed.failure =
          dynamic_cast<const InputError*>(&error) != nullptr
              ? error.what()
              : fmt::format("{}: run \"{}\": {}", session.manifest.string(), run.id, error.what());
      result.runs.push_back(std::move(failed));
    }
  }

  std::vector<double> own_stiffness;
  for (const RunResult& run : result.runs) {
    own_stiffness.push_back(
        run.ok && run.kelvin_voigt->stiffness ? run.kelvin_voigt->stiffness->value : 0.0);
  }
  if (session.reduction.average_stiffness) ApplyAverageStiffness(result, session.apparatus->mass);
  result.kelvin_voigt =
      AnalyseAcrossRuns(result, session.reduction.average_stiffness, own_stiffness);

  for (const Prediction& p : session.predictions) {
    const RunResult* source = result.FindRun(p.source_run);
    const RunResult* target = result.FindRun(p.target_run);
    try {
      if (source == nullptr || target == nullptr || !source->ok || !target->ok) {
        throw std::invalid_argument("both runs must reduce to a Kelvin-Voigt fit");
      }
      result.predictions.push_back(PredictRun(pendulum, source->id, *source->kelvin_voigt,
                                              target->id, target->xmax, *target->kelvin_voigt,
                                              p.start_rebound));
    } catch (const std::exception& error) {
      result.warnings.push_back(
          fmt::format("{}: prediction of run \"{}\" from run \"{}\" skipped: {}",
                      session.manifest.string(), p.target_run, p.source_run, error.what()));
    }
  }
  return result;
}

}  // namespace impactlab
