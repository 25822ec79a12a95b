#include "multibody/two_link_simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "model/ode_integrator.h"
#include "multibody/two_link_dynamics.h"
#include "multibody/two_link_kinematics.h"
#include "multibody/two_link_state.h"

namespace impactlab {
namespace {

using Integrator = OdeIntegrator<2 * kTwoLinkCoordinates>;
using State = Integrator::State;

// The tip strikes when it is this far into the surface: a separated tip
// starts at gap 0 (the loop closure's), and rounding alone must not strike it
// again at once (Zeno chatter at one instant).
constexpr double kContactTolerance = 1e-12;  // m

// The model's fastest rate, 1/s, and what sets it: what makes an explicit
// integrator's steps small. Each candidate's rate from its closed form.
struct Rate {
  double per_s = 0.0;
  std::string what;
  std::string Describe() const {
    return fmt::format("the fastest rate in the model is {}, {:.3g} /s", what, per_s);
  }
};

Rate FastestRate(const TwoLinkParameters& p) {
  std::vector<std::pair<double, std::string>> rates;
  auto beam = [&](const char* name, const TwoLinkBeam& b) {
    const double length4 = std::pow(b.length_m, 4);
    rates.push_back(
        {3.516 * std::sqrt(b.flexural_rigidity_n_m2 / (b.mass_per_length_kg_per_m * length4)),
         fmt::format("[{}] bending (flexural_rigidity_n_m2 = {:g})", name,
                     b.flexural_rigidity_n_m2)});
    rates.push_back(
        {b.damping_n_s_per_m2 / b.mass_per_length_kg_per_m,
         fmt::format("[{}] damping (damping_n_s_per_m2 = {:g})", name, b.damping_n_s_per_m2)});
  };
  auto drive = [&](const char* name, const TwoLinkDrive& d) {
    const double n2 = d.gear_ratio * d.gear_ratio;
    rates.push_back({n2 * d.torque_constant_n_m_per_a * d.back_emf_v_s_per_rad /
                         (d.armature_resistance_ohm * d.equivalent_inertia_kg_m2),
                     fmt::format("[{}] back-EMF braking n^2 K_t K_b / (R J_eq) (gear_ratio = {:g})",
                                 name, d.gear_ratio)});
    rates.push_back({std::sqrt(d.mesh_stiffness_n_m_per_rad / d.equivalent_inertia_kg_m2),
                     fmt::format("[{}] gear mesh (mesh_stiffness_n_m_per_rad = {:g})", name,
                                 d.mesh_stiffness_n_m_per_rad)});
    rates.push_back(
        {(d.mesh_damping_n_m_s + d.equivalent_damping_n_m_s) / d.equivalent_inertia_kg_m2,
         fmt::format("[{}] damping (mesh_damping_n_m_s = {:g}, "
                     "equivalent_damping_n_m_s = {:g})",
                     name, d.mesh_damping_n_m_s, d.equivalent_damping_n_m_s)});
  };
  beam("beam1", p.beam1);
  beam("beam2", p.beam2);
  drive("drive_a", p.drive_a);
  drive("drive_b", p.drive_b);
  const auto fastest = std::max_element(rates.begin(), rates.end());
  return {fastest->first, fastest->second};
}

// Dormand-Prince is stable for steps up to about 3.3 / |s| at a real or
// lightly damped pole s.
constexpr double kStableStepTimesRate = 3.3;

// The regime the integrator is in.
struct Regime {
  bool constrained = false;
  int dependent = kLink2Angle;
};

class Simulation {
 public:
  Simulation(const TwoLinkModel& model, const TwoLinkCase& experiment,
             const TwoLinkSimulationOptions& options)
      : model_(model),
        case_(experiment),
        options_(options),
        rate_(options.sample_rate_hz > 0.0 ? options.sample_rate_hz
                                           : model.parameters().sensors.sample_rate_hz),
        end_(options.duration_s > 0.0 ? options.duration_s : experiment.duration_s),
        integrator_({options.relative_tolerance, options.absolute_tolerance, options.max_step_s}),
        step_budget_(options.max_steps > 0 ? options.max_steps
                                           : 50000 + static_cast<long>(40000.0 * end_)),
        wall_budget_s_(options.max_wall_seconds > 0.0 ? options.max_wall_seconds
                                                      : 2.0 + 0.5 * end_),
        started_(std::chrono::steady_clock::now()) {}

