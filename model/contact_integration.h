// Event-located integration of one impact in scaled variables, for the laws
// without a closed-form contact time (Hertz with a linear damper) and as the
// independent check of the ones with (Hertz, Hunt-Crossley).
//
// Scaled by a length x* and the time x*/v0 (each law says which), the
// compression u and its rate w obey
//   u' = w,   w' = -f(u, w),   u(0) = 0, w(0) = 1,
// f the scaled contact force. The contact ends at the first time after the
// start where u returns to 0 (kinematic) or f does (force). A Runge-Kutta-
// Fehlberg 7(8) pair with step control at 1e-13 carries the state; an event
// inside an accepted step is found by a bracketed root search (TOMS 748) on
// single steps of the same method from the step's start, so the event
// inherits the integration's accuracy rather than an interpolant's.
#pragma once

#include <array>
#include <functional>
#include <string>

#include "model/contact.h"

namespace impactlab {

// The scaled force f(u, w). Must be defined for small negative u (the last
// step may overshoot the contact's end): odd extensions such as
// sign(u) |u|^n are the usual choice.
using ScaledForce = std::function<double(double compression, double rate)>;

struct ScaledImpact {
  // False when the contact did not end: not by max_time, not within
  // max_steps, or the step or the state could no longer be computed; `reason`
  // says which, at what scaled time. The figures below are then not an end's.
  bool ok = true;
  std::string reason;
  double contact_time = 0.0;      // s_c, scaled
  double exit_rate = 0.0;         // w at the end (negative); e = -exit_rate
  double exit_compression = 0.0;  // u at the end (0 under kinematic separation)
  double peak_compression = 0.0;  // max u
  double peak_time = 0.0;         // s at max u
  int steps = 0;                  // accepted steps, for benchmarks
};

struct ScaledIntegrationOptions {
  double tolerance = 1e-13;  // absolute and relative, per step
  double max_time = 1e4;     // scaled; beyond it the contact is said not to end
  // Steps tried (accepted or not) before the contact is said not to end. A
  // strongly overdamped law is stiff: this explicit stepper then needs steps
  // of the fast time scale over the slow one's whole span (at a damping of
  // 1e6, some 1e10 of them), and a state gone non-finite shrinks the step for
  // ever. A real impact takes hundreds.
  long max_steps = 200'000;
};

// A contact that has not ended by max_time or within max_steps, or whose step
// or state can no longer be computed, is an impact with !ok and the reason:
// the law's failure on these parameters, a value (HertzDamperContact, whose
// callers need an end, throws it as NoSeparationError).
ScaledImpact IntegrateScaledImpact(const ScaledForce& force, Separation separation,
                                   const ScaledIntegrationOptions& options = {});

// The same impact with the derivatives of its end with respect to one
// parameter p of the force, f(u, w; p): the variational equations
//   s_u' = s_w,  s_w' = -(f_u s_u + f_w s_w + f_p)
// ride along (inside the same error control), and the event time's
// derivative follows from the implicit-function theorem on the event
// function g: ds_c/dp = -(dg/dp)/(dg/ds) at the event. Exact to the
// integration's accuracy: no differences of perturbed runs. A contact that
// does not end is `impact` with !ok, as above.
struct ScaledForceWithPartials {
  // f and its partial derivatives f_u, f_w, f_p at (u, w).
  std::function<std::array<double, 4>(double compression, double rate)> evaluate;
};
struct ScaledImpactSensitivity {
  ScaledImpact impact;
  double d_contact_time = 0.0;  // d s_c / dp
  double d_exit_rate = 0.0;     // d w_end / dp
};
ScaledImpactSensitivity IntegrateScaledImpactWithSensitivity(
    const ScaledForceWithPartials& force, Separation separation,
    const ScaledIntegrationOptions& options = {});

// u(s) and w(s) at scaled time s >= 0 (no event: the caller knows s is inside
// the contact).
struct ScaledState {
  double compression = 0.0;
  double rate = 0.0;
};
ScaledState ScaledStateAt(const ScaledForce& force, double time,
                          const ScaledIntegrationOptions& options = {});

}  // namespace impactlab
