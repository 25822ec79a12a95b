// The run as a sequence of smooth phases (free flight, contact), each split at
// the known discontinuities of the forcing (releases, wire-sawtooth jumps).
// Events inside a phase (contact start/end, maxima) are located on the exact
// RK step from the last accepted point, not on samples or the interpolant.
#include "synth/experiment.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "synth/dynamics.h"
#include "synth/integrator.h"

namespace impactlab {
namespace {

using namespace synth_detail;
using std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();

// The three displacement traces whose maxima are reported.
enum ReportedTrace : int { kTraceRight = 0, kTraceLeft = 1, kTraceAverage = 2 };

struct PeakCandidate {
  double xmax = -kInf;
  double time_s = 0.0;
  bool refined = false;
};

class ExperimentSimulation {
 public:
  explicit ExperimentSimulation(const ExperimentOptions& options);
  ExperimentResult Finish() &&;
  // The run to its end, or to where it cannot go on: then the result is
  // !ok with the reason, holding what was simulated before.
  void Simulate();

 private:
  // Traces.
  double TraceX(const State& y, int trace) const;
  double TraceRate(const State& y, int trace) const;
  int TraceCount() const { return wall_ ? 1 : 3; }

  double NextBoundary(double t) const;
  void CrossBoundary(double t);
  void EmitSamples(double t_stop);
  void TrackPeaks(double t_hi, const State& y_hi);
  void CloseRebound(double end_time_s);
  State StartContact(double t, State y);
  State EndContact(double t, State y);
  double ContactTimescale() const;
  void Stop(std::string reason);

  const ExperimentOptions& o_;
  bool wall_ = false;
  ExperimentResult result_;
  Dynamics dyn_;
  Integrator integrator_;
  std::array<double, 2> release_time_s_{};
  long next_sample_ = 0;

