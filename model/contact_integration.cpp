#include "model/contact_integration.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include <boost/math/tools/roots.hpp>
// odeint's steppers copy members before they are first written (harmless: they
// are scratch space); GCC warns about it at every instantiation.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#include <boost/numeric/odeint/integrate/integrate_adaptive.hpp>
#include <boost/numeric/odeint/stepper/controlled_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/generation.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_fehlberg78.hpp>
#pragma GCC diagnostic pop
#include <fmt/format.h>

namespace impactlab {
namespace {

namespace odeint = boost::numeric::odeint;
using State = std::array<double, 2>;  // u, w

// Ends an integration that cannot finish: more than `max_steps` steps tried,
// a step size collapsed to nothing against the time, or a state no longer
// finite (each of which would otherwise loop for ever). Check says why the
// integration must stop after a trial step (none: it may go on).
struct StepGuard {
  long max_steps = 0;
  long tried = 0;
  template <typename Vector>
  std::optional<std::string> Check(double t, double dt, const Vector& x) {
    ++tried;
    bool finite = std::isfinite(t) && std::isfinite(dt);
    for (double v : x) finite = finite && std::isfinite(v);
    if (!finite) {
      return fmt::format("the contact's motion is no longer finite at scaled time {:.6g}", t);
    }
    if (!(t + dt > t)) {
      return fmt::format("the contact's step size collapsed to {:.3g} at scaled time {:.6g}", dt,
                         t);
    }
    if (tried > max_steps) {
      return fmt::format(
          "the contact had not ended after {} steps (scaled time {:.6g}): too stiff for this "
          "integration, e.g. a damping far beyond critical",
          max_steps, t);
    }
    return std::nullopt;
  }
};

// The impact that did not end, with why.
ScaledImpact NotEnded(ScaledImpact impact, std::string reason) {
  impact.ok = false;
  impact.reason = std::move(reason);
  return impact;
}
using Stepper = odeint::runge_kutta_fehlberg78<State>;

struct System {
  const ScaledForce& force;
  void operator()(const State& x, State& dxdt, double /*t*/) const {
    dxdt[0] = x[1];
    dxdt[1] = -force(x[0], x[1]);
  }
};

// One uncontrolled step of length h from x (h no longer than the accepted
// step it refines, so its error is no larger).
State StepFrom(const System& system, const State& x, double t, double h) {
  Stepper stepper;
  State out = x;
  if (h > 0.0) stepper.do_step(system, out, t, h);
  return out;
}

// The h in [0, step] where g(state after h) = 0, given a sign change over the step.
template <typename Event>
double LocateEvent(const System& system, const State& x, double t, double step, Event g) {
  auto phi = [&](double h) { return g(StepFrom(system, x, t, h)); };
  double a = 0.0, b = step;
  double fa = phi(a), fb = phi(b);
  if (fa == 0.0) return a;
  if (fb == 0.0 || fa * fb > 0.0) return b;
  std::uintmax_t iterations = 100;
  const auto bracket = boost::math::tools::toms748_solve(
      phi, a, b, fa, fb, boost::math::tools::eps_tolerance<double>(52), iterations);
  return 0.5 * (bracket.first + bracket.second);
}

}  // namespace

ScaledImpact IntegrateScaledImpact(const ScaledForce& force, Separation separation,
                                   const ScaledIntegrationOptions& options) {
  const System system{force};
  auto controlled = odeint::make_controlled(options.tolerance, options.tolerance, Stepper());
  auto ended = [&](const State& x) {
    return separation == Separation::kKinematic ? x[0] : force(x[0], x[1]);
  };
  State x{0.0, 1.0};
  double t = 0.0;
  double dt = 1e-3;
  ScaledImpact out;
  bool past_peak = false;
  // Under force separation the force may start at 0 (a law with no damping
  // at zero compression): the event is armed once the force is positive.
  bool armed = separation == Separation::kKinematic || ended(x) > 0.0;
  StepGuard guard{options.max_steps};
  while (t < options.max_time) {
    const State before = x;
    const double t_before = t;
    const bool accepted = controlled.try_step(system, x, t, dt) == odeint::success;
    if (std::optional<std::string> why = guard.Check(t, dt, x)) return NotEnded(out, *why);
    if (!accepted) continue;
    ++out.steps;
    const double step = t - t_before;
    if (!past_peak && x[1] <= 0.0) {
      const double h =
          LocateEvent(system, before, t_before, step, [](const State& s) { return s[1]; });
      out.peak_time = t_before + h;
      out.peak_compression = StepFrom(system, before, t_before, h)[0];
      past_peak = true;
    }
    if (!armed) {
      armed = ended(x) > 0.0;
      continue;
    }
    if (past_peak && ended(x) <= 0.0) {
      const double h = LocateEvent(system, before, t_before, step, ended);
      const State end = StepFrom(system, before, t_before, h);
      out.contact_time = t_before + h;
      out.exit_rate = end[1];
      out.exit_compression = separation == Separation::kKinematic ? 0.0 : end[0];
      return out;
    }
  }
  return NotEnded(out,
                  fmt::format("the contact had not ended after {} scaled time units ({} steps)",
                              options.max_time, out.steps));
}

namespace {

using Augmented = std::array<double, 4>;  // u, w, s_u, s_w
using AugmentedStepper = odeint::runge_kutta_fehlberg78<Augmented>;

struct AugmentedSystem {
  const ScaledForceWithPartials& force;
  void operator()(const Augmented& x, Augmented& dxdt, double /*t*/) const {
    const std::array<double, 4> f = force.evaluate(x[0], x[1]);
    dxdt[0] = x[1];
    dxdt[1] = -f[0];
    dxdt[2] = x[3];
    dxdt[3] = -(f[1] * x[2] + f[2] * x[3] + f[3]);
  }
};

Augmented AugmentedStep(const AugmentedSystem& system, const Augmented& x, double t, double h) {
  AugmentedStepper stepper;
  Augmented out = x;
  if (h > 0.0) stepper.do_step(system, out, t, h);
  return out;
}

}  // namespace

ScaledImpactSensitivity IntegrateScaledImpactWithSensitivity(
    const ScaledForceWithPartials& force, Separation separation,
    const ScaledIntegrationOptions& options) {
  const AugmentedSystem system{force};
  auto controlled =
      odeint::make_controlled(options.tolerance, options.tolerance, AugmentedStepper());
  const bool kinematic = separation == Separation::kKinematic;
  auto ended = [&](const Augmented& x) { return kinematic ? x[0] : force.evaluate(x[0], x[1])[0]; };
  // The event inside [t, t + step] from state x, by TOMS 748 on single steps.
  auto locate = [&](const Augmented& x, double t, double step, auto g) {
    auto phi = [&](double h) { return g(AugmentedStep(system, x, t, h)); };
    double fa = phi(0.0), fb = phi(step);
    if (fa == 0.0) return 0.0;
    if (fb == 0.0 || fa * fb > 0.0) return step;
    std::uintmax_t iterations = 100;
    const auto b = boost::math::tools::toms748_solve(
        phi, 0.0, step, fa, fb, boost::math::tools::eps_tolerance<double>(52), iterations);
    return 0.5 * (b.first + b.second);
  };
  Augmented x{0.0, 1.0, 0.0, 0.0};
  double t = 0.0, dt = 1e-3;
  ScaledImpactSensitivity out;
  bool past_peak = false;
  bool armed = kinematic || ended(x) > 0.0;
  StepGuard guard{options.max_steps};
  while (t < options.max_time) {
    const Augmented before = x;
    const double t_before = t;
    const bool accepted = controlled.try_step(system, x, t, dt) == odeint::success;
    if (std::optional<std::string> why = guard.Check(t, dt, x)) {
      out.impact = NotEnded(out.impact, *why);
      return out;
    }
    if (!accepted) continue;
    ++out.impact.steps;
    const double step = t - t_before;
    if (!past_peak && x[1] <= 0.0) {
      const double h = locate(before, t_before, step, [](const Augmented& a) { return a[1]; });
      out.impact.peak_time = t_before + h;
      out.impact.peak_compression = AugmentedStep(system, before, t_before, h)[0];
      past_peak = true;
    }
    if (!armed) {
      armed = ended(x) > 0.0;
      continue;
    }
    if (!past_peak || ended(x) > 0.0) continue;
    const double h = locate(before, t_before, step, ended);
    const Augmented e = AugmentedStep(system, before, t_before, h);
    const std::array<double, 4> f = force.evaluate(e[0], e[1]);
    out.impact.contact_time = t_before + h;
    out.impact.exit_rate = e[1];
    out.impact.exit_compression = kinematic ? 0.0 : e[0];
    // g = u: dg/ds = w, dg/dp = s_u. g = f: dg/ds = f_u w - f_w f, dg/dp = f_u s_u + f_w s_w + f_p.
    const double dg_ds = kinematic ? e[1] : f[1] * e[1] - f[2] * f[0];
    const double dg_dp = kinematic ? e[2] : f[1] * e[2] + f[2] * e[3] + f[3];
    out.d_contact_time = -dg_dp / dg_ds;
    out.d_exit_rate = e[3] - f[0] * out.d_contact_time;  // w' = -f at the end
    return out;
  }
  out.impact =
      NotEnded(out.impact, fmt::format("the contact had not ended after {} scaled time units ({} "
                                       "steps)",
                                       options.max_time, out.impact.steps));
  return out;
}

ScaledState ScaledStateAt(const ScaledForce& force, double time,
                          const ScaledIntegrationOptions& options) {
  if (!(time > 0.0)) return {0.0, 1.0};
  const System system{force};
  auto controlled = odeint::make_controlled(options.tolerance, options.tolerance, Stepper());
  State x{0.0, 1.0};
  odeint::integrate_adaptive(controlled, system, x, 0.0, time, std::fmin(1e-3, time));
  return {x[0], x[1]};
}

}  // namespace impactlab
