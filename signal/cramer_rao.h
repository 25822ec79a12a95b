// The Cramer-Rao bound for a damped cosine in white Gaussian noise
// (docs/logs.md, "Cramer-Rao bound").
//
//   y_n = A exp(-sigma t_n) cos(2 pi f t_n + phi) + w_n,   t_n = n / f_s,
//   sigma = 2 pi f zeta / sqrt(1 - zeta^2),  w_n ~ N(0, s^2),  n = 0 .. N-1,
//
// with f the damped frequency and zeta the damping ratio. The Fisher
// information of theta = (A, phi, f, zeta) is F = J^T J / s^2, J_nk = dy_n/dtheta_k
// (closed-form derivatives, below); the bound on the standard deviation of any
// unbiased estimate of theta_k is sqrt((F^-1)_kk). For zeta = 0 with zeta known
// (3 parameters) the frequency bound tends to the classical tone bound
// sqrt(12 / ((2 pi)^2 eta N (N^2 - 1))) cycles/sample, eta = A^2 / (2 s^2).
#pragma once

#include <cstddef>

namespace impactlab {

struct DampedCosine {
  double amplitude = 1.0;      // A, units
  double phase_rad = 0.0;      // phi at t = 0
  double frequency_hz = 1.0;   // f, damped
  double damping_ratio = 0.0;  // zeta, in [0, 1)
};

struct CramerRaoBound {
  double amplitude = 0.0;      // units
  double phase_rad = 0.0;      // rad
  double frequency_hz = 0.0;   // Hz
  double damping_ratio = 0.0;  // 1 (0 when the decay is taken as known)
};

// One-sigma bounds for N samples at `sample_rate_hz` in noise of standard
// deviation `noise_sigma`. With `decay_known` only (A, phi, f) are estimated.
CramerRaoBound DampedCosineCrb(const DampedCosine& signal, double sample_rate_hz,
                               std::size_t samples, double noise_sigma, bool decay_known = false);

// The classical bound for an undamped tone, cycles per sample (Rife & Boorstyn 1974).
double ToneFrequencyCrbCyclesPerSample(std::size_t samples, double eta);

}  // namespace impactlab
