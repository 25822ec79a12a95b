// Internal to synth/: the pendulum experiment's integrator, the project's
// Dormand-Prince stepper (model/ode_integrator.h) on its six-component state.
#pragma once

#include <functional>

#include "model/ode_integrator.h"
#include "synth/dynamics.h"

namespace impactlab::synth_detail {

using IntegratorTolerances = OdeTolerances;
using Integrator = OdeIntegrator<std::tuple_size_v<State>>;

}  // namespace impactlab::synth_detail
