// The one-step integrator (model/ode_integrator.h) where a motion leaves the
// finite numbers or asks for more than a double can give: it says why it
// cannot step, as a value, and never accepts a NaN state.
#include "model/ode_integrator.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <catch2/catch.hpp>

namespace impactlab {
namespace {

using Integrator = OdeIntegrator<6>;

// dy/dt = y^2 from y = 1 blows up at t = 1; past y = 1e6 the right-hand side
// is NaN, as an overflowing model's would be.
void BlowingUp(const Integrator::State& y, Integrator::State& dydt, double) {
  dydt.fill(0.0);
  dydt[0] = y[0] < 1e6 ? y[0] * y[0] : std::numeric_limits<double>::quiet_NaN();
}

// dy/dt = -y from y = 1 at t0, first step 1e-3.
void StartDecay(Integrator& integrator, double t0) {
  Integrator::State y{};
  y[0] = 1.0;
  integrator.Reset(
      [](const Integrator::State& s, Integrator::State& dydt, double) {
        dydt.fill(0.0);
        dydt[0] = -s[0];
      },
      y, t0, 1e-3);
}

TEST_CASE("ode integrator: a right-hand side that turns NaN is refused, never stepped into") {
  // odeint alone accepts the step whose error estimate is NaN.
  Integrator integrator({1e-8, 1e-12, 0.1});
  Integrator::State y{};
  y[0] = 1.0;
  integrator.Reset(BlowingUp, y, 0.0, 1e-3);
  OdeStepResult step;
  while (step.ok && integrator.time() < 2.0) {
    step = integrator.Step(2.0);
    REQUIRE(std::isfinite(integrator.state()[0]));
  }
  CHECK_FALSE(step.ok);
  CHECK_FALSE(step.reason.empty());
  // The failed step left the integrator where it was: the last good state.
  CHECK(integrator.time() < 1.0);
  CHECK(integrator.state()[0] > 1.0);
  CHECK(std::isfinite(integrator.state()[0]));
}

TEST_CASE("ode integrator: tolerances no step can meet are a collapse said with its time") {
  // y' = -y from y = 1 at t = 3: every trial's error estimate exceeds a
  // tolerance of 1e-300, so the step shrinks until it is nothing against t.
  Integrator integrator({1e-300, 1e-300, 0.1});
  StartDecay(integrator, 3.0);
  const OdeStepResult step = integrator.Step(4.0);
  CHECK_FALSE(step.ok);
  CHECK_THAT(step.reason, Catch::StartsWith("ODE step size collapsed at t = 3 s"));
  CHECK(integrator.time() == 3.0);
  CHECK(integrator.state()[0] == 1.0);
  CHECK(integrator.accepted_steps() == 0);
}

TEST_CASE("ode integrator: a step that advances says so and lands on its limit") {
  Integrator integrator({1e-10, 1e-14, 0.5});
  StartDecay(integrator, 0.0);
  OdeStepResult step;
  while (integrator.time() < 1.0) {
    step = integrator.Step(1.0);
    REQUIRE(step.ok);
  }
  CHECK(step.reason.empty());
  CHECK(integrator.time() == 1.0);
  CHECK(integrator.state()[0] == Approx(std::exp(-1.0)).epsilon(1e-9));
}

TEST_CASE("ode integrator: a limit not after the time is the caller's mistake, thrown") {
  Integrator integrator({1e-8, 1e-12, 0.1});
  integrator.Reset(BlowingUp, Integrator::State{}, 1.0, 1e-3);
  CHECK_THROWS_AS(integrator.Step(1.0), std::logic_error);
}

}  // namespace
}  // namespace impactlab
