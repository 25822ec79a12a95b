// Damped modes of a ring-down: the matrix pencil for starting values, then a
// least-squares fit with Ceres (docs/logs.md, "Damped-mode fit").
//
// Model, for samples y_n at t_n = n / f_s from the window's start:
//   y(t) = c + sum_k A_k exp(-sigma_k t) cos(2 pi f_k t + phi_k)
//            + sum_j B_j exp(-r_j t),
//   sigma_k = 2 pi f_k zeta_k / sqrt(1 - zeta_k^2)
// with f_k the damped frequency (the one a spectrum shows; the natural
// frequency is f_k / sqrt(1 - zeta_k^2)) and zeta_k the damping ratio. The
// real decays B_j exp(-r_j t) are overdamped motions (after an impact the hub
// settles on its motor's damping) that would otherwise bend the modes.
//
// 1. Matrix pencil (Hua & Sarkar 1990): on at most `pencil_max_samples` samples
//    (averaged in blocks of D: averaging a sum of exponentials keeps their poles),
//    the Hankel matrix's principal right singular vectors V give the poles as the
//    eigenvalues of pinv(V_top) V_bottom. The order holds `extra_modes` more pairs
//    than wanted, so noise and weak modes do not bend the strong ones. A pole
//    with less than one cycle in the window counts as a real decay; a decay
//    that does not e-fold within the window is left to the offset.
// 2. Linear least squares for every pole's amplitudes on the full window. The
//    `modes` pairs and `decays` real poles with the most energy in the window are
//    kept, if their energy exceeds `min_term_snr` noise variances (s^2 of that
//    least-squares fit): a term the data do not support would leave its
//    frequency and damping undetermined. Of two pairs closer than the window's
//    resolution (1 / duration), the weaker is dropped.
// 3. Ceres (analytic Jacobian) refines (a_k, b_k, f_k, zeta_k), (B_j, r_j)
//    and c, with a_k = A_k cos phi_k, b_k = -A_k sin phi_k (linear). It sees
//    the window's thousands of residuals through their Jacobian's QR, p + 1
//    rows that give the same steps (signal/qr_compressed_cost.h).
// Uncertainties: s^2 (J^T J)^-1 at the solution, s^2 = residual sum / (N - p),
// i.e. white noise is assumed; a singular J^T J makes `covariance_ok` false.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "model/estimate.h"

namespace impactlab {

struct DampedModeOptions {
  int modes = 2;                 // leading modes fitted jointly, at most
  int decays = 2;                // real decays fitted with them, at most
  int extra_modes = 2;           // pencil order: 2 (modes + extra_modes) + decays (+1 offset)
  bool fit_offset = true;        // a constant c (accelerometer bias, static deflection)
  double min_term_snr = 50.0;    // a term's energy over the window, in noise variances, to keep it
  int pencil_max_samples = 300;  // the pencil's samples (block averages), at most
  double pencil_fraction = 1.0 / 3.0;  // pencil parameter L as a fraction of its samples
  double max_frequency_hz = 0.0;       // modes above are ignored; 0: from the window's spectrum
  int max_iterations = 100;            // Ceres iterations
  double function_tolerance = 1e-12;   // Ceres' relative cost change to stop (default 1e-6)

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("modes", self.modes, "leading modes fitted jointly, at most");
    visit("decays", self.decays, "real decays fitted with them, at most");
    visit("extra_modes", self.extra_modes, "extra pencil order");
    visit("fit_offset", self.fit_offset, "fit a constant offset");
    visit("min_term_snr", self.min_term_snr, "a term's energy in noise variances to keep it");
    visit("pencil_max_samples", self.pencil_max_samples, "the pencil's samples, at most");
    visit("pencil_fraction", self.pencil_fraction, "pencil parameter as a fraction of samples");
    visit("max_frequency_hz", self.max_frequency_hz, "modes above are ignored, Hz (0: auto)");
    visit("max_iterations", self.max_iterations, "Ceres iterations");
    visit("function_tolerance", self.function_tolerance, "relative cost change to stop");
  }

  bool Check(std::string* error) const;
};

struct DampedMode {
  Estimate frequency_hz;              // damped frequency f
  Estimate damping_ratio;             // zeta
  Estimate amplitude;                 // A at the window start, units
  Estimate phase_rad;                 // phi at the window start
  double natural_frequency_hz = 0.0;  // f / sqrt(1 - zeta^2)
  double decay_rate_per_s = 0.0;      // sigma
  double energy = 0.0;                // sum of the mode's squared samples in the window, units^2
};

struct RealDecay {
  Estimate amplitude;   // B at the window start, units
  Estimate rate_per_s;  // r
};

struct DampedModeFit {
  bool ok = false;
  std::string reason;                    // why not ok
  std::string note;                      // an ok fit's caveat (e.g. fewer modes than asked)
  std::vector<DampedMode> modes;         // by decreasing energy
  std::vector<RealDecay> decays;         // by decreasing energy
  std::vector<DampedMode> pencil_modes;  // the starting values (no uncertainties)
  Estimate offset;                       // c, units
  double residual_rms = 0.0;             // units
  int samples = 0;
  int iterations = 0;
  bool covariance_ok = false;  // J^T J invertible at the solution
  double fit_ms = 0.0;         // pencil + Ceres wall time
};

// Throws std::invalid_argument for bad options or a rate <= 0; a window too
// short for the modes asked, or a fit that fails, is a result with !ok.
DampedModeFit FitDampedModes(std::span<const double> samples, double sample_rate_hz,
                             const DampedModeOptions& options);

// The pencil alone: its oscillating modes by decreasing energy, with amplitudes
// from linear least squares, before the significance test (tests, benchmarks).
std::vector<DampedMode> MatrixPencilModes(std::span<const double> samples, double sample_rate_hz,
                                          const DampedModeOptions& options);

}  // namespace impactlab