  // The motion to its end, or to where the model refuses it, the reason
  // naming the time and the cause and the samples kept up to the last whole
  // one. Simulate returns the refusals of the stepping (a start inside the
  // surface, a budget, a step the integrator cannot take, a non-finite state,
  // a beam beyond the small-deflection model, chatter) as that record; only
  // the dynamics' own refusals deep inside a step (a jam in an impact, a loop
  // closure that fails, a mass matrix that loses its definiteness in the
  // integrator's right-hand side) unwind to here as std::domain_error.
  TwoLinkRecord Run();

 private:
  TwoLinkRecord Simulate();
  TwoLinkRecord Refused(const std::string& reason);
  DriveVoltages Voltages(double t, const TwoLinkVector& q) const {
    return CaseVoltages(model_, case_, t, q(kGearboxAAngle), q(kGearboxBAngle));
  }
  Integrator::System SystemFor(const Regime& regime);
  void Emit(double up_to_s, const Regime& regime);
  void Sample(double t, const State& y, const Regime& regime);
  // After every accepted step: why the motion cannot go on (none: it can).
  std::optional<std::string> CheckStep(const Regime& regime);
  double Energy(const TwoLinkVector& q, const TwoLinkVector& v) const {
    return model_.KineticEnergy(q, v) + model_.PotentialEnergy(q);
  }
  // Adds the work of the non-potential forces over [t0, t1] within the last
  // step to the ledger.
  void AddWork(double t0, double t1, const Regime& regime);
  double NormalForce(double t, const State& y) const {
    TwoLinkVector q, v;
    SplitState(y, &q, &v);
    return ConstrainedMotion(model_, q, v, Voltages(t, q)).normal_force_n;
  }

