// The secant covariance (fit/secant_covariance.h) against least-squares
// problems whose honest covariance is known in closed form.
#include <cmath>
#include <optional>
#include <vector>

#include <catch2/catch.hpp>

#include "fit/secant_covariance.h"

namespace impactlab {
namespace {

constexpr int kRows = 1000;

// A linear model with one well and one weakly determined parameter: column 0
// all ones, column 1 a zero-mean ramp 0.05 sqrt(12) high, so (A^T A)^-1 is
// diagonal with sigmas 1 / sqrt(1000) and about 1 / (0.05 sqrt(1000)) = 0.632
// (exactly 1 / |column 1|, WeakSigma).
Eigen::MatrixXd Design() {
  Eigen::MatrixXd a(kRows, 2);
  for (int k = 0; k < kRows; ++k) {
    a(k, 0) = 1.0;
    a(k, 1) = 0.05 * std::sqrt(12.0) * ((k + 0.5) / kRows - 0.5);
  }
  return a;
}

double WeakSigma() { return 1.0 / Design().col(1).norm(); }

// Residuals A x plus a ripple of amplitude `ripple` and wavenumber
// `wavenumber` in parameter 1, a different phase in every row: a rough
// small-scale response on a smooth cost.
Eigen::VectorXd Residuals(const Eigen::MatrixXd& a, const Eigen::VectorXd& x, double ripple,
                          double wavenumber) {
  Eigen::VectorXd r = a * x;
  for (int k = 0; k < kRows; ++k) r(k) += ripple * std::sin(wavenumber * x(1) + 2.399963 * k);
  return r;
}

Eigen::MatrixXd PointJacobian(const Eigen::MatrixXd& a, const Eigen::VectorXd& x, double ripple,
                              double wavenumber) {
  Eigen::MatrixXd j = a;
  for (int k = 0; k < kRows; ++k)
    j(k, 1) += ripple * wavenumber * std::cos(wavenumber * x(1) + 2.399963 * k);
  return j;
}

ResidualsAtPoints Evaluator(const Eigen::MatrixXd& a, double ripple, double wavenumber,
                            int* calls = nullptr) {
  return [=](const std::vector<Eigen::VectorXd>& points) {
    std::vector<std::optional<Eigen::VectorXd>> out;
    for (const Eigen::VectorXd& x : points) out.emplace_back(Residuals(a, x, ripple, wavenumber));
    if (calls) *calls += static_cast<int>(points.size());
    return out;
  };
}

TEST_CASE("Linear residuals: the secant covariance is (J^T J)^-1 after one round",
          "[secant_covariance]") {
  const Eigen::MatrixXd a = Design();
  const Eigen::VectorXd x = Eigen::Vector2d(0.3, -1.2);
  const SecantCovariance c = SecantCovarianceAt(x, a, Evaluator(a, 0.0, 0.0));
  const Eigen::MatrixXd exact = (a.transpose() * a).inverse();
  CHECK(c.rounds == 1);
  CHECK(c.evaluations == 4);
  for (int i = 0; i < 2; ++i) {
    CHECK(c.determined[static_cast<std::size_t>(i)]);
    CHECK(c.sigma_ratios[static_cast<std::size_t>(i)] == Approx(1.0).epsilon(1e-9));
    for (int j = 0; j < 2; ++j) CHECK(c.covariance(i, j) == Approx(exact(i, j)).margin(1e-12));
  }
}

TEST_CASE("A rough small-scale ripple: the secants find the smooth cost's sigma",
          "[secant_covariance]") {
  // The ripple's slope (1e-3 x 1e3 = 1 per row) dwarfs the weak column's
  // (0.05): the Jacobian at the point says parameter 1 is known to ~0.045,
  // but the minimum moves with the noise on the smooth cost's scale,
  // 1 / (0.05 sqrt(1000)) = 0.632, and there the ripple averages out.
  const Eigen::MatrixXd a = Design();
  const double ripple = 1e-3, wavenumber = 1e3;
  const Eigen::VectorXd x = Eigen::Vector2d(0.3, -1.2);
  const Eigen::MatrixXd j = PointJacobian(a, x, ripple, wavenumber);
  const Eigen::MatrixXd point = (j.transpose() * j).inverse();
  const double honest = WeakSigma();
  REQUIRE(std::sqrt(point(1, 1)) < honest / 5.0);  // the Jacobian's sigma is far too small

  int calls = 0;
  const SecantCovariance c = SecantCovarianceAt(x, j, Evaluator(a, ripple, wavenumber, &calls));
  CHECK(std::sqrt(c.covariance(1, 1)) == Approx(honest).epsilon(0.02));
  CHECK(std::sqrt(c.covariance(0, 0)) == Approx(1.0 / std::sqrt(double(kRows))).epsilon(0.02));
  // The steps end at about 2 sigma of the direction: the secants span many
  // ripples.
  const std::size_t weak = c.singular_values(0) > c.singular_values(1) ? 1 : 0;
  CHECK(c.steps[weak] == Approx(2.0 * honest).epsilon(0.3));
  CHECK(c.sigma_ratios[weak] > 5.0);
  CHECK(c.rounds <= 4);
  CHECK(calls == c.evaluations);
}

TEST_CASE("An undetermined direction gets no secants and no variance", "[secant_covariance]") {
  // Columns 1 and 2 equal: only their sum is fixed.
  Eigen::MatrixXd a(kRows, 3);
  a.leftCols(2) = Design();
  a.col(2) = a.col(1);
  const Eigen::VectorXd x = Eigen::Vector3d(0.3, -1.2, 0.4);
  const SecantCovariance c = SecantCovarianceAt(x, a, Evaluator(a, 0.0, 0.0));
  CHECK(c.determined == std::vector<bool>{true, true, false});
  CHECK(c.evaluations == 4);
  const Eigen::VectorXd along = c.directions.col(2);  // ~ (0, 0.71, -0.71)
  CHECK(std::abs(along(1) + along(2)) < 1e-9);
  CHECK((c.covariance * along).norm() < 1e-9);
  // The sum's variance is the two-parameter problem's.
  const Eigen::Vector3d sum(0.0, 1.0, 1.0);
  const double honest = WeakSigma();
  CHECK(std::sqrt(sum.dot(c.covariance * sum)) == Approx(honest).epsilon(1e-9));
}

TEST_CASE("A secant point that cannot be evaluated keeps the Jacobian's response",
          "[secant_covariance]") {
  const Eigen::MatrixXd a = Design();
  const Eigen::VectorXd x = Eigen::Vector2d(0.3, -1.2);
  // Parameter 1 cannot go above -1.2 + 0.1: the weak direction's secant fails.
  const ResidualsAtPoints bounded = [&](const std::vector<Eigen::VectorXd>& points) {
    std::vector<std::optional<Eigen::VectorXd>> out;
    for (const Eigen::VectorXd& p : points) {
      if (p(1) > -1.1)
        out.emplace_back(std::nullopt);
      else
        out.emplace_back(a * p);
    }
    return out;
  };
  const SecantCovariance c = SecantCovarianceAt(x, a, bounded);
  const std::size_t weak = c.singular_values(0) > c.singular_values(1) ? 1 : 0;
  CHECK(c.secant_failed[weak]);
  CHECK_FALSE(c.secant_failed[1 - weak]);
  const Eigen::MatrixXd exact = (a.transpose() * a).inverse();
  CHECK(c.covariance(1, 1) == Approx(exact(1, 1)).epsilon(1e-9));
}

TEST_CASE("The secants' Gauss-Newton step goes to the smooth cost's minimum, past the ripple",
          "[secant_covariance]") {
  // Residuals A (x - x*) plus the ripple: from 0.8 sigma off along the weak
  // parameter, the point Jacobian's step is led by the ripple's slope; the
  // secants' lands within a few hundredths of a sigma of x*.
  const Eigen::MatrixXd a = Design();
  const double ripple = 1e-3, wavenumber = 1e3;
  const Eigen::VectorXd best = Eigen::Vector2d(0.3, -1.2);
  const double honest = WeakSigma();
  const Eigen::VectorXd x = best + Eigen::Vector2d(0.0, 0.8 * honest);
  const Eigen::VectorXd offset = a * best;
  const ResidualsAtPoints shifted = [&](const std::vector<Eigen::VectorXd>& points) {
    std::vector<std::optional<Eigen::VectorXd>> out;
    for (const Eigen::VectorXd& p : points)
      out.emplace_back(Residuals(a, p, ripple, wavenumber) - offset);
    return out;
  };
  const Eigen::MatrixXd j = PointJacobian(a, x, ripple, wavenumber);
  const Eigen::VectorXd r = Residuals(a, x, ripple, wavenumber) - offset;
  const Eigen::VectorXd point_step = -(j.transpose() * j).ldlt().solve(j.transpose() * r);
  CHECK(std::abs(x(1) + point_step(1) - best(1)) > 0.5 * honest);  // the ripple misleads it

  const SecantCovariance c = SecantCovarianceAt(x, j, shifted);
  const Eigen::VectorXd step = SecantStep(c, r);
  CHECK(std::abs(x(1) + step(1) - best(1)) < 0.05 * honest);
  CHECK(std::abs(x(0) + step(0) - best(0)) < 0.05 / std::sqrt(double(kRows)));
  // Rows scaled by 1: the same step.
  CHECK((SecantStep(c, r, Eigen::VectorXd::Ones(kRows)) - step).norm() < 1e-12);
}

}  // namespace
}  // namespace impactlab
