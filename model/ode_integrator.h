// Boost.Odeint's adaptive Dormand-Prince 5(4) stepper driven one accepted step
// at a time, for hybrid simulations (the pendulum experiment in synth/, the
// two-link manipulator in multibody/), so that the caller can
//  - stop exactly at known discontinuities (releases, a motor switched on),
//  - read the dense output (4th-order interpolant) for the output samples,
//  - evaluate the state at an event time with one fresh RK step from the last
//    accepted point (5th order, as accurate as an accepted step), which is what
//    event roots and the next phase's initial state use, and
//  - replace the state after a step (a projection onto a constraint) before
//    the next one.
// Explicitly instantiated for the state sizes the project uses (6 and 16).
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

namespace impactlab {

struct OdeTolerances {
  double relative = 1e-12;   // per step, relative to each component and its change
  double absolute = 1e-17;   // per step, in each component's units
  double max_step_s = 0.01;  // no step longer than this, s
};

// What one Step did: it advanced, or the motion cannot be carried on from
// time() and `reason` says why and where (the step size collapsed, or no step
// leaves the state finite). A step that fails leaves time() and state() where
// they were, so the caller keeps what was integrated up to there.
struct OdeStepResult {
  bool ok = true;
  std::string reason;  // empty when ok
};

template <std::size_t N>
class OdeIntegrator {
 public:
  using State = std::array<double, N>;
  // dy/dt = f(y, t); must stay valid and unchanged during a phase.
  using System = std::function<void(const State& y, State& dydt, double t)>;

  explicit OdeIntegrator(const OdeTolerances& tolerances);
  ~OdeIntegrator();
  OdeIntegrator(const OdeIntegrator&) = delete;
  OdeIntegrator& operator=(const OdeIntegrator&) = delete;

  // Starts a smooth phase of `system` at (t, y) with a first trial step.
  void Reset(System system, const State& y, double t_s, double first_step_s);

  // Takes one accepted step that ends no later than `limit_s` (ending exactly
  // on it when it is reached), or says why none can be taken: a step size
  // below 1e-15 of the time (or of 1 s), a state no step keeps finite, or 200
  // rejected trials. That is the motion's failure, a value; a `limit_s` not
  // after time() is the caller's mistake and throws std::logic_error.
  [[nodiscard]] OdeStepResult Step(double limit_s);

  // Replaces the state at time() (e.g. its projection onto a constraint); the
  // next step starts from it. Dense output of the last step is not changed.
  void ReplaceState(const State& y);

  double previous_time() const { return t_prev_; }
  double time() const { return t_; }
  const State& previous_state() const { return y_prev_; }
  const State& state() const { return y_; }

  // Dense output within the last step [previous_time, time].
  State Interpolate(double t_s) const;
  // The state at t in [previous_time, time] from one RK step out of the last
  // accepted point: smooth in t and as accurate as an accepted step.
  State Exact(double t_s) const;

  // Root of g(Exact(t)) in [previous_time, t_hi] (t_hi <= time), given g
  // changes sign there (g_prev = g(previous_state), g_hi = g(Exact(t_hi)));
  // to within a few ulps of t.
  double RefineRoot(const std::function<double(const State&)>& g, double g_prev, double t_hi_s,
                    double g_hi) const;

  // The step size odeint proposes next, s.
  double suggested_step() const;
  long accepted_steps() const { return accepted_steps_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double t_prev_ = 0.0;
  double t_ = 0.0;
  State y_prev_{};
  State y_{};
  long accepted_steps_ = 0;
};

extern template class OdeIntegrator<6>;
extern template class OdeIntegrator<16>;

}  // namespace impactlab
