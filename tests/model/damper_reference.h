// An independent integration of the damper's scaled impact (Hertz spring
// with a linear damper, model/power_law_contact.h) accurate to ~1e-13, the
// truth its tables are built from and checked against.
//
// In time, the spring's u^n is not smooth where u = 0 (for n = 3/2, u^n ~
// s^(3/2) at the start and at a kinematic end), and the event-located
// integration of model/contact_integration.h keeps e only to ~1e-8 there.
// Near u = 0 this one takes r = sqrt(u) as the variable instead:
//   dw/dr = -2 r f / w,   ds/dr = 2 r / w,   f = ((n+1)/2) r^(2n) + beta w,
// polynomial in r for 2n whole, and w is far from 0 there (the contact
// enters at w = 1 and leaves at w = -e). Three phases: in r from u = 0 to
// u_1, in time from u_1 through the peak back to u_1 (or to F = 0 under force
// separation), in r again down to u = 0 (or to F = 0), with u_1 a quarter of
// the peak's rough size min(1, 1/beta).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <boost/math/tools/roots.hpp>
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#include <boost/numeric/odeint/integrate/integrate_adaptive.hpp>
#include <boost/numeric/odeint/stepper/controlled_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/generation.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_fehlberg78.hpp>
#pragma GCC diagnostic pop

#include "model/contact.h"

namespace impactlab::damper_reference {

struct Impact {
  double contact_time = 0.0;  // s_c
  double restitution = 0.0;   // e
};

using Pair = std::array<double, 2>;
using Stepper = boost::numeric::odeint::runge_kutta_fehlberg78<Pair>;

// The scaled force with the odd extension below u = 0.
inline double Force(double n, double beta, double u, double w) {
  return 0.5 * (n + 1.0) * std::copysign(std::pow(std::abs(u), n), u) + beta * w;
}

// y = (w, s) against q, where r = r0 + direction q.
struct InRoot {
  double n, beta, r0, direction;
  void operator()(const Pair& y, Pair& dy, double q) const {
    const double r = r0 + direction * q;
    const double f = 0.5 * (n + 1.0) * std::pow(std::abs(r), 2.0 * n) + beta * y[0];
    dy[0] = direction * (-2.0 * r * f / y[0]);
    dy[1] = direction * (2.0 * r / y[0]);
  }
};

// x = (u, w) against s.
struct InTime {
  double n, beta;
  void operator()(const Pair& x, Pair& dx, double /*s*/) const {
    dx[0] = x[1];
    dx[1] = -Force(n, beta, x[0], x[1]);
  }
};

// The h in [0, step] where g(the state one step of h from x) = 0, given
// g(x) > 0 and g <= 0 after the whole step.
template <typename System, typename Event>
double Locate(const System& system, const Pair& x, double t, double step, Event g) {
  const auto phi = [&](double h) {
    Pair y = x;
    if (h > 0.0) Stepper().do_step(system, y, t, h);
    return g(y, t + h);
  };
  const double fa = phi(0.0), fb = phi(step);
  if (!(fa > 0.0) || fb == 0.0) return fa > 0.0 ? step : 0.0;
  std::uintmax_t iterations = 200;
  const auto bracket = boost::math::tools::toms748_solve(
      phi, 0.0, step, fa, fb, boost::math::tools::eps_tolerance<double>(53), iterations);
  return 0.5 * (bracket.first + bracket.second);
}

// Advances the state by controlled steps until g(state, t) <= 0, then
// returns the state at g = 0 (its independent variable in *t).
template <typename System, typename Event>
Pair Until(const System& system, Pair x, double* t, double limit, double first_step,
           double tolerance, Event g) {
  namespace odeint = boost::numeric::odeint;
  auto controlled = odeint::make_controlled(tolerance, tolerance, Stepper());
  double dt = first_step;
  while (*t < limit) {
    const Pair before = x;
    const double t_before = *t;
    dt = std::fmin(dt, limit - *t);  // the event is before the limit: never step past it
    if (controlled.try_step(system, x, *t, dt) != odeint::success) continue;
    if (g(x, *t) > 0.0) continue;
    const double h = Locate(system, before, t_before, *t - t_before, g);
    x = before;
    if (h > 0.0) Stepper().do_step(system, x, t_before, h);
    *t = t_before + h;
    return x;
  }
  throw NoSeparationError("the reference integration did not reach its event");
}

inline Impact Integrate(double n, double beta, Separation separation, double tolerance = 1e-14) {
  namespace odeint = boost::numeric::odeint;
  const bool force = separation == Separation::kForce;
  const double u1 = 0.25 * std::fmin(1.0, 1.0 / beta);
  const double r1 = std::sqrt(u1);
  // Phase 1: r from 0 to r1.
  Pair y{1.0, 0.0};
  odeint::integrate_adaptive(odeint::make_controlled(tolerance, tolerance, Stepper()),
                             InRoot{n, beta, 0.0, 1.0}, y, 0.0, r1, 1e-3 * r1);
  // Phase 2: in time until F = 0 (force) or u = u1 after the peak (the
  // smaller of the two event functions, each positive before its event).
  const InTime in_time{n, beta};
  double s = y[1];
  const auto at_force = [&](const Pair& z) { return force ? Force(n, beta, z[0], z[1]) : 1.0; };
  const auto at_return = [&](const Pair& z) { return z[1] < 0.0 ? z[0] - u1 : 1.0; };
  const Pair x = Until(in_time, Pair{u1, y[0]}, &s, 1e4, 1e-3, tolerance,
                       [&](const Pair& z, double) { return std::fmin(at_force(z), at_return(z)); });
  if (std::abs(at_force(x)) < std::abs(at_return(x))) return {s, -x[1]};
  // Phase 3: r from r1 down to 0 (q = r1 - r from 0 to r1), or to F = 0.
  const InRoot down{n, beta, r1, -1.0};
  y = {x[1], s};
  if (!force) {
    odeint::integrate_adaptive(odeint::make_controlled(tolerance, tolerance, Stepper()), down, y,
                               0.0, r1, 1e-3 * r1);
    return {y[1], -y[0]};
  }
  double q = 0.0;
  y = Until(down, y, &q, r1, 1e-3 * r1, tolerance, [&](const Pair& z, double at) {
    return 0.5 * (n + 1.0) * std::pow(r1 - at, 2.0 * n) + beta * z[0];
  });
  return {y[1], -y[0]};
}

}  // namespace impactlab::damper_reference
