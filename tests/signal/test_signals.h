// Synthetic signals for the signal tests: sums of damped cosines with known
// parameters, white Gaussian noise from a fixed seed.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

namespace impactlab::testing {

struct Tone {
  double amplitude = 1.0;
  double phase_rad = 0.0;
  double frequency_hz = 1.0;  // damped
  double damping_ratio = 0.0;
};

// y_n = offset + sum A e^(-sigma t) cos(2 pi f t + phi), t = n / rate.
inline std::vector<double> DampedCosines(const std::vector<Tone>& tones, double rate_hz,
                                         std::size_t n, double offset = 0.0) {
  std::vector<double> y(n, offset);
  for (const Tone& tone : tones) {
    const double omega = 2.0 * std::numbers::pi * tone.frequency_hz;
    const double zeta = tone.damping_ratio;
    const double sigma = omega * zeta / std::sqrt(1.0 - zeta * zeta);
    for (std::size_t i = 0; i < n; ++i) {
      const double t = static_cast<double>(i) / rate_hz;
      y[i] += tone.amplitude * std::exp(-sigma * t) * std::cos(omega * t + tone.phase_rad);
    }
  }
  return y;
}

inline void AddNoise(std::vector<double>& y, double sigma, std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  std::normal_distribution<double> normal(0.0, sigma);
  for (double& v : y) v += normal(engine);
}

}  // namespace impactlab::testing
