// Internal to synth/: Boost.Odeint's adaptive Dormand-Prince 5(4) stepper
// driven one accepted step at a time, so that the caller can
//  - stop exactly at known discontinuities (releases, wire-sawtooth jumps),
//  - read the dense output (4th-order interpolant) for the output samples, and
//  - evaluate the state at an event time with one fresh RK step from the last
//    accepted point (5th order, as accurate as an accepted step), which is what
//    event roots and the next phase's initial state use.
#pragma once

#include <functional>
#include <memory>

#include "synth/dynamics.h"

namespace impactlab::synth_detail {

struct IntegratorTolerances {
  double relative = 1e-12;   // per step, relative to each component and its change
  double absolute = 1e-17;   // per step, in each component's units
  double max_step_s = 0.01;  // no step longer than this, s
};

class Integrator {
 public:
  explicit Integrator(const IntegratorTolerances& tolerances);
  ~Integrator();
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;

  // Starts a smooth phase of `dynamics` at (t, y) with a first trial step.
  // `dynamics` must outlive the phase and not change during it.
  void Reset(const Dynamics& dynamics, const State& y, double t_s, double first_step_s);

  // Takes one accepted step that ends no later than `limit_s` (ending exactly
  // on it when it is reached). Throws std::runtime_error if the step size
  // collapses.
  void Step(double limit_s);

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

}  // namespace impactlab::synth_detail