  const TwoLinkModel& model_;
  const TwoLinkCase& case_;
  const TwoLinkSimulationOptions& options_;
  const double rate_;
  const double end_;
  Integrator integrator_;
  const long step_budget_;
  const double wall_budget_s_;
  const std::chrono::steady_clock::time_point started_;
  bool warned_deflection_ = false;
  TwoLinkRecord record_;
  long next_sample_ = 0;
  std::array<Eigen::Vector2d, kTwoLinkAccelerometers> last_velocity_{};
  std::array<double, kTwoLinkAccelerometers> last_axis_{};
};

Integrator::System Simulation::SystemFor(const Regime& regime) {
  return [this, regime](const State& y, State& dydt, double t) {
    ++record_.rhs_evaluations;
    TwoLinkVector q, v;
    SplitState(y, &q, &v);
    const DriveVoltages voltages = Voltages(t, q);
    const TwoLinkVector a = regime.constrained
                                ? ConstrainedMotion(model_, q, v, voltages).acceleration
                                : FreeAcceleration(model_, q, v, voltages);
    dydt = JoinState(v, a);
  };
}

void Simulation::AddWork(double t0, double t1, const Regime& regime) {
  // Three-point Gauss-Legendre on the step's dense output: exact for the
  // power's polynomial degree 5 and below, beyond the interpolant's order.
  static constexpr double kNodes[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
  static constexpr double kWeights[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  const double half = 0.5 * (t1 - t0), mid = 0.5 * (t0 + t1);
  if (!(half > 0.0)) return;
  for (int i = 0; i < 3; ++i) {
    const double t = mid + half * kNodes[i];
    TwoLinkVector q, v;
    SplitState(integrator_.Interpolate(t), &q, &v);
    const DriveVoltages voltages = Voltages(t, q);
    // The conservative part of the applied forces is what they are at rest
    // with the motors off (the beams' and meshes' elastic forces).
    const TwoLinkVector non_potential =
        model_.AppliedForces(q, v, voltages) -
        model_.AppliedForces(q, TwoLinkVector::Zero(), DriveVoltages{});
    record_.energy.drives_and_damping_j += kWeights[i] * half * v.dot(non_potential);
    if (regime.constrained) {
      const ConstrainedAcceleration c = ConstrainedMotion(model_, q, v, voltages);
      const PointMotion tip = model_.Tip(q, v);
      const double power = c.normal_force_n * tip.jacobian.row(0).dot(v) +
                           c.friction_force_n * tip.jacobian.row(1).dot(v);
      record_.energy.surface_j += kWeights[i] * half * power;
    }
  }
}

// Why a motion needs more steps than its budget: the model's stiffness, or,
// where the steps are far below the stability limit, the motion itself.
std::string WhyTooManySteps(const Rate& fastest, double t, long steps, std::size_t events) {
  const double stable_step = kStableStepTimesRate / fastest.per_s;
  const double mean_step = t / static_cast<double>(std::max(1L, steps));
  if (mean_step < 0.1 * stable_step) {
    return fmt::format(
        "its steps average {:.3g} s, far below the {:.3g} s that stiffness allows ({}): the "
        "motion itself needs them ({} impacts and separations so far)",
        mean_step, stable_step, fastest.Describe(), events);
  }
  return fmt::format("too stiff for the explicit integrator: {}", fastest.Describe());
}

// After every accepted step: the budgets, the state's finiteness and the
// small-deflection model's reach, each refused with its cause.
std::optional<std::string> Simulation::CheckStep(const Regime& regime) {
  const double t = integrator_.time();
  const char* motion = regime.constrained ? "constrained" : "free";
  ++record_.steps;
  if (record_.steps > step_budget_) {
    return fmt::format(
        "two-link, {} motion: more than {} integration steps by t = {:.6f} s: {}", motion,
        step_budget_, t,
        WhyTooManySteps(FastestRate(model_.parameters()), t, record_.steps, record_.events.size()));
  }
  if (record_.steps % 64 == 0) {
    const double spent =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    if (spent > wall_budget_s_) {
      return fmt::format(
          "two-link, {} motion: {:.1f} s of computing reached only t = {:.6f} s of {:g} s "
          "(limit {:.1f} s): {}",
          motion, spent, t, end_, wall_budget_s_,
          WhyTooManySteps(FastestRate(model_.parameters()), t, record_.steps,
                          record_.events.size()));
    }
  }
  TwoLinkVector q, v;
  SplitState(integrator_.state(), &q, &v);
  if (!q.allFinite() || !v.allFinite()) {
    return fmt::format(
        "two-link, {} motion: the state is not finite at t = {:.6f} s (parameters beyond the "
        "model's range; {})",
        motion, t, FastestRate(model_.parameters()).Describe());
  }
  const TwoLinkParameters& p = model_.parameters();
  const std::pair<const char*, double> deflections[] = {
      {"beam1", std::abs(q(kBeam1Deflection)) / p.beam1.length_m},
      {"beam2", std::abs(q(kBeam2Deflection)) / p.beam2.length_m}};
  for (const auto& [beam, ratio] : deflections) {
    record_.max_deflection_ratio = std::max(record_.max_deflection_ratio, ratio);
    const TwoLinkBeam& b = std::string_view(beam) == "beam1" ? p.beam1 : p.beam2;
    if (ratio > options_.max_deflection_ratio) {
      return fmt::format(
          "two-link: [{}]'s tip deflects {:.3g} m on a {:g} m beam at t = {:.6f} s, beyond the "
          "small-deflection model (limit {:g} of its length): flexural_rigidity_n_m2 = {:g} is "
          "too low for the loads",
          beam, ratio * b.length_m, b.length_m, t, options_.max_deflection_ratio,
          b.flexural_rigidity_n_m2);
    }
    if (ratio > options_.warn_deflection_ratio && !warned_deflection_) {
      warned_deflection_ = true;
      record_.warnings.push_back(fmt::format(
          "[{}]'s tip deflects {:.3g} m on a {:g} m beam at t = {:.6f} s: more than {:g} of "
          "its length, where the model's linear deflections lose accuracy "
          "(flexural_rigidity_n_m2 = {:g})",
          beam, ratio * b.length_m, b.length_m, t, options_.warn_deflection_ratio,
          b.flexural_rigidity_n_m2));
    }
  }
  return std::nullopt;
}

void Simulation::Sample(double t, const State& y, const Regime& regime) {
  TwoLinkVector q, v;
  SplitState(y, &q, &v);
  if (regime.constrained) {
    CloseLoop(model_, regime.dependent, &q, &v);
    record_.max_loop_closure_m = std::max(record_.max_loop_closure_m, std::abs(model_.Gap(q)));
  }
  const double dt = 1.0 / rate_;
  record_.energy.peak_kinetic_j =
      std::max(record_.energy.peak_kinetic_j, model_.KineticEnergy(q, v));
  record_.time_s.push_back(t);
  record_.gearbox_a_rad.push_back(q(kGearboxAAngle));
  record_.gearbox_b_rad.push_back(q(kGearboxBAngle));
  for (int s = 0; s < kTwoLinkAccelerometers; ++s) {
    const auto sensor = static_cast<TwoLinkSensor>(s);
    const Eigen::Vector2d velocity = model_.Sensor(sensor, q, v).jacobian * v;
    const double axis = model_.SensorAxisAngle(sensor, q);
    double mean_acceleration = 0.0;
    if (next_sample_ > 0) {
      const double mid = 0.5 * (axis + last_axis_[s]);
      mean_acceleration =
          Eigen::Vector2d(std::cos(mid), std::sin(mid)).dot(velocity - last_velocity_[s]) / dt;
    }
    record_.acceleration_m_s2[s].push_back(mean_acceleration);
    last_velocity_[s] = velocity;
    last_axis_[s] = axis;
  }
  if (options_.keep_state) {
    const DriveVoltages voltages = Voltages(t, q);
    const PointMotion tip = model_.Tip(q, v);
    record_.position.push_back(q);
    record_.velocity.push_back(v);
    record_.in_contact.push_back(regime.constrained ? 1 : 0);
    double normal = 0.0, friction = 0.0;
    if (regime.constrained) {
      const ConstrainedAcceleration c = ConstrainedMotion(model_, q, v, voltages);
      normal = c.normal_force_n;
      friction = c.friction_force_n;
    }
    record_.normal_force_n.push_back(normal);
    record_.friction_force_n.push_back(friction);
    record_.tip_x_m.push_back(tip.position.x());
    record_.tip_y_m.push_back(tip.position.y());
    record_.voltage_a_v.push_back(voltages.a_v);
    record_.voltage_b_v.push_back(voltages.b_v);
  }
  ++next_sample_;
}

void Simulation::Emit(double up_to_s, const Regime& regime) {
  for (;;) {
    const double t = static_cast<double>(next_sample_) / rate_;
    if (t > up_to_s || t > end_) return;
    Sample(t, integrator_.Interpolate(t), regime);
  }
}

TwoLinkRecord Simulation::Run() {
  try {
    return Simulate();
  } catch (const std::domain_error& e) {
    return Refused(e.what());
  }
}

TwoLinkRecord Simulation::Refused(const std::string& reason) {
  record_.ok = false;
  record_.reason = reason;
  // A refusal inside a sample leaves its channels unequal: keep whole samples.
  std::size_t n = record_.time_s.size();
  const auto shortest = [&n](const auto& channel) { n = std::min(n, channel.size()); };
  shortest(record_.gearbox_a_rad), shortest(record_.gearbox_b_rad);
  for (const std::vector<double>& a : record_.acceleration_m_s2) shortest(a);
  if (options_.keep_state) {
    shortest(record_.position), shortest(record_.velocity), shortest(record_.in_contact);
    shortest(record_.normal_force_n), shortest(record_.friction_force_n);
    shortest(record_.tip_x_m), shortest(record_.tip_y_m);
    shortest(record_.voltage_a_v), shortest(record_.voltage_b_v);
  }
  const auto trim = [n](auto& channel) {
    if (channel.size() > n) channel.resize(n);
  };
  trim(record_.time_s), trim(record_.gearbox_a_rad), trim(record_.gearbox_b_rad);
  for (std::vector<double>& a : record_.acceleration_m_s2) trim(a);
  trim(record_.position), trim(record_.velocity), trim(record_.in_contact);
  trim(record_.normal_force_n), trim(record_.friction_force_n);
  trim(record_.tip_x_m), trim(record_.tip_y_m);
  trim(record_.voltage_a_v), trim(record_.voltage_b_v);
  return std::move(record_);
}

TwoLinkRecord Simulation::Simulate() {
  TwoLinkVector q = TwoLinkVector::Zero(), v = TwoLinkVector::Zero();
  q(kLink1Angle) = q(kGearboxAAngle) = case_.q1_rad;
  q(kLink2Angle) = q(kGearboxBAngle) = case_.q4_rad;
  if (!(model_.Gap(q) > 0.0)) {
    return Refused(
        fmt::format("two-link: the tool's tip starts {:.4g} m inside the surface", -model_.Gap(q)));
  }
  // The explicit integrator's steps cannot exceed its stability limit at the
  // model's fastest rate: a motion that would need more steps than the budget
  // is refused before it starts.
  const Rate fastest = FastestRate(model_.parameters());
  const double stable_step = kStableStepTimesRate / fastest.per_s;
  if (end_ / stable_step > static_cast<double>(step_budget_)) {
    return Refused(fmt::format(
        "two-link: too stiff for the explicit integrator: {}, so steps of at most {:.3g} s, "
        "about {:.3g} of them for {:g} s, more than the budget of {}",
        fastest.Describe(), stable_step, end_ / stable_step, end_, step_budget_));
  }
  Regime regime;
  double t = 0.0;
  State y = JoinState(q, v);
  record_.energy.initial_j = Energy(q, v);
  double first_step = std::min(1e-4, stable_step);
  while (t < end_) {
    const double limit = t < case_.start_delay_s ? std::min(case_.start_delay_s, end_) : end_;
    integrator_.Reset(SystemFor(regime), y, t, first_step);
    if (next_sample_ == 0) Sample(0.0, y, regime);
    bool switched = false;
    // (a phase within 1e-12 s of its limit has reached it: no step that short)
    const double reached = limit - 1e-12 * std::max(1.0, limit);
    while (!switched && integrator_.time() < reached) {
      OdeStepResult step;
      try {
        step = integrator_.Step(limit);
      } catch (const std::domain_error& e) {
        // The right-hand side's own refusal on a trial step (a mass matrix
        // that loses its definiteness), said like the integrator's.
        step = {false, e.what()};
      }
      if (!step.ok) {
        // A step size that collapses, a state that leaves the finite numbers
        // or a mass matrix that loses its definiteness on a trial step: a
        // motion beyond what the model's parameters allow.
        return Refused(fmt::format("two-link, {} motion at t = {:.6f} s: {} ({})",
                                   regime.constrained ? "constrained" : "free", integrator_.time(),
                                   step.reason, fastest.Describe()));
      }
      if (std::optional<std::string> why = CheckStep(regime)) return Refused(*why);
      const double t_lo = integrator_.previous_time(), t_hi = integrator_.time();
      const State& y_lo = integrator_.previous_state();
      const State& y_hi = integrator_.state();
      // Event: the gap closing in free flight, the normal force vanishing in
      // constrained motion.
      auto event = [&](const State& s) {
        if (!regime.constrained) {
          TwoLinkVector qs, vs;
          SplitState(s, &qs, &vs);
          return model_.Gap(qs) + kContactTolerance;
        }
        return NormalForce(t_lo, s);  // the drive law's time dependence is smooth
      };
      const double e_lo = event(y_lo), e_hi = event(y_hi);
      const bool crossed = e_hi <= 0.0 && (e_lo > 0.0 || !regime.constrained);
      if (!crossed) {
        Emit(t_hi, regime);
        AddWork(t_lo, t_hi, regime);
        if (regime.constrained) {
          SplitState(y_hi, &q, &v);
          const double before = Energy(q, v);
          CloseLoop(model_, regime.dependent, &q, &v);
          record_.energy.projections_j += Energy(q, v) - before;
          integrator_.ReplaceState(JoinState(q, v));
        }
        continue;
      }
      // (a tip already in, which the tolerance makes all but impossible, strikes at once)
      const double t_event = !regime.constrained && e_lo <= 0.0
                                 ? t_lo
                                 : integrator_.RefineRoot(event, e_lo, t_hi, e_hi);
      Emit(t_event, regime);
      AddWork(t_lo, t_event, regime);
      const State y_event = integrator_.Exact(t_event);
      SplitState(y_event, &q, &v);
      TwoLinkEvent record_event;
      record_event.time_s = t_event;
      if (!regime.constrained) {
        record_event.kind = "impact";
        record_event.impact = Impact(model_, q, v, options_.plastic_below_m_s);
        v = record_event.impact.velocity;
        record_.energy.impacts_j +=
            record_event.impact.normal_work_j + record_event.impact.friction_work_j;
        // A tip that rebounds (restitution) leaves; one brought to rest on
        // the surface stays where the surface must push it.
        const ImpactOutcome& impact = record_event.impact;
        const bool rebounds =
            impact.normal_velocity_after_m_s > 1e-9 * std::abs(impact.normal_velocity_before_m_s);
        regime.constrained =
            !rebounds && ConstrainedMotion(model_, q, v, Voltages(t_event, q)).normal_force_n > 0.0;
        if (regime.constrained) {
          regime.dependent = DependentCoordinate(model_, q);
          const double before = Energy(q, v);
          CloseLoop(model_, regime.dependent, &q, &v);
          record_.energy.projections_j += Energy(q, v) - before;
        }
      } else {
        record_event.kind = "separation";
        regime.constrained = false;
      }
      record_.events.push_back(record_event);
      if (static_cast<int>(record_.events.size()) > options_.max_events) {
        return Refused(
            fmt::format("two-link: more than {} impacts and separations by t = {:.6f} s (chatter)",
                        options_.max_events, t_event));
      }
      t = t_event;
      y = JoinState(q, v);
      first_step = std::max(1e-7, 0.1 * integrator_.suggested_step());
      switched = true;
    }
    if (!switched) {
      t = limit;
      y = integrator_.state();
      first_step = integrator_.suggested_step();
    }
  }
  SplitState(y, &q, &v);
  record_.energy.final_j = Energy(q, v);
  return std::move(record_);
}

}  // namespace

double TwoLinkRecord::FirstImpact() const {
  for (const TwoLinkEvent& e : events) {
    if (e.kind == "impact") return e.time_s;
  }
  return -1.0;
}

DriveVoltages CaseVoltages(const TwoLinkModel& model, const TwoLinkCase& experiment, double t_s,
                           double gearbox_a_rad, double gearbox_b_rad) {
  if (t_s < experiment.start_delay_s) return {};
  if (!experiment.sanding) return {experiment.voltage_a_v, experiment.voltage_b_v};
  const TwoLinkSanding& law = model.parameters().sanding;
  const double phase = 2.0 * M_PI * (t_s - experiment.start_delay_s) / law.period_s;
  const Eigen::Vector2d target(-model.parameters().surface.distance_m - law.press_depth_m,
                               law.centre_y_m + law.amplitude_m * std::sin(phase));
  const JointAngles command = RigidInverseKinematics(model.parameters(), target, gearbox_b_rad);
  auto clip = [&](double volts) {
    return std::clamp(volts, -law.max_voltage_v, law.max_voltage_v);
  };
  return {clip(law.gain_v_per_rad * (command.q1_rad - gearbox_a_rad)),
          clip(law.gain_v_per_rad * (command.q4_rad - gearbox_b_rad))};
}

TwoLinkRecord SimulateTwoLink(const TwoLinkModel& model, const TwoLinkCase& experiment,
                              const TwoLinkSimulationOptions& options) {
  if (!(options.relative_tolerance > 0.0) || !(options.absolute_tolerance > 0.0) ||
      !(options.max_step_s > 0.0) || options.sample_rate_hz < 0.0 || options.duration_s < 0.0) {
    throw std::invalid_argument("two-link simulation: tolerances and steps must be positive");
  }
  const double rate = options.sample_rate_hz > 0.0 ? options.sample_rate_hz
                                                   : model.parameters().sensors.sample_rate_hz;
  const double duration = options.duration_s > 0.0 ? options.duration_s : experiment.duration_s;
  if (!(rate * duration <= kTwoLinkMaxSamples)) {
    throw std::invalid_argument(fmt::format(
        "two-link: {:g} Hz for {:g} s is {:.3g} samples, over the limit of {:g} per case (the "
        "sample rate and the case's duration)",
        rate, duration, rate * duration, kTwoLinkMaxSamples));
  }
  Simulation simulation(model, experiment, options);
  return simulation.Run();
}

}  // namespace impactlab
