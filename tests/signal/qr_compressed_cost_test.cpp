// Tests of the QR-compressed cost: the p + 1 rows it hands Ceres give the full
// problem's cost, gradient, Gauss-Newton matrix and Levenberg-Marquardt steps
// (Ceres's dense QR's, computed here on both), so a fit on them ends where one
// on all the rows ends; a point evaluated again is answered from the one kept,
// not computed anew. (Not Ceres itself: its problem.h brings glog's CHECK.)
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "signal/qr_compressed_cost.h"

namespace impactlab {
namespace {

// y = B exp(-r t) + c at t = i / 100: blocks (B, r) and (c), Jacobian
// column-major.
struct Decay {
  std::vector<double> y;
  int* evaluations = nullptr;  // counts the full evaluations, when set

  bool operator()(double const* const* p, double* residuals, double* jacobian) const {
    if (evaluations) ++*evaluations;
    const auto n = y.size();
    for (std::size_t i = 0; i < n; ++i) {
      const double t = 0.01 * static_cast<double>(i);
      const double e = std::exp(-p[0][1] * t);
      residuals[i] = p[0][0] * e + p[1][0] - y[i];
      if (jacobian) {
        jacobian[i] = e;
        jacobian[n + i] = -t * p[0][0] * e;
        jacobian[2 * n + i] = 1.0;
      }
    }
    return true;
  }
};

Decay NoisyDecay(std::size_t n, double noise) {
  Decay decay;
  std::mt19937 random(7);
  std::normal_distribution<double> normal(0.0, noise);
  for (std::size_t i = 0; i < n; ++i) {
    decay.y.push_back(2.0 * std::exp(-1.5 * 0.01 * static_cast<double>(i)) + 0.3 + normal(random));
  }
  return decay;
}

// A Levenberg-Marquardt step as Ceres's dense QR takes it: the least-squares
// solution of [J; sqrt(mu) D] d = -[r; 0].
Eigen::VectorXd Step(const Eigen::MatrixXd& j, const Eigen::VectorXd& r, double mu) {
  const Eigen::Index rows = j.rows(), p = j.cols();
  Eigen::MatrixXd a(rows + p, p);
  a << j, std::sqrt(mu) * Eigen::MatrixXd(j.colwise().norm().asDiagonal());
  Eigen::VectorXd b = Eigen::VectorXd::Zero(rows + p);
  b.head(rows) = -r;
  return a.householderQr().solve(b);
}

// The compressed rows of `cost` at `p`: residuals and Jacobian (p + 1 rows).
std::pair<Eigen::Vector4d, Eigen::Matrix<double, 4, 3>> Compressed(const QrCompressedCost& cost,
                                                                   const double* const* p) {
  Eigen::Vector4d residuals;
  Eigen::Matrix<double, 4, 2, Eigen::RowMajor> j0;
  Eigen::Vector4d j1;
  double* jacobians[] = {j0.data(), j1.data()};
  REQUIRE(cost.Evaluate(p, residuals.data(), jacobians));
  Eigen::Matrix<double, 4, 3> jacobian;
  jacobian << j0, j1;
  return {residuals, jacobian};
}

TEST_CASE("The p + 1 rows carry the full problem's cost, gradient, J^T J and steps",
          "[qr_compressed_cost]") {
  const std::size_t n = 500;
  const Decay decay = NoisyDecay(n, 0.05);
  const std::array<double, 2> b_r = {1.7, 1.2};
  const double c = 0.25;
  const double* p[] = {b_r.data(), &c};
  Eigen::VectorXd r(n);
  Eigen::MatrixXd j(n, 3);
  decay(p, r.data(), j.data());

  const QrCompressedCost cost(static_cast<int>(n), {2, 1}, decay);
  REQUIRE(cost.num_residuals() == 4);
  const auto [residuals, jacobian] = Compressed(cost, p);

  CHECK(residuals.squaredNorm() == Approx(r.squaredNorm()).epsilon(1e-13));
  const Eigen::Vector3d gradient = jacobian.transpose() * residuals;
  const Eigen::Vector3d full_gradient = j.transpose() * r;
  CHECK((gradient - full_gradient).norm() < 1e-12 * full_gradient.norm());
  const Eigen::Matrix3d normal = jacobian.transpose() * jacobian;
  const Eigen::Matrix3d full_normal = j.transpose() * j;
  CHECK((normal - full_normal).norm() < 1e-13 * full_normal.norm());
  CHECK(jacobian.row(3).isZero(0.0));  // rho depends on nothing to first order
  CHECK(jacobian(1, 0) == 0.0);        // R is upper triangular
  CHECK(jacobian(2, 0) == 0.0);
  CHECK(jacobian(2, 1) == 0.0);
  // Levenberg-Marquardt's steps, from Gauss-Newton's (mu 0) to short ones.
  for (const double mu : {0.0, 1e-3, 1.0, 1e3}) {
    const Eigen::VectorXd step = Step(jacobian, residuals, mu);
    const Eigen::VectorXd full_step = Step(j, r, mu);
    CHECK((step - full_step).norm() < 1e-12 * full_step.norm());
  }

  // A trial point's cost alone: the whole norm in the last residual.
  const std::array<double, 2> other = {1.6, 1.2};
  const double* q[] = {other.data(), &c};
  Eigen::VectorXd r_other(n);
  decay(q, r_other.data(), nullptr);
  Eigen::Vector4d cost_only;
  REQUIRE(cost.Evaluate(q, cost_only.data(), nullptr));
  CHECK(cost_only.head<3>().isZero(0.0));
  CHECK(cost_only(3) == Approx(r_other.norm()).epsilon(1e-14));
}

TEST_CASE("Gauss-Newton on the compressed rows reaches the truth", "[qr_compressed_cost]") {
  const std::size_t n = 800;
  const QrCompressedCost cost(static_cast<int>(n), {2, 1}, NoisyDecay(n, 0.0));
  std::array<double, 2> b_r = {1.0, 1.0};
  double c = 0.0;
  const double* p[] = {b_r.data(), &c};
  for (int iteration = 0; iteration < 30; ++iteration) {
    const auto [residuals, jacobian] = Compressed(cost, p);
    const Eigen::VectorXd step = Step(jacobian, residuals, 0.0);
    b_r[0] += step(0);
    b_r[1] += step(1);
    c += step(2);
  }
  CHECK(b_r[0] == Approx(2.0).epsilon(1e-12));
  CHECK(b_r[1] == Approx(1.5).epsilon(1e-12));
  CHECK(c == Approx(0.3).epsilon(1e-12));
}

TEST_CASE("A point evaluated again is answered from the one kept", "[qr_compressed_cost]") {
  const std::size_t n = 300;
  int evaluations = 0;
  Decay decay = NoisyDecay(n, 0.05);
  decay.evaluations = &evaluations;
  const QrCompressedCost cost(static_cast<int>(n), {2, 1}, decay);
  std::array<double, 2> b_r = {1.7, 1.2};
  double c = 0.25;
  const double* p[] = {b_r.data(), &c};
  Eigen::Vector4d first, again, cost_only;
  Eigen::Matrix<double, 4, 2, Eigen::RowMajor> j0, j0_again;
  Eigen::Vector4d j1, j1_again;
  double* jacobians[] = {j0.data(), j1.data()};
  double* jacobians_again[] = {j0_again.data(), j1_again.data()};
  REQUIRE(cost.Evaluate(p, first.data(), jacobians));
  REQUIRE(cost.Evaluate(p, cost_only.data(), nullptr));
  REQUIRE(cost.Evaluate(p, again.data(), jacobians_again));
  CHECK(evaluations == 1);
  CHECK(cost_only == first);
  CHECK(again == first);
  CHECK(j0_again == j0);
  CHECK(j1_again == j1);

  c = 0.26;  // a new point is evaluated
  REQUIRE(cost.Evaluate(p, again.data(), jacobians_again));
  CHECK(evaluations == 2);
  CHECK(again != first);
}

TEST_CASE("Fewer rows than parameters plus one are refused", "[qr_compressed_cost]") {
  CHECK_THROWS_AS(QrCompressedCost(3, {2, 1}, Decay{}), std::invalid_argument);
}

}  // namespace
}  // namespace impactlab
