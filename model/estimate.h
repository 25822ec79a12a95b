// An estimate with its one-sigma uncertainty, and how far correlated
// residuals widen a least-squares one. Every stage reports its results so:
// fits, rebound maxima, calibration bands, log analysis.
#pragma once

#include <span>
#include <vector>

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

// The autocovariance of the errors behind a least-squares fit, at lags 0 ..
// max_lag samples, from the fit's residuals: unbiased where the residuals'
// own is not. A fit absorbs the part of the errors its model can follow, so
// over a window a few correlation lengths long the residuals' correlation
// falls off early and CorrelationInflation understates it (a peak fit over
// 60-120 samples of errors blurred over 2 samples: by 1.35-1.6 in sigma,
// in simulation). With the
// residuals r = M e (M = I - J (J^T J)^-1 J^T, J the fit's n x p Jacobian,
// column-major, weighted as fitted) and stationary errors of autocovariance
// gamma_k, E[sum_i r_i r_(i+j)] is linear in gamma: that system, solved for
// gamma_0 .. gamma_max_lag, undoes the fit's absorption. Truncated where it
// first turns non-positive (the initial positive sequence); empty where the
// residuals cannot tell (too few, all zero, a singular system).
std::vector<double> FitErrorAutocovariance(std::span<const double> residual,
                                           std::span<const double> jacobian, int parameters,
                                           int max_lag);

// The variance of sum_i h_i e_i for errors of that autocovariance (none beyond
// its last lag): the exact sandwich variance of a fitted quantity whose
// least-squares weights on the samples are h.
double CorrelatedVariance(std::span<const double> autocovariance, std::span<const double> h);

}  // namespace impactlab
