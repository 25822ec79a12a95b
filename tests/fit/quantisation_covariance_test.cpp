// An encoder's whole counts in a least-squares fit: over the grid's phases,
// the fitted values scatter about the truth as the computed covariance says,
// where counting the counts' error as white noise understates it.
#include "fit/quantisation_covariance.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

namespace impactlab {
namespace {

// Over the draws, each parameter's RMS error against the RMS of its
// computed sigma: the computed covariance's worse ratio (as a factor >= 1,
// too small or too large alike), and white noise's smaller one.
struct LinePulls {
  double quantisation_rms = 0.0;  // from QuantisationScoreCovariance, >= 1
  double white_rms = 0.0;         // from sigma^2 (J^T J)^-1, sigma = step / sqrt 12
};

// An angle a + b t creeping through a few counts over the record, read by
// an encoder of step 1 whose grid lies at a random phase; a + b t fitted to
// the readings at the counts' centres.
LinePulls FitLines(int n, double counts_crossed, int draws) {
  const double step = 1.0, a = 0.3, b = counts_crossed;
  const double sigma = step / std::sqrt(12.0);
  Eigen::MatrixXd j(n, 2);
  for (int i = 0; i < n; ++i) j.row(i) << 1.0, static_cast<double>(i) / n;
  const Eigen::MatrixXd whitened = j / sigma;
  const Eigen::MatrixXd bread = (whitened.transpose() * whitened).inverse();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> phase(0.0, 1.0);
  double scatter[2] = {0.0, 0.0}, variance[2] = {0.0, 0.0}, white[2] = {0.0, 0.0};
  for (int d = 0; d < draws; ++d) {
    const double u = phase(rng);
    Eigen::VectorXd readings(n);
    for (int i = 0; i < n; ++i) {
      const double theta = a + b * j(i, 1);
      readings(i) = (std::floor(theta / step + u) - u + 0.5) * step;
    }
    const Eigen::Vector2d fitted = (j.transpose() * j).ldlt().solve(j.transpose() * readings);
    std::vector<double> angle(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
      angle[static_cast<std::size_t>(i)] = fitted(0) + fitted(1) * j(i, 1);
    const Eigen::MatrixXd meat = QuantisationScoreCovariance(whitened, angle, step, sigma);
    const Eigen::MatrixXd covariance = bread * meat * bread;
    const Eigen::Vector2d error = fitted - Eigen::Vector2d(a, b);
    for (int k = 0; k < 2; ++k) {
      scatter[k] += std::pow(error(k), 2) / draws;
      variance[k] += covariance(k, k) / draws;
      white[k] += bread(k, k) / draws;
    }
  }
  LinePulls out;
  for (int k = 0; k < 2; ++k) {
    out.quantisation_rms =
        std::max(out.quantisation_rms, std::abs(std::log(std::sqrt(scatter[k] / variance[k]))));
    out.white_rms =
        std::min(out.white_rms > 0 ? out.white_rms : 1e300, std::sqrt(scatter[k] / white[k]));
  }
  out.quantisation_rms = std::exp(out.quantisation_rms);
  return out;
}

TEST_CASE("an encoder's counts give honest sigmas where the angle creeps through a few counts",
          "[fit][quantisation]") {
  // Three counts in 2000 samples: the reading's error is a sawtooth ~700
  // samples long, so the samples are far from independent readings.
  const LinePulls pulls = FitLines(2000, 3.0, 400);
  CHECK(pulls.quantisation_rms < 1.2);
  CHECK(pulls.white_rms > 5.0);
}

TEST_CASE("an encoder's counts give honest sigmas where the angle sweeps many counts",
          "[fit][quantisation]") {
  // 0.354 counts a sample. (At exactly 0.35, 7 in 20, the error repeats
  // every 20 samples and the slope's scatter nearly vanishes.)
  const LinePulls pulls = FitLines(2000, 707.1, 400);
  CHECK(pulls.quantisation_rms < 1.2);
}

}  // namespace
}  // namespace impactlab
