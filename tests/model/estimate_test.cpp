#include "model/estimate.h"

#include <cmath>
#include <random>
#include <vector>

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

}  // namespace
}  // namespace impactlab