  int rebound_ = 0;  // current rebound N (free) or the impact N + 1 in progress
  double rebound_start_s_ = 0.0;
  std::array<PeakCandidate, 3> best_{};
  double contact_start_s_ = 0.0;
  bool finished_ = false;
};

ExperimentSimulation::ExperimentSimulation(const ExperimentOptions& o)
    : o_(o),
      wall_(o.arrangement == Arrangement::kWall),
      integrator_({o.integration.relative_tolerance, o.integration.absolute_tolerance,
                   o.integration.max_step_s}) {
  result_.options = o;
  result_.right = {o.pendulum_length, o.mass, o.release_x_right, 0.0};
  if (!wall_) {
    result_.left = {o.pendulum_length * (1.0 + o.left_length_excess),
                    o.mass * (1.0 + o.left_mass_excess), o.release_x_left, o.left_release_delay_s};
  }
  dyn_.gravity = o.gravity;
  dyn_.bars[kRight] = {result_.right.length, result_.right.mass, true};
  dyn_.bars[kLeft] = {result_.left.length, result_.left.mass, !wall_};
  dyn_.elements = wall_ ? 1 : 2;
  if (o.contact_model == ContactModelKind::kKelvinVoigt) {
    dyn_.element = {false, o.kelvin_voigt.stiffness, 0.0, o.kelvin_voigt.damping};
  } else {
    dyn_.element = {true, o.poynting_thomson.stiffness_1, o.poynting_thomson.stiffness_2,
                    o.poynting_thomson.damping};
  }
  release_time_s_ = {0.0, wall_ ? kInf : o.left_release_delay_s};
}

double ExperimentSimulation::TraceX(const State& y, int trace) const {
  if (trace == kTraceAverage) {
    return 0.5 * (dyn_.Displacement(y, kRight) + dyn_.Displacement(y, kLeft));
  }
  return dyn_.Displacement(y, trace);
}

double ExperimentSimulation::TraceRate(const State& y, int trace) const {
  if (trace == kTraceAverage) return 0.5 * (dyn_.Velocity(y, kRight) + dyn_.Velocity(y, kLeft));
  return dyn_.Velocity(y, trace);
}

double ExperimentSimulation::ContactTimescale() const {
  // 1 / omega of the relative motion on the stiffest path (K1 + K2 per face).
  const double k = (dyn_.element.k1 + dyn_.element.k2) / dyn_.elements;
  const double mr = dyn_.bars[kRight].mass;
  const double ml = dyn_.bars[kLeft].mass;
  const double reduced_mass = wall_ ? mr : mr * ml / (mr + ml);
  return std::sqrt(reduced_mass / k);
}

double ExperimentSimulation::NextBoundary(double t) const {
  double next = kInf;
  for (double release : release_time_s_) {
    if (release > t) next = std::min(next, release);
  }
  for (const Sawtooth& s : dyn_.sawtooths) next = std::min(next, s.NextJumpTime());
  return next;
}

void ExperimentSimulation::CrossBoundary(double t) {
  for (int bar : {kRight, kLeft}) {
    if (release_time_s_[bar] <= t) dyn_.held[bar] = false;
  }
  for (Sawtooth& s : dyn_.sawtooths) {
    if (s.NextJumpTime() <= t) ++s.cycle;
  }
  // A decayed sawtooth no longer matters (e^-40 ~ 4e-18 of its amplitude).
  std::erase_if(dyn_.sawtooths,
                [t](const Sawtooth& s) { return s.decay_rate * (t - s.start_s) > 40.0; });
}

void ExperimentSimulation::EmitSamples(double t_stop) {
  SampledRun& out = result_.samples;
  for (;;) {
    const double t = static_cast<double>(next_sample_) / o_.sample_rate_hz;  // no drift
    if (t > t_stop) return;
    const State y = integrator_.Interpolate(t);
    out.time_s.push_back(t);
    out.x_right.push_back(dyn_.Displacement(y, kRight));
    if (!wall_) out.x_left.push_back(dyn_.Displacement(y, kLeft));
    out.in_contact.push_back(dyn_.in_contact ? 1 : 0);
    ++next_sample_;
  }
}

// Maxima of each trace inside [previous_time, t_hi]: the rate falls through 0.
void ExperimentSimulation::TrackPeaks(double t_hi, const State& y_hi) {
  const State& y_lo = integrator_.previous_state();
  for (int trace = 0; trace < TraceCount(); ++trace) {
    const double rate_lo = TraceRate(y_lo, trace);
    const double rate_hi = TraceRate(y_hi, trace);
    PeakCandidate& best = best_[trace];
    if (rate_lo > 0.0 && rate_hi <= 0.0) {
      const double t = integrator_.RefineRoot([&](const State& y) { return TraceRate(y, trace); },
                                              rate_lo, t_hi, rate_hi);
      const double x = TraceX(integrator_.Exact(t), trace);
      if (!best.refined || x > best.xmax) best = {x, t, true};
    } else if (!best.refined && TraceX(y_hi, trace) > best.xmax) {
      best = {TraceX(y_hi, trace), t_hi, false};  // fallback: a step end
    }
  }
}

void ExperimentSimulation::CloseRebound(double end_time_s) {
  std::array<std::vector<ReboundTruth>*, 3> lists = {
      &result_.rebounds_right, &result_.rebounds_left, &result_.rebounds_average};
  for (int trace = 0; trace < TraceCount(); ++trace) {
    ReboundTruth r;
    r.rebound = rebound_;
    r.end_time_s = end_time_s;
    if (rebound_ == 0) {
      // The release swing peaks where it starts: each bar at its release, the
      // average when the first bar leaves (the other is still held).
      const double t_first = std::min(release_time_s_[kRight], release_time_s_[kLeft]);
      if (trace == kTraceAverage) {
        r.start_time_s = t_first;
        r.xmax = 0.5 * (o_.release_x_right + o_.release_x_left);
        r.peak_time_s = t_first;
      } else {
        r.start_time_s = release_time_s_[trace];
        r.xmax = trace == kTraceRight ? o_.release_x_right : o_.release_x_left;
        r.peak_time_s = release_time_s_[trace];
      }
    } else {
      r.start_time_s = rebound_start_s_;
      r.xmax = best_[trace].xmax;
      r.peak_time_s = best_[trace].time_s;
    }
    r.duration_s = r.end_time_s - r.start_time_s;
    lists[trace]->push_back(r);
  }
  best_ = {};
}

State ExperimentSimulation::StartContact(double t, State y) {
  CloseRebound(t);
  if (rebound_ == o_.impact_count) {  // impact impact_count + 1 begins: the run is complete
    finished_ = true;
    result_.end_time_s = t;
    return y;
  }
  ImpactTruth impact;
  impact.impact = rebound_ + 1;
  impact.start_time_s = t;
  impact.approach_speed = dyn_.OverlapRate(y);
  impact.right_impact_speed = -dyn_.Velocity(y, kRight);
  impact.left_impact_speed = wall_ ? 0.0 : -dyn_.Velocity(y, kLeft);
  impact.energy_before = dyn_.MechanicalEnergy(y);
  result_.impacts.push_back(impact);

  if (o_.wires.enabled) {
    // Thesis eq. 101-104 for each bar, from its own approach speed.
    const SupportWireOptions& w = o_.wires;
    for (int bar : {kRight, kLeft}) {
      if (!dyn_.bars[bar].present) continue;
      const double weight = dyn_.bars[bar].mass * o_.gravity;
      const double tension = weight / (w.wires_per_bar * std::cos(w.inclination_rad));
      const double wave_speed = std::sqrt(tension / w.mass_per_length);
      const double chord = w.chord_length > 0.0
                               ? w.chord_length
                               : dyn_.bars[bar].length / std::cos(w.inclination_rad);
      const double approach = bar == kRight ? impact.right_impact_speed : impact.left_impact_speed;
      Sawtooth s;
      s.bar = bar;
      s.start_s = t;
      s.amplitude =
          w.wires_per_bar * (2.0 * approach / pi) * std::sqrt(w.mass_per_length * tension);
      s.omega = pi * wave_speed / chord;
      s.decay_rate = std::isfinite(w.decay_time_s) ? 1.0 / w.decay_time_s : 0.0;
      dyn_.sawtooths.push_back(s);
    }
  }
  y[4] = 0.0;  // the Poynting-Thomson node starts relaxed at each contact
  y[5] = 0.0;
  dyn_.in_contact = true;
  contact_start_s_ = t;
  return y;
}

State ExperimentSimulation::EndContact(double t, State y) {
  ImpactTruth& impact = result_.impacts.back();
  impact.end_time_s = t;
  impact.duration_s = t - impact.start_time_s;
  impact.separation_speed = -dyn_.OverlapRate(y);
  impact.restitution = impact.separation_speed / impact.approach_speed;
  impact.right_exit_speed = dyn_.Velocity(y, kRight);
  impact.left_exit_speed = wall_ ? 0.0 : dyn_.Velocity(y, kLeft);
  impact.energy_after = dyn_.MechanicalEnergy(y);
  impact.dissipated_energy = y[5];
  impact.residual_elastic = dyn_.ElasticEnergy(y);
  dyn_.in_contact = false;
  y[4] = 0.0;
  y[5] = 0.0;
  ++rebound_;
  rebound_start_s_ = t;
  return y;
}

void ExperimentSimulation::Stop(std::string reason) {
  result_.ok = false;
  result_.reason = std::move(reason);
  result_.integrator_steps = integrator_.accepted_steps();
}

void ExperimentSimulation::Simulate() {
  const double t_first = std::min(release_time_s_[kRight], release_time_s_[kLeft]);
  State y{};
  for (int bar : {kRight, kLeft}) {
    if (!dyn_.bars[bar].present) continue;
    const double x0 = bar == kRight ? o_.release_x_right : o_.release_x_left;
    y[2 * bar] = std::asin(x0 / dyn_.bars[bar].length);
    dyn_.held[bar] = release_time_s_[bar] > t_first;
  }
  next_sample_ = static_cast<long>(std::ceil(t_first * o_.sample_rate_hz));
  if (static_cast<double>(next_sample_) / o_.sample_rate_hz < t_first) ++next_sample_;

  // A free phase longer than a few full swings means the bars never meet.
  const double longest_length = std::max(dyn_.bars[kRight].length, dyn_.bars[kLeft].length);
  const double free_limit_s = 20.0 * pi * std::sqrt(longest_length / o_.gravity);
  const double contact_first_step_s = 1e-3 * ContactTimescale();
  double t = t_first;
  double phase_start_s = t;
  double first_step_s = 1e-5;

  while (!finished_) {
    const double boundary = NextBoundary(t);
    const double phase_limit = dyn_.in_contact
                                   ? contact_start_s_ + o_.integration.max_contact_time_s
                                   : phase_start_s + free_limit_s;
    const double limit = std::min(boundary, phase_limit);
    integrator_.Reset(std::cref(dyn_), y, t, first_step_s);
    for (;;) {
      if (const OdeStepResult step = integrator_.Step(limit); !step.ok) {
        return Stop(fmt::format("the run cannot be integrated on: {}", step.reason));
      }
      const State& y_lo = integrator_.previous_state();
      const State& y_hi = integrator_.state();
      const double t_hi = integrator_.time();
      std::optional<double> event;
      if (!dyn_.in_contact) {
        const double gap_lo = dyn_.Overlap(y_lo);
        const double gap_hi = dyn_.Overlap(y_hi);
        if (gap_lo < 0.0 && gap_hi >= 0.0) {
          event = integrator_.RefineRoot([this](const State& s) { return dyn_.Overlap(s); }, gap_lo,
                                         t_hi, gap_hi);
        }
        const double t_end = event.value_or(t_hi);
        TrackPeaks(t_end, event ? integrator_.Exact(t_end) : y_hi);
      } else {
        const bool kinematic = o_.separation == Separation::kKinematic;
        auto end_measure = [this, kinematic](const State& s) {
          return kinematic ? dyn_.Overlap(s) : dyn_.ContactForce(s);
        };
        const double lo = end_measure(y_lo);
        const double hi = end_measure(y_hi);
        if (lo > 0.0 && hi <= 0.0) event = integrator_.RefineRoot(end_measure, lo, t_hi, hi);
        const double t_end = event.value_or(t_hi);
        const State y_end = event ? integrator_.Exact(t_end) : y_hi;
        const double rate_lo = dyn_.OverlapRate(y_lo);
        const double rate_hi = dyn_.OverlapRate(y_end);
        if (rate_lo > 0.0 && rate_hi <= 0.0) {
          const double tp = integrator_.RefineRoot(
              [this](const State& s) { return dyn_.OverlapRate(s); }, rate_lo, t_end, rate_hi);
          result_.impacts.back().peak_overlap = dyn_.Overlap(integrator_.Exact(tp));
          result_.impacts.back().peak_overlap_time_s = tp;
        }
      }
      if (event) {
        EmitSamples(*event);
        y = integrator_.Exact(*event);
        t = *event;
        y = dyn_.in_contact ? EndContact(t, y) : StartContact(t, y);
        phase_start_s = t;
        // Contact needs tiny steps; leaving it, the controller grows them back.
        first_step_s = contact_first_step_s;
        break;
      }
      EmitSamples(t_hi);
      if (t_hi >= limit) {
        if (t_hi >= phase_limit && phase_limit < boundary) {
          if (dyn_.in_contact) {
            return Stop(fmt::format(
                "impact {} has not separated after {} s ({} separation, {} contact): the "
                "contact law never lets go under this convention",
                result_.impacts.back().impact, o_.integration.max_contact_time_s,
                SeparationName(o_.separation), ContactModelName(o_.contact_model)));
          }
          return Stop(
              fmt::format("no impact within {} s after t = {} s", free_limit_s, phase_start_s));
        }
        y = y_hi;
        t = t_hi;
        CrossBoundary(t);
        first_step_s = integrator_.suggested_step();
        break;
      }
    }
  }
  result_.integrator_steps = integrator_.accepted_steps();
}

ExperimentResult ExperimentSimulation::Finish() && { return std::move(result_); }

}  // namespace

ExperimentResult SimulateExperiment(const ExperimentOptions& options) {
  options.Check();
  ExperimentSimulation run(options);
  run.Simulate();
  return std::move(run).Finish();
}

SampledSwing SimulateFreeSwing(const FreeSwingOptions& o) {
  o.Check();
  Dynamics dyn;
  dyn.gravity = o.gravity;
  dyn.bars[kRight] = {o.pendulum_length, 1.0, true};
  dyn.bars[kLeft] = {0.0, 0.0, false};
  Integrator integrator({o.integration.relative_tolerance, o.integration.absolute_tolerance,
                         o.integration.max_step_s});
  State y{};
  y[0] = std::asin(o.release_x / o.pendulum_length);
  integrator.Reset(std::cref(dyn), y, 0.0, 1e-5);
  SampledSwing out;
  long k = 0;
  auto emit = [&](double t_stop) {
    for (double t = 0.0; (t = static_cast<double>(k) / o.sample_rate_hz) <= t_stop; ++k) {
      out.time_s.push_back(t);
      out.x.push_back(dyn.Displacement(integrator.Interpolate(t), kRight));
    }
  };
  emit(0.0);
  while (integrator.time() < o.duration_s) {
    if (const OdeStepResult step = integrator.Step(o.duration_s); !step.ok) {
      out.ok = false;
      out.reason = fmt::format("the free swing cannot be integrated on: {}", step.reason);
      return out;
    }
    emit(integrator.time());
  }
  return out;
}

}  // namespace impactlab
