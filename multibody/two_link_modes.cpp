#include "multibody/two_link_modes.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include <Eigen/Eigenvalues>

#include "multibody/two_link_dynamics.h"

namespace impactlab {

std::vector<VibrationMode> LinearisedModes(const TwoLinkModel& model, const TwoLinkVector& q,
                                           const TwoLinkVector& v, const DriveVoltages& voltages,
                                           bool constrained) {
  const int dependent = constrained ? DependentCoordinate(model, q) : -1;
  std::vector<int> free_coordinates;
  for (int i = 0; i < kTwoLinkCoordinates; ++i) {
    if (i != dependent) free_coordinates.push_back(i);
  }
  const int n = static_cast<int>(free_coordinates.size());
  // The reduced state z = (q_r, v_r) and its rate.
  auto rate = [&](const Eigen::VectorXd& z) {
    TwoLinkVector qz = q, vz = v;
    for (int i = 0; i < n; ++i) {
      qz(free_coordinates[i]) = z(i);
      vz(free_coordinates[i]) = z(n + i);
    }
    TwoLinkVector a;
    if (constrained) {
      CloseLoop(model, dependent, &qz, &vz);
      a = ConstrainedMotion(model, qz, vz, voltages).acceleration;
    } else {
      a = FreeAcceleration(model, qz, vz, voltages);
    }
    Eigen::VectorXd out(2 * n);
    for (int i = 0; i < n; ++i) {
      out(i) = vz(free_coordinates[i]);
      out(n + i) = a(free_coordinates[i]);
    }
    return out;
  };
  Eigen::VectorXd z(2 * n);
  for (int i = 0; i < n; ++i) {
    z(i) = q(free_coordinates[i]);
    z(n + i) = v(free_coordinates[i]);
  }
  Eigen::MatrixXd jacobian(2 * n, 2 * n);
  for (int j = 0; j < 2 * n; ++j) {
    const double h = 1e-7 * std::max(1.0, std::abs(z(j)));
    Eigen::VectorXd up = z, down = z;
    up(j) += h;
    down(j) -= h;
    jacobian.col(j) = (rate(up) - rate(down)) / (2.0 * h);
  }
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(jacobian, false);
  // Rigid-body motions (the arm turning freely in flight) are zero
  // eigenvalues, which the differences split into tiny spurious pairs: left out.
  double largest = 0.0;
  for (const std::complex<double>& s : solver.eigenvalues())
    largest = std::max(largest, std::abs(s));
  std::vector<VibrationMode> oscillatory, real;
  for (const std::complex<double>& s : solver.eigenvalues()) {
    if (s.imag() < 0.0 || std::abs(s) < 1e-6 * largest) continue;
    VibrationMode mode;
    mode.frequency_hz = s.imag() / (2.0 * std::numbers::pi);
    mode.decay_rate_per_s = -s.real();
    mode.damping_ratio = std::abs(s) > 0.0 ? -s.real() / std::abs(s) : 1.0;
    (s.imag() > 1e-9 * std::abs(s) ? oscillatory : real).push_back(mode);
  }
  auto by_frequency = [](const VibrationMode& a, const VibrationMode& b) {
    return a.frequency_hz < b.frequency_hz;
  };
  auto by_decay = [](const VibrationMode& a, const VibrationMode& b) {
    return a.decay_rate_per_s < b.decay_rate_per_s;
  };
  std::sort(oscillatory.begin(), oscillatory.end(), by_frequency);
  std::sort(real.begin(), real.end(), by_decay);
  oscillatory.insert(oscillatory.end(), real.begin(), real.end());
  return oscillatory;
}

}  // namespace impactlab
