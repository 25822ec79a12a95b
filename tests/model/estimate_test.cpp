#include "model/estimate.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

namespace impactlab {
namespace {

// AR(1) noise x_i = rho x_{i-1} + e_i: its autocorrelation at lag k is
// rho^k, so 1 + 2 sum rho^k = (1 + rho) / (1 - rho), the factor by which the
// variance of a mean grows over independent samples.
std::vector<double> Ar1(double rho, std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> e(0.0, 1.0);
  std::vector<double> x(n);
  double state = 0.0;
  for (double& v : x) v = state = rho * state + e(rng);
  return x;
}

TEST_CASE("estimate: independent residuals need no inflation") {
  const double inflation = CorrelationInflation(Ar1(0.0, 20000, 1));
  CHECK(inflation >= 1.0);
  CHECK(inflation < 1.1);
}

TEST_CASE("estimate: AR(1) residuals inflate by (1 + rho) / (1 - rho)") {
  for (double rho : {0.5, 0.8, 0.95}) {
    INFO("rho " << rho);
    const double expected = (1.0 + rho) / (1.0 - rho);
    CHECK(CorrelationInflation(Ar1(rho, 200000, 2)) == Approx(expected).epsilon(0.15));
  }
}

TEST_CASE(
    "uncertainty: runs of equal values, as a scope's quantised record, inflate by the run length") {
  // Each value repeated 10 times: a mean holds n / 10 independent readings.
  std::mt19937 rng(3);
  std::normal_distribution<double> e(0.0, 1.0);
  std::vector<double> x;
  for (int i = 0; i < 5000; ++i) x.insert(x.end(), 10, e(rng));
  CHECK(CorrelationInflation(x) == Approx(10.0).epsilon(0.15));
}

TEST_CASE("estimate: too few or all-zero residuals give 1") {
  CHECK(CorrelationInflation(std::vector<double>{1.0, 1.0, 1.0}) == 1.0);
  CHECK(CorrelationInflation(std::vector<double>(100, 0.0)) == 1.0);
}

// A peak-like fit: n samples over +-1.4 rad of a swing, the model
// a cos t + b sin t + c (the peak fit's amplitude, time and offset,
// linearised); the fitted maximum is a + c.
struct PeakWindow {
  Eigen::MatrixXd jacobian;
  Eigen::VectorXd maximum_weights;  // the maximum's least-squares weights on the samples
};

PeakWindow PeakLikeWindow(int n) {
  PeakWindow w{Eigen::MatrixXd(n, 3), {}};
  for (int i = 0; i < n; ++i) {
    const double t = -1.4 + 2.8 * i / (n - 1);
    w.jacobian.row(i) << std::cos(t), std::sin(t), 1.0;
  }
  const Eigen::Matrix3d normal_inverse = (w.jacobian.transpose() * w.jacobian).inverse();
  w.maximum_weights = w.jacobian * (normal_inverse * Eigen::Vector3d(1.0, 0.0, 1.0));
  return w;
}

// Errors blurred over `width` samples (a Gaussian kernel, unit variance).
Eigen::VectorXd BlurredErrors(int n, double width, std::mt19937& rng) {
  std::normal_distribution<double> e(0.0, 1.0);
  const int half = static_cast<int>(4.0 * width) + 1;
  std::vector<double> kernel;
  double norm = 0.0;
  for (int k = -half; k <= half; ++k) {
    kernel.push_back(std::exp(-0.5 * (k / width) * (k / width)));
    norm += kernel.back() * kernel.back();
  }
  std::vector<double> white(static_cast<std::size_t>(n + 2 * half));
  for (double& v : white) v = e(rng);
  Eigen::VectorXd out(n);
  for (int i = 0; i < n; ++i) {
    double sum = 0.0;
    for (std::size_t k = 0; k < kernel.size(); ++k) sum += kernel[k] * white[i + k];
    out(i) = sum / std::sqrt(norm);
  }
  return out;
}

TEST_CASE("estimate: a fit's errors' autocovariance is recovered from its residuals") {
  // AR(1) errors, rho = 0.8, under a 60-sample fit: the residuals' own
  // lag-0 and lag-1 products fall short of the errors' (1 and 0.8), the
  // fit having followed part of them; the system undoes that on average.
  const int n = 60;
  const PeakWindow w = PeakLikeWindow(n);
  const Eigen::MatrixXd hat_free =
      Eigen::MatrixXd::Identity(n, n) -
      w.jacobian * (w.jacobian.transpose() * w.jacobian).inverse() * w.jacobian.transpose();
  std::mt19937 rng(11);
  std::normal_distribution<double> e(0.0, 1.0);
  double gamma0 = 0.0, gamma1 = 0.0, raw0 = 0.0, raw1 = 0.0;
  const int windows = 400;
  for (int rep = 0; rep < windows; ++rep) {
    Eigen::VectorXd errors(n);
    double state = e(rng);
    for (int i = 0; i < n; ++i) errors(i) = state = 0.8 * state + 0.6 * e(rng);
    const Eigen::VectorXd r = hat_free * errors;
    const std::vector<double> gamma = FitErrorAutocovariance(
        {r.data(), static_cast<std::size_t>(n)},
        {w.jacobian.data(), static_cast<std::size_t>(w.jacobian.size())}, 3, n / 4);
    REQUIRE(gamma.size() >= 2);
    gamma0 += gamma[0] / windows;
    gamma1 += gamma[1] / windows;
    raw0 += r.squaredNorm() / n / windows;
    raw1 += r.head(n - 1).dot(r.tail(n - 1)) / (n - 1) / windows;
  }
  CHECK(gamma0 == Approx(1.0).epsilon(0.08));
  CHECK(gamma1 == Approx(0.8).epsilon(0.10));
  CHECK(raw0 < 0.75);
  CHECK(raw1 < 0.55);
}

// The maximum's pull RMS over many windows of `errors_of`'s errors, its
// sigma from the residuals' inflation alone and from the larger of that and
// the corrected autocovariance's variance.
template <typename Errors>
std::pair<double, double> MaximumPullRms(int n, int windows, Errors errors_of) {
  const PeakWindow w = PeakLikeWindow(n);
  const Eigen::MatrixXd fit_of =
      (w.jacobian.transpose() * w.jacobian).inverse() * w.jacobian.transpose();
  double inflated_pull2 = 0.0, corrected_pull2 = 0.0;
  for (int rep = 0; rep < windows; ++rep) {
    const Eigen::VectorXd errors = errors_of();
    const Eigen::Vector3d q = fit_of * errors;
    const Eigen::VectorXd r = errors - w.jacobian * q;
    const double error = q(0) + q(2);
    const double linear = CorrelationInflation({r.data(), static_cast<std::size_t>(n)}) *
                          r.squaredNorm() / (n - 3) * w.maximum_weights.squaredNorm();
    const std::vector<double> gamma = FitErrorAutocovariance(
        {r.data(), static_cast<std::size_t>(n)},
        {w.jacobian.data(), static_cast<std::size_t>(w.jacobian.size())}, 3, std::min(n / 4, 20));
    const double corrected = std::max(
        linear, CorrelatedVariance(gamma, {w.maximum_weights.data(),
                                           static_cast<std::size_t>(w.maximum_weights.size())}));
    inflated_pull2 += error * error / linear / windows;
    corrected_pull2 += error * error / corrected / windows;
  }
  return {std::sqrt(inflated_pull2), std::sqrt(corrected_pull2)};
}

TEST_CASE(
    "estimate: a peak fit's sigma holds for blurred errors where the inflation alone is short") {
  // Errors blurred over 2 samples (a digitized trace's spot), 120-sample
  // windows: the residuals' inflation alone understates the maximum's error
  // (pull RMS ~1.35); the larger of it and the corrected autocovariance's
  // variance comes near 1.
  std::mt19937 rng(12);
  const auto [inflated, corrected] =
      MaximumPullRms(120, 400, [&] { return BlurredErrors(120, 2.0, rng); });
  CHECK(inflated > 1.2);
  CHECK(corrected > 0.9);
  CHECK(corrected < 1.25);
}

TEST_CASE("estimate: white errors' autocovariance is their variance, and their sigma holds") {
  const int n = 120;
  const PeakWindow w = PeakLikeWindow(n);
  const Eigen::MatrixXd hat_free =
      Eigen::MatrixXd::Identity(n, n) -
      w.jacobian * (w.jacobian.transpose() * w.jacobian).inverse() * w.jacobian.transpose();
  std::mt19937 rng(13);
  std::normal_distribution<double> e(0.0, 2.0);
  const auto white = [&] {
    Eigen::VectorXd errors(n);
    for (int i = 0; i < n; ++i) errors(i) = e(rng);
    return errors;
  };
  double gamma0 = 0.0;
  const int windows = 300;
  for (int rep = 0; rep < windows; ++rep) {
    const Eigen::VectorXd r = hat_free * white();
    const std::vector<double> gamma = FitErrorAutocovariance(
        {r.data(), static_cast<std::size_t>(n)},
        {w.jacobian.data(), static_cast<std::size_t>(w.jacobian.size())}, 3, 20);
    REQUIRE(!gamma.empty());
    gamma0 += gamma[0] / windows;
  }
  CHECK(gamma0 == Approx(4.0).epsilon(0.05));
  // Noise's positive lags widen the sigma a little, never much.
  const auto [inflated, corrected] = MaximumPullRms(n, 400, white);
  CHECK(corrected > 0.85);
  CHECK(corrected < 1.1);
}

TEST_CASE("estimate: a fit's residuals that cannot tell give no autocovariance") {
  const PeakWindow w = PeakLikeWindow(10);
  const std::vector<double> zero(10, 0.0);
  CHECK(FitErrorAutocovariance(zero, {w.jacobian.data(), 30}, 3, 5).empty());
  const std::vector<double> short_jacobian(12, 1.0);
  const std::vector<double> some(10, 1.0);
  CHECK(FitErrorAutocovariance(some, short_jacobian, 3, 5).empty());
}

}  // namespace
}  // namespace impactlab
