// Uncertainty helpers: linear propagation of independent input uncertainties,
// and the growth of a least-squares variance when residuals are correlated.
#pragma once

#include <functional>
#include <span>
#include <vector>

namespace impactlab {

// sigma_j(out) = sqrt(sum_i (d out_j / d in_i * sigma_i)^2). Inputs with
// sigma_i = 0 are skipped. The difference step is a small fraction of sigma_i
// (and of |in_i|), so the linearisation is taken where the data say it applies.
std::vector<double> PropagateUncertainty(
    const std::function<std::vector<double>(const std::vector<double>&)>& f,
    const std::vector<double>& inputs, const std::vector<double>& input_sigmas);

// How much a least-squares estimate's variance grows because the residuals
// are correlated along the record rather than independent: 1 + 2 sum rho_k,
// the residuals' autocorrelation at lag k summed while it stays positive (the
// initial positive sequence), at least 1. A digitized photo's trace errs
// smoothly over many samples (the spot's blur, the graticule's residual
// mapping), a scope's quantised record in runs of equal codes; s^2 (A^T A)^-1
// alone counts every sample as an independent reading and understates the
// uncertainty by the square root of this. For a model that varies slowly over
// the correlation length, the exact sandwich covariance reduces to this factor
// times it. `residual` in sample order, weighted as the fit weighted it.
double CorrelationInflation(std::span<const double> residual);

}  // namespace impactlab
