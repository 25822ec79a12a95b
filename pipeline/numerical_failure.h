// A fit whose integration fails on the data fails alone (internal to
// pipeline/).
#pragma once

#include <functional>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace impactlab {

// `fit()`, or, where the ODE integrator's step-size failure (a
// std::runtime_error model/ still throws) ends it, a default Fit that
// `name` identifies (its law, its separation) and whose `reason` says so:
// the run's measurement and the other fits and products stand, as a run
// that fails does not cost the others. Programming errors (logic_error)
// are not caught.
template <typename Fit>
Fit FitOrNumericalFailure(const std::function<Fit()>& fit, const std::function<void(Fit&)>& name) {
  try {
    return fit();
  } catch (const std::runtime_error& error) {
    Fit failed;
    name(failed);
    failed.reason = fmt::format("the fit's integration failed: {}", error.what());
    return failed;
  }
}

}  // namespace impactlab
