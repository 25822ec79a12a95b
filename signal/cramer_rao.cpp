#include "signal/cramer_rao.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>

namespace impactlab {

CramerRaoBound DampedCosineCrb(const DampedCosine& signal, double sample_rate_hz,
                               std::size_t samples, double noise_sigma, bool decay_known) {
  if (!(signal.damping_ratio >= 0.0 && signal.damping_ratio < 1.0) || !(sample_rate_hz > 0.0) ||
      !(noise_sigma > 0.0) || samples < 4) {
    throw std::invalid_argument("DampedCosineCrb: need 0 <= zeta < 1, rate > 0, noise > 0, N >= 4");
  }
  const double two_pi = 2.0 * std::numbers::pi;
  const double a = signal.amplitude, zeta = signal.damping_ratio;
  const double omega = two_pi * signal.frequency_hz;
  const double root = std::sqrt(1.0 - zeta * zeta);
  const double sigma = omega * zeta / root;
  const double dsigma_df = two_pi * zeta / root;             // zeta held
  const double dsigma_dzeta = omega / (root * root * root);  // f held
  const int p = decay_known ? 3 : 4;

  // F = J^T J accumulated row by row: N can be large.
  Eigen::MatrixXd fisher = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd row(p);
  for (std::size_t n = 0; n < samples; ++n) {
    const double t = static_cast<double>(n) / sample_rate_hz;
    const double e = std::exp(-sigma * t);
    const double c = std::cos(omega * t + signal.phase_rad);
    const double s = std::sin(omega * t + signal.phase_rad);
    const double y = a * e * c;
    const double dy_domega = -a * e * t * s;  // decay rate held
    const double dy_dsigma = -t * y;
    row(0) = e * c;
    row(1) = -a * e * s;
    row(2) = two_pi * dy_domega + (decay_known ? 0.0 : dy_dsigma * dsigma_df);
    if (!decay_known) row(3) = dy_dsigma * dsigma_dzeta;
    fisher.noalias() += row * row.transpose();
  }
  fisher /= noise_sigma * noise_sigma;
  const Eigen::MatrixXd inverse = fisher.ldlt().solve(Eigen::MatrixXd::Identity(p, p));
  CramerRaoBound bound;
  bound.amplitude = std::sqrt(inverse(0, 0));
  bound.phase_rad = std::sqrt(inverse(1, 1));
  bound.frequency_hz = std::sqrt(inverse(2, 2));
  bound.damping_ratio = decay_known ? 0.0 : std::sqrt(inverse(3, 3));
  return bound;
}

double ToneFrequencyCrbCyclesPerSample(std::size_t samples, double eta) {
  const double n = static_cast<double>(samples);
  const double two_pi = 2.0 * std::numbers::pi;
  return std::sqrt(12.0 / (two_pi * two_pi * eta * n * (n * n - 1.0)));
}

}  // namespace impactlab
