#include <cmath>

#include <catch2/catch.hpp>

#include "fit/kelvin_voigt_session.h"
#include "fit/kelvin_voigt_two_point.h"
#include "fit/pendul.h"
#include "fit/uncertainty.h"
#include "model/kelvin_voigt.h"
#include "model/rebound_history.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using testing::kBarMass;
using testing::kG;

// Ground truth: maxima and contact time simulated by the model from known K, C.
struct Truth {
  KelvinVoigt parameters;
  ReboundSequence sequence;
};
Truth Simulate(const Pendulum& p, double stiffness, double damping, Separation sep, double x0) {
  const KelvinVoigt kv{kBarMass, stiffness, damping};
  return {kv, SimulateRebounds(p, KelvinVoigtContactLaw(kv, sep), x0, 6)};
}

TEST_CASE("two_point: recovers K and C from the model's own maxima for any pair") {
  for (auto convention : {PendulumConvention::kExact, PendulumConvention::kThesis}) {
    for (auto sep : {Separation::kKinematic, Separation::kForce}) {
      const Pendulum p{22.0, kG, convention};
      const Truth truth = Simulate(p, 462000.0, 9.0, sep, 1.2);
      ReboundMeasurements m;
      m.xmax = truth.sequence.xmax;  // PENDUL numbering: list index = rebound
      m.contact_time = truth.sequence.contact.contact_time;
      for (auto pair : {std::array<int, 2>{0, 1}, {1, 3}, {2, 6}}) {
        TwoPointOptions options{pair, sep};
        // PENDUL's fit takes X_b through 1 - cos(X/L) but the model's amplitude
        // is linear: ln e is biased by (X_b/2L)^2/6 per impact, which the
        // extrapolation over six rebounds compounds to ~2e-3.
        const double tol = convention == PendulumConvention::kExact ? 1e-12 : 3e-3;
        const KelvinVoigtTwoPointFit fit = FitKelvinVoigtTwoPoint(p, kBarMass, m, options);
        REQUIRE(fit.ok);
        CHECK(fit.stiffness->value == Approx(462000.0).epsilon(tol));
        CHECK(fit.damping->value == Approx(9.0).epsilon(tol * 10));
        for (std::size_t n = 0; n < m.xmax.size(); ++n) {
          CHECK(fit.predicted_xmax[n].value == Approx(m.xmax[n]).epsilon(tol));
        }
      }
    }
  }
}

TEST_CASE("two_point: equal maxima are the elastic limit (a note), growing maxima a reason") {
  const Pendulum p{22.0, kG, PendulumConvention::kExact};
  ReboundMeasurements m;
  m.xmax = {0.3, 0.3, 0.35};
  m.contact_time = 350e-6;
  KelvinVoigtTwoPointFit equal = FitKelvinVoigtTwoPoint(p, kBarMass, m, {{0, 1}});
  CHECK(equal.ok);
  CHECK(equal.damping_ratio.value == 0.0);
  CHECK(equal.damping->value == 0.0);
  CHECK_THAT(equal.note, Catch::Contains("no measurable dissipation"));
  const KelvinVoigtTwoPointFit grows = FitKelvinVoigtTwoPoint(p, kBarMass, m, {{1, 2}});
  CHECK_FALSE(grows.ok);
  CHECK_THAT(grows.reason, Catch::Contains("exceeds"));
  CHECK_THROWS_AS(FitKelvinVoigtTwoPoint(p, kBarMass, m, {{1, 3}}), std::invalid_argument);
}

TEST_CASE("two_point: uncertainties propagate reading errors linearly") {
  const Pendulum p{22.0, kG, PendulumConvention::kThesis};
  ReboundMeasurements m;
  m.xmax = {0.293, 0.195};
  m.xmax_sigma = {0.0005, 0.0005};
  m.contact_time = 353e-6;
  m.contact_time_sigma = 5e-6;
  const KelvinVoigtTwoPointFit fit = FitKelvinVoigtTwoPoint(p, kBarMass, m, {{0, 1}});
  // Thesis convention, small angles: ln e ~ ln(Xb/Xa), so
  // sigma(ln e) ~ sqrt((sa/Xa)^2 + (sb/Xb)^2).
  const double expected = std::hypot(0.0005 / 0.293, 0.0005 / 0.195);
  CHECK(fit.log_restitution.sigma == Approx(expected).epsilon(1e-3));
  // K ~ 1/tau_c^2 dominates its own uncertainty: 2 sigma_tau/tau.
  CHECK(fit.stiffness->sigma / fit.stiffness->value == Approx(2.0 * 5.0 / 353.0).epsilon(2e-2));
  CHECK(fit.predicted_xmax[0].sigma == Approx(0.0005).epsilon(1e-6));  // passes through X_a
}

