// The truth's modes: the poles of a phase's equations (synth/beam_model_internal.h).
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <utility>

#include <Eigen/LU>

#include "synth/beam_model_internal.h"

namespace impactlab::beam_internal {
namespace {

using Complex = std::complex<double>;
constexpr double kPi = std::numbers::pi;

// By LU with partial pivoting rather than Eigen's cofactor formula for small
// matrices: it is backward stable, which the Newton steps below need near a
// root, and it gives an exact 0 for the free flight's singular K.
template <typename Matrix>
typename Matrix::Scalar Determinant(const Matrix& a) {
  return Eigen::PartialPivLU<Matrix>(a).determinant();
}

}  // namespace

// The polynomial's coefficients by interpolation on a circle, its roots by
// Durand-Kerner iteration, each root polished by Newton on the determinant.
std::vector<BeamPole> Poles(const Eigen::MatrixXd& mass, const Eigen::MatrixXd& damping,
                            const Eigen::MatrixXd& stiffness) {
  const auto degree = static_cast<std::size_t>(2 * mass.rows());
  // s = scale u keeps |u| ~ 1: the roots' geometric mean when K is regular.
  const double det_k = Determinant(stiffness), det_m = Determinant(mass);
  const double scale = det_k > 0.0 ? std::pow(det_k / det_m, 1.0 / static_cast<double>(degree))
                                   : std::sqrt(stiffness.trace() / mass.trace());
  const Eigen::MatrixXcd m = mass.cast<Complex>(), c = damping.cast<Complex>(),
                         k = stiffness.cast<Complex>();
  auto det_s = [&](Complex s) { return Determinant(Eigen::MatrixXcd(m * s * s + c * s + k)); };
  auto det = [&](Complex u) { return det_s(scale * u); };

  const std::size_t points = degree + 1;
  Eigen::VectorXcd nodes(points), values(points);
  for (std::size_t j = 0; j < points; ++j) {
    nodes[j] = std::polar(1.0, 2.0 * kPi * static_cast<double>(j) / static_cast<double>(points));
    values[j] = det(nodes[j]);
  }
  // The discrete Fourier transform of the values on the unit circle.
  Eigen::VectorXcd coefficient = Eigen::VectorXcd::Zero(points);
  for (std::size_t p = 0; p < points; ++p) {
    for (std::size_t j = 0; j < points; ++j) {
      coefficient[p] += values[j] * std::pow(std::conj(nodes[j]), static_cast<double>(p));
    }
    coefficient[p] /= static_cast<double>(points);
  }
  auto polynomial = [&](Complex u) {  // monic, by Horner
    Complex v = 0.0;
    for (std::size_t p = points; p-- > 0;) v = v * u + coefficient[p] / coefficient[degree];
    return v;
  };
  std::vector<Complex> roots(degree);
  for (std::size_t i = 0; i < degree; ++i) roots[i] = std::pow(Complex(0.4, 0.9), double(i));
  for (int iteration = 0; iteration < 2000; ++iteration) {
    double change = 0.0;
    for (std::size_t i = 0; i < degree; ++i) {
      Complex denominator = 1.0;
      for (std::size_t j = 0; j < degree; ++j) {
        if (j != i) denominator *= roots[i] - roots[j];
      }
      const Complex step = polynomial(roots[i]) / denominator;
      roots[i] -= step;
      change = std::max(change, std::abs(step));
    }
    if (change < 1e-15) break;
  }
  std::vector<BeamPole> modes;
  for (const Complex& u : roots) {
    // Newton on the determinant itself: the coefficients lose digits when the
    // roots spread over decades, the determinant does not.
    Complex s = scale * u;
    for (int iteration = 0; iteration < 8 && std::abs(s) > 0.0; ++iteration) {
      const Complex h = 1e-7 * std::abs(s);
      const Complex slope = (det_s(s + h) - det_s(s - h)) / (2.0 * h);
      if (std::abs(slope) == 0.0) break;
      const Complex step = det_s(s) / slope;
      s -= step;
      if (std::abs(step) <= 1e-15 * std::abs(s)) break;
    }
    // The rigid rotation's root at 0 is no mode; a conjugate pair counts once.
    if (!(std::abs(s) > 1e-6 * scale) || s.imag() < -1e-9 * std::abs(s)) continue;
    BeamPole mode;
    const bool real = std::abs(s.imag()) <= 1e-9 * std::abs(s);
    mode.frequency_hz = real ? 0.0 : s.imag() / (2.0 * kPi);
    mode.natural_frequency_hz = std::abs(s) / (2.0 * kPi);
    mode.damping_ratio = real ? 1.0 : -s.real() / std::abs(s);
    mode.decay_rate_per_s = -s.real();
    modes.push_back(mode);
  }
  std::sort(modes.begin(), modes.end(), [](const BeamPole& a, const BeamPole& b) {
    return std::pair(a.frequency_hz, a.decay_rate_per_s) <
           std::pair(b.frequency_hz, b.decay_rate_per_s);
  });
  return modes;
}

}  // namespace impactlab::beam_internal
