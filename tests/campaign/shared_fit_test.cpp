// The shared constants' generalised least squares against closed forms: one
// constant is the weighted mean, its chi^2 and leave-one-out pulls known in
// closed form; a session stating part of the constants; a session far off set
// aside, the others measured against the fit without it.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "campaign/shared_fit.h"

namespace impactlab {
namespace {

constexpr double kNever = std::numeric_limits<double>::infinity();

SessionStatement One(const std::string& name, double y, double sigma) {
  return {name, {y}, {sigma * sigma}, {1.0}, {0}};
}

TEST_CASE("shared fit: one constant is the weighted mean, with its chi2 and pulls") {
  const std::vector<double> y = {1.0, 1.3, 0.8, 1.1}, s = {0.1, 0.2, 0.15, 0.05};
  std::vector<SessionStatement> statements;
  for (std::size_t i = 0; i < y.size(); ++i)
    statements.push_back(One(std::to_string(i), y[i], s[i]));
  const SharedFit fit = FitSharedConstants(statements, 1, kNever);
  REQUIRE(fit.ok);
  double w = 0, wy = 0;
  for (std::size_t i = 0; i < y.size(); ++i) w += 1 / (s[i] * s[i]), wy += y[i] / (s[i] * s[i]);
  const double mean = wy / w;
  CHECK(fit.values[0] == Approx(mean).epsilon(1e-12));
  CHECK(fit.sigma[0] == Approx(1 / std::sqrt(w)).epsilon(1e-12));
  double chi2 = 0;
  for (std::size_t i = 0; i < y.size(); ++i) chi2 += std::pow((y[i] - mean) / s[i], 2);
  CHECK(fit.chi2 == Approx(chi2).epsilon(1e-12));
  CHECK(fit.dof == 3);
  CHECK(fit.birge_ratio == Approx(std::sqrt(chi2 / 3)).epsilon(1e-12));
  REQUIRE(fit.pull.size() == 4);
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double wi = w - 1 / (s[i] * s[i]);
    const double others = (wy - y[i] / (s[i] * s[i])) / wi;
    CHECK(fit.pull[i] == Approx((y[i] - others) / std::sqrt(s[i] * s[i] + 1 / wi)).epsilon(1e-10));
  }
  CHECK(fit.set_aside.empty());
}

TEST_CASE("shared fit: two correlated constants, and a session stating the second alone") {
  // Two sessions state both (correlated); a third states only the second.
  std::vector<SessionStatement> statements = {
      {"a", {2.0, 5.0}, {0.04, 0.01, 0.01, 0.09}, {1, 0, 0, 1}, {0, 1}},
      {"b", {2.2, 5.3}, {0.04, -0.01, -0.01, 0.09}, {1, 0, 0, 1}, {0, 1}},
      {"c", {4.9}, {0.01}, {0, 1}, {1}},
  };
  const SharedFit fit = FitSharedConstants(statements, 2, kNever);
  REQUIRE(fit.ok);
  CHECK(fit.dof == 3);
  // The normal equations by hand (2 x 2 inverses).
  const auto inv = [](double a, double b, double d) {
    const double det = a * d - b * b;
    return std::vector<double>{d / det, -b / det, -b / det, a / det};
  };
  const std::vector<double> ia = inv(0.04, 0.01, 0.09), ib = inv(0.04, -0.01, 0.09);
  const double a00 = ia[0] + ib[0], a01 = ia[1] + ib[1], a11 = ia[3] + ib[3] + 100.0;
  const double b0 = ia[0] * 2.0 + ia[1] * 5.0 + ib[0] * 2.2 + ib[1] * 5.3;
  const double b1 = ia[2] * 2.0 + ia[3] * 5.0 + ib[2] * 2.2 + ib[3] * 5.3 + 100.0 * 4.9;
  const double det = a00 * a11 - a01 * a01;
  CHECK(fit.values[0] == Approx((a11 * b0 - a01 * b1) / det).epsilon(1e-12));
  CHECK(fit.values[1] == Approx((a00 * b1 - a01 * b0) / det).epsilon(1e-12));
  CHECK(fit.sigma[1] == Approx(std::sqrt(a00 / det)).epsilon(1e-12));
}

TEST_CASE("shared fit: a session far off is set aside and the others agree") {
  std::vector<SessionStatement> statements;
  const std::vector<double> y = {1.00, 1.02, 0.97, 1.01, 0.99, 1.03, 1.6};
  for (std::size_t i = 0; i < y.size(); ++i)
    statements.push_back(One(std::to_string(i), y[i], 0.02));
  const SharedFit fit = FitSharedConstants(statements, 1, 3.0);
  REQUIRE(fit.ok);
  CHECK(fit.set_aside == std::vector<std::string>{"6"});
  CHECK(fit.values[0] == Approx((1.00 + 1.02 + 0.97 + 1.01 + 0.99 + 1.03) / 6));
  CHECK(fit.dof == 5);
  for (std::size_t k = 0; k < fit.pull.size(); ++k) {
    INFO(fit.pull_session[k]);
    CHECK((std::abs(fit.pull[k]) > 3.0) == (fit.pull_session[k] == "6"));
  }
}

TEST_CASE("shared fit: fewer than two sessions, or constants left free, fit nothing") {
  CHECK_FALSE(FitSharedConstants({One("a", 1.0, 0.1)}, 1, kNever).ok);
  const SharedFit free = FitSharedConstants(
      {{"a", {1.0}, {0.01}, {1, 0}, {0}}, {"b", {1.1}, {0.01}, {1, 0}, {0}}}, 2, kNever);
  CHECK_FALSE(free.ok);
  CHECK(free.reason == "the sessions' statements do not fix every constant");
  CHECK_THROWS_AS(
      FitSharedConstants({One("a", 1.0, 0.1), {"b", {1.0}, {-1.0}, {1}, {0}}}, 1, kNever),
      std::invalid_argument);
}

TEST_CASE("shared fit: the pull threshold holds the campaign's false alarms, and is 3 or more") {
  CHECK(PullThreshold(1, 0.01) == 3.0);
  // 0.01 / (2 * 1000): the normal tail beyond 4.4172.
  CHECK(PullThreshold(1000, 0.01) == Approx(4.4172).epsilon(1e-4));
}

}  // namespace
}  // namespace impactlab
