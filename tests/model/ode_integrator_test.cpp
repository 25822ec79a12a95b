// The one-step integrator (model/ode_integrator.h) where a motion leaves the
// finite numbers: it refuses, it never accepts a NaN state.
#include "model/ode_integrator.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <catch2/catch.hpp>

namespace impactlab {

TEST_CASE("ode integrator: a right-hand side that turns NaN is refused, never stepped into") {
  // dy/dt = y^2 from y = 1 blows up at t = 1; past y = 1e6 the right-hand
  // side is NaN, as an overflowing model's would be. odeint alone accepts the
  // step whose error estimate is NaN.
  using Integrator = OdeIntegrator<6>;
  Integrator integrator({1e-8, 1e-12, 0.1});
  const Integrator::System blowing_up = [](const Integrator::State& y, Integrator::State& dydt,
                                           double) {
    dydt.fill(0.0);
    dydt[0] = y[0] < 1e6 ? y[0] * y[0] : std::numeric_limits<double>::quiet_NaN();
  };
  Integrator::State y{};
  y[0] = 1.0;
  integrator.Reset(blowing_up, y, 0.0, 1e-3);
  bool refused = false;
  try {
    while (integrator.time() < 2.0) {
      integrator.Step(2.0);
      REQUIRE(std::isfinite(integrator.state()[0]));
    }
  } catch (const std::runtime_error& e) {
    refused = true;
    CHECK(integrator.time() < 1.0);
    CHECK(std::isfinite(integrator.state()[0]));
  }
  CHECK(refused);
}

}  // namespace impactlab