TEST_CASE("uncertainty: propagation through a linear map is exact") {
  const auto f = [](const std::vector<double>& x) {
    return std::vector<double>{2.0 * x[0] + 3.0 * x[1], x[1]};
  };
  const std::vector<double> sigma = PropagateUncertainty(f, {1.0, 5.0}, {0.1, 0.2});
  CHECK(sigma[0] == Approx(std::hypot(0.2, 0.6)).epsilon(1e-9));
  CHECK(sigma[1] == Approx(0.2).epsilon(1e-9));
}

TEST_CASE("damping_line: points on C = a (1 - b s) give a and b exactly, with zero scatter") {
  const double a = 77.44, b = 1.014;
  std::vector<double> s = {0.80, 0.82, 0.85, 0.87, 0.90}, c;
  for (double x : s) c.push_back(a * (1.0 - b * x));
  const DampingLineFit fit = FitDampingLine(s, c);
  REQUIRE(fit.ok);
  const DampingLine& line = fit.line;
  CHECK(line.a.value == Approx(a).epsilon(1e-12));
  CHECK(line.b.value == Approx(b).epsilon(1e-12));
  CHECK(line.a.sigma == Approx(0.0).margin(1e-9));
}

TEST_CASE("damping_line: runs of one restitution, or one run, give no line, said as a value") {
  const DampingLineFit equal = FitDampingLine({0.8, 0.8}, {1.0, 2.0});
  CHECK_FALSE(equal.ok);
  CHECK(equal.reason == "the damping line needs runs of different restitution");
  CHECK(equal.line.points == 2);
  const DampingLineFit one = FitDampingLine({0.8}, {1.0});
  CHECK_FALSE(one.ok);
  CHECK_THAT(one.reason, Catch::Contains("at least two runs") && Catch::Contains("got 1"));
  // Columns of different lengths are a caller's slip, not data.
  CHECK_THROWS_AS(FitDampingLine({0.8, 0.9}, {1.0}), std::invalid_argument);
}

TEST_CASE("damping_line: standard errors match the textbook regression formulas") {
  const std::vector<double> s = {0.80, 0.82, 0.85, 0.87, 0.90};
  const std::vector<double> c = {14.1, 12.9, 10.2, 9.0, 6.8};
  const DampingLine line = FitDampingLine(s, c).line;
  // Independent: normal equations, sigma^2 = RSS/(n - 2), var(alpha) = sigma^2 sum(s^2)/(n Sxx).
  double sum_s = 0, sum_c = 0, sum_ss = 0, sum_sc = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    sum_s += s[i];
    sum_c += c[i];
    sum_ss += s[i] * s[i];
    sum_sc += s[i] * c[i];
  }
  const double n = 5.0, det = n * sum_ss - sum_s * sum_s;
  const double beta = (n * sum_sc - sum_s * sum_c) / det, alpha = (sum_c - beta * sum_s) / n;
  double rss = 0;
  for (std::size_t i = 0; i < s.size(); ++i) rss += std::pow(c[i] - alpha - beta * s[i], 2);
  const double var_alpha = rss / (n - 2) * sum_ss / det;
  CHECK(line.a.value == Approx(alpha).epsilon(1e-10));
  CHECK(line.b.value == Approx(-beta / alpha).epsilon(1e-10));
  CHECK(line.a.sigma == Approx(std::sqrt(var_alpha)).epsilon(1e-8));
}

TEST_CASE("pendul: option 3 reproduces option 2 with the fitted parameters") {
  const Pendulum p{22.0, kG, PendulumConvention::kExact};
  ReboundMeasurements m;
  m.xmax = {0.169, 0.110};
  m.contact_time = 353.35e-6;
  const PendulFit fitted = PendulFromMeasurements(p, kBarMass, m, {{0, 1}}, 4);
  CHECK(fitted.response.sequence.xmax[1] == Approx(0.110).epsilon(1e-12));
  const auto predicted = PendulPredict(p, fitted, {0.293}, 4);
  const PendulResponse direct =
      PendulResponseFor(p, fitted.response.parameters, Separation::kKinematic, 0.293, 4);
  CHECK(predicted[0].sequence.xmax == direct.sequence.xmax);
  CHECK(predicted[0].sequence.xmax[1] == Approx(0.1907).margin(5e-4));  // Table 4
}

}  // namespace
}  // namespace impactlab
