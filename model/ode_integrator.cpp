#include "model/ode_integrator.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <boost/math/tools/roots.hpp>
#include <boost/numeric/odeint/stepper/controlled_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_dopri5.hpp>

namespace impactlab {

namespace odeint = boost::numeric::odeint;

template <std::size_t N>
struct OdeIntegrator<N>::Impl {
  using Dopri = odeint::runge_kutta_dopri5<State>;
  using Controlled = odeint::controlled_runge_kutta<Dopri>;

  explicit Impl(const OdeTolerances& tol)
      : controlled(typename Controlled::error_checker_type(tol.absolute, tol.relative),
                   typename Controlled::step_adjuster_type(tol.max_step_s), Dopri()) {}

  // Odeint copies the system: a thin wrapper around the current one.
  auto Wrapped() const {
    return [s = &system](const State& y, State& dydt, double t) { (*s)(y, dydt, t); };
  }

  Controlled controlled;
  mutable Dopri exact;  // separate stages, so Exact() leaves the dense output intact
  System system;
  State dydt_prev{};
  State dydt{};
  double step_s = 0.0;
};

template <std::size_t N>
OdeIntegrator<N>::OdeIntegrator(const OdeTolerances& tolerances)
    : impl_(std::make_unique<Impl>(tolerances)) {}

template <std::size_t N>
OdeIntegrator<N>::~OdeIntegrator() = default;

template <std::size_t N>
void OdeIntegrator<N>::Reset(System system, const State& y, double t_s, double first_step_s) {
  impl_->system = std::move(system);
  impl_->controlled.reset();
  t_prev_ = t_ = t_s;
  y_prev_ = y_ = y;
  impl_->system(y_, impl_->dydt, t_);
  impl_->dydt_prev = impl_->dydt;
  impl_->step_s = first_step_s;
}

namespace {

template <std::size_t N>
bool AllFinite(const std::array<double, N>& values) {
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

}  // namespace

template <std::size_t N>
OdeStepResult OdeIntegrator<N>::Step(double limit_s) {
  if (!(limit_s > t_)) {
    throw std::logic_error(fmt::format("integrator asked to step from {} s to {} s", t_, limit_s));
  }
  const auto system = impl_->Wrapped();
  for (int attempt = 0; attempt < 200; ++attempt) {
    const bool clipped = impl_->step_s >= limit_s - t_;
    double dt = clipped ? limit_s - t_ : impl_->step_s;
    double t = t_;
    State y_out;
    State dydt_out;
    const auto result = impl_->controlled.try_step(system, y_, impl_->dydt, t, y_out, dydt_out, dt);
    // odeint accepts a step whose error estimate is NaN (NaN > 1 is false):
    // a step that leaves the finite numbers is rejected and retried shorter.
    const bool finite = AllFinite(y_out) && AllFinite(dydt_out);
    if (result == odeint::success && !finite) {
      impl_->step_s = 0.25 * (clipped ? limit_s - t_ : impl_->step_s);
      if (!(impl_->step_s > 1e-15 * std::max(1.0, std::abs(t_)))) {
        return {false, fmt::format("the state is not finite after any step from t = {} s "
                                   "(forces beyond double range)",
                                   t_)};
      }
      continue;
    }
    if (result == odeint::success) {
      t_prev_ = t_;
      y_prev_ = y_;
      impl_->dydt_prev = impl_->dydt;
      t_ = clipped ? limit_s : t;  // land on the limit exactly, not one ulp off
      y_ = y_out;
      impl_->dydt = dydt_out;
      impl_->step_s = dt;  // the size odeint suggests for the next step
      ++accepted_steps_;
      return {};
    }
    impl_->step_s = dt;  // the reduced size odeint suggests
    if (!(dt > 1e-15 * std::max(1.0, std::abs(t_)))) break;
  }
  return {false,
          fmt::format("ODE step size collapsed at t = {} s (last trial {} s)", t_, impl_->step_s)};
}

template <std::size_t N>
typename OdeIntegrator<N>::State OdeIntegrator<N>::Interpolate(double t_s) const {
  if (t_s == t_) return y_;
  State y;
  impl_->controlled.stepper().calc_state(t_s, y, y_prev_, impl_->dydt_prev, t_prev_, y_,
                                         impl_->dydt, t_);
  return y;
}

template <std::size_t N>
typename OdeIntegrator<N>::State OdeIntegrator<N>::Exact(double t_s) const {
  if (t_s == t_prev_) return y_prev_;
  State y;
  State dydt;
  impl_->exact.do_step(impl_->Wrapped(), y_prev_, impl_->dydt_prev, t_prev_, y, dydt,
                       t_s - t_prev_);
  return y;
}

template <std::size_t N>
double OdeIntegrator<N>::RefineRoot(const std::function<double(const State&)>& g, double g_prev,
                                    double t_hi_s, double g_hi) const {
  if (g_prev == 0.0) return t_prev_;
  if (g_hi == 0.0) return t_hi_s;
  auto f = [&](double t) { return g(Exact(t)); };
  std::uintmax_t iterations = 100;
  const auto [lo, hi] = boost::math::tools::toms748_solve(
      f, t_prev_, t_hi_s, g_prev, g_hi, boost::math::tools::eps_tolerance<double>(50), iterations);
  return 0.5 * (lo + hi);
}

template <std::size_t N>
double OdeIntegrator<N>::suggested_step() const {
  return impl_->step_s;
}

template <std::size_t N>
void OdeIntegrator<N>::ReplaceState(const State& y) {
  y_ = y;
  impl_->system(y_, impl_->dydt, t_);
  impl_->controlled.reset();
}

template class OdeIntegrator<6>;
template class OdeIntegrator<16>;

}  // namespace impactlab
