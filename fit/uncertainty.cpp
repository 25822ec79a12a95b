#include "fit/uncertainty.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace impactlab {

std::vector<double> PropagateUncertainty(
    const std::function<std::vector<double>(const std::vector<double>&)>& f,
    const std::vector<double>& inputs, const std::vector<double>& input_sigmas) {
  if (inputs.size() != input_sigmas.size()) {
    throw std::invalid_argument("PropagateUncertainty: one sigma per input is needed");
  }
  std::vector<double> variance;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const double sigma = input_sigmas[i];
    if (!(sigma > 0.0)) continue;
    // A step well inside the uncertainty keeps the difference local to the
    // estimate; 1e-4 sigma keeps truncation and rounding errors both ~1e-8.
    const double step = std::min(1e-4 * sigma, 1e-6 * std::max(std::abs(inputs[i]), 1e-300));
    std::vector<double> up = inputs, down = inputs;
    up[i] += step;
    down[i] -= step;
    const std::vector<double> f_up = f(up), f_down = f(down);
    if (variance.empty()) variance.assign(f_up.size(), 0.0);
    for (std::size_t j = 0; j < f_up.size(); ++j) {
      const double slope = (f_up[j] - f_down[j]) / (2.0 * step);
      variance[j] += slope * slope * sigma * sigma;
    }
  }
  if (variance.empty()) variance.assign(f(inputs).size(), 0.0);
  for (double& v : variance) v = std::sqrt(v);
  return variance;
}

}  // namespace impactlab
