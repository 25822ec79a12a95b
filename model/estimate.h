// An estimate with its one-sigma uncertainty, and how far correlated
// residuals widen a least-squares one. Every stage reports its results so:
// fits, rebound maxima, calibration bands, log analysis.
#pragma once

#include <span>

namespace impactlab {

// An estimate and its one-sigma uncertainty (linear propagation of the
// measurement uncertainties; 0 when the inputs carry none).
struct Estimate {
  double value = 0.0;
  double sigma = 0.0;
};

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
