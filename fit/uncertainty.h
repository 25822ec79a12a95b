// Linear (first-order) propagation of independent input uncertainties through
// a smooth function, with central-difference partial derivatives. Used where a
// closed form gives the estimate and the Jacobian is not worth writing out.
// (Correlated residuals: CorrelationInflation in model/estimate.h.)
#pragma once

#include <functional>
#include <vector>

namespace impactlab {

// sigma_j(out) = sqrt(sum_i (d out_j / d in_i * sigma_i)^2). Inputs with
// sigma_i = 0 are skipped. The difference step is a small fraction of sigma_i
// (and of |in_i|), so the linearisation is taken where the data say it applies.
std::vector<double> PropagateUncertainty(
    const std::function<std::vector<double>(const std::vector<double>&)>& f,
    const std::vector<double>& inputs, const std::vector<double>& input_sigmas);

}  // namespace impactlab
