#include "multibody/two_link_simulation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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
        integrator_({options.relative_tolerance, options.absolute_tolerance, options.max_step_s}) {}

  TwoLinkRecord Run();

 private:
  DriveVoltages Voltages(double t, const TwoLinkVector& q) const {
    return CaseVoltages(model_, case_, t, q(kGearboxAAngle), q(kGearboxBAngle));
  }
  Integrator::System SystemFor(const Regime& regime);
  void Emit(double up_to_s, const Regime& regime);
  void Sample(double t, const State& y, const Regime& regime);
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

void Simulation::Sample(double t, const State& y, const Regime& regime) {
  TwoLinkVector q, v;
  SplitState(y, &q, &v);
  if (regime.constrained) {
    CloseLoop(model_, regime.dependent, &q, &v);
    record_.max_loop_closure_m = std::max(record_.max_loop_closure_m, std::abs(model_.Gap(q)));
  }
  const double dt = 1.0 / rate_;
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
  TwoLinkVector q = TwoLinkVector::Zero(), v = TwoLinkVector::Zero();
  q(kLink1Angle) = q(kGearboxAAngle) = case_.q1_rad;
  q(kLink2Angle) = q(kGearboxBAngle) = case_.q4_rad;
  if (!(model_.Gap(q) > 0.0)) {
    throw std::domain_error(
        fmt::format("two-link: the tool's tip starts {:.4g} m inside the surface", -model_.Gap(q)));
  }
  Regime regime;
  double t = 0.0;
  State y = JoinState(q, v);
  double first_step = 1e-4;
  while (t < end_) {
    const double limit = t < case_.start_delay_s ? case_.start_delay_s : end_;
    integrator_.Reset(SystemFor(regime), y, t, first_step);
    if (next_sample_ == 0) Sample(0.0, y, regime);
    bool switched = false;
    // (a phase within 1e-12 s of its limit has reached it: no step that short)
    const double reached = limit - 1e-12 * std::max(1.0, limit);
    while (!switched && integrator_.time() < reached) {
      try {
        integrator_.Step(limit);
      } catch (const std::runtime_error& e) {
        throw std::domain_error(fmt::format("two-link, {} motion at t = {:.6f} s: {}",
                                            regime.constrained ? "constrained" : "free",
                                            integrator_.time(), e.what()));
      }
      if (++record_.steps > options_.max_steps && options_.max_steps > 0) {
        throw std::domain_error(fmt::format(
            "two-link: more than {} integration steps by t = {:.6f} s (too stiff for the budget)",
            options_.max_steps, integrator_.time()));
      }
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
        if (regime.constrained) {
          SplitState(y_hi, &q, &v);
          CloseLoop(model_, regime.dependent, &q, &v);
          integrator_.ReplaceState(JoinState(q, v));
        }
        continue;
      }
      // (a tip already in, which the tolerance makes all but impossible, strikes at once)
      const double t_event = !regime.constrained && e_lo <= 0.0
                                 ? t_lo
                                 : integrator_.RefineRoot(event, e_lo, t_hi, e_hi);
      Emit(t_event, regime);
      const State y_event = integrator_.Exact(t_event);
      SplitState(y_event, &q, &v);
      TwoLinkEvent record_event;
      record_event.time_s = t_event;
      if (!regime.constrained) {
        record_event.kind = "impact";
        record_event.impact = Impact(model_, q, v);
        v = record_event.impact.velocity;
        regime.constrained =
            ConstrainedMotion(model_, q, v, Voltages(t_event, q)).normal_force_n > 0.0;
        if (regime.constrained) {
          regime.dependent = DependentCoordinate(model_, q);
          CloseLoop(model_, regime.dependent, &q, &v);
        }
      } else {
        record_event.kind = "separation";
        regime.constrained = false;
      }
      record_.events.push_back(record_event);
      if (static_cast<int>(record_.events.size()) > options_.max_events) {
        throw std::domain_error(
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
    throw std::domain_error("two-link simulation: tolerances and steps must be positive");
  }
  Simulation simulation(model, experiment, options);
  return simulation.Run();
}

}  // namespace impactlab
