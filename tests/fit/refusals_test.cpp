// Failure as a value (issue 33, item 4): data a fit or the model refuses is
// a result with the reason, never thrown; only a caller's slip (options, a
// pair outside the measured rebounds, columns of different lengths) throws.
#include <cmath>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "fit/contact_law_fit.h"
#include "fit/kelvin_voigt_response.h"
#include "fit/kelvin_voigt_session.h"
#include "fit/kelvin_voigt_two_point.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using testing::kBarMass;
using testing::kG;

const Pendulum kThesis{22.0, kG, PendulumConvention::kThesis};
const Pendulum kExact{22.0, kG, PendulumConvention::kExact};

KelvinVoigtTwoPointFit FitOf(const Pendulum& p, const std::vector<double>& xmax) {
  ReboundMeasurements m;
  m.xmax = xmax;
  m.contact_time = 353e-6;
  return FitKelvinVoigtTwoPoint(p, kBarMass, m, {{0, 1}});
}

TEST_CASE("refusals: PredictRun gives the thesis's Table 4 rows, or why not, as a value") {
  // Thesis convention: X is linear in the speed, so a restitution e predicts
  // X_n = X_start e^(n - start) exactly.
  const std::vector<double> source_xmax = {0.3, 0.24}, target_xmax = {0.5, 0.41, 0.33};
  const KelvinVoigtTwoPointFit source = FitOf(kThesis, source_xmax);
  const KelvinVoigtTwoPointFit target = FitOf(kThesis, target_xmax);
  REQUIRE(source.ok);
  REQUIRE(target.ok);
  const PredictedRun predicted = PredictRun(kThesis, "s", source, "t", target_xmax, target, 1);
  REQUIRE(predicted.ok);
  CHECK(predicted.reason.empty());
  const double e = std::exp(source.log_restitution.value);
  REQUIRE(predicted.prediction.predicted.size() == 2);
  CHECK(predicted.prediction.predicted[0] == Approx(0.41).epsilon(1e-12));
  CHECK(predicted.prediction.predicted[1] == Approx(0.41 * e).epsilon(1e-12));

  const PredictedRun beyond = PredictRun(kThesis, "s", source, "t", target_xmax, target, 3);
  CHECK_FALSE(beyond.ok);
  CHECK(beyond.reason == "start_rebound 3 is not a measured rebound of run t (0..2)");
  CHECK(beyond.prediction.source_run == "s");
  CHECK(beyond.prediction.target_run == "t");
  CHECK(beyond.prediction.predicted.empty());

  const KelvinVoigtTwoPointFit growing = FitOf(kThesis, {0.3, 0.31});
  REQUIRE_FALSE(growing.ok);
  const PredictedRun unfitted = PredictRun(kThesis, "s", growing, "t", target_xmax, target, 0);
  CHECK_FALSE(unfitted.ok);
  CHECK(unfitted.reason == "cannot predict run t from run s: s has no Kelvin-Voigt fit");
}

TEST_CASE("refusals: a two-point fit refuses maxima no swing reaches, as a value") {
  ReboundMeasurements m;
  m.xmax = {0.3, -0.2, 0.1};
  KelvinVoigtTwoPointFit fit = FitKelvinVoigtTwoPoint(kExact, kBarMass, m, {{0, 2}});
  CHECK_FALSE(fit.ok);
  CHECK(fit.reason == "rebound 1 maximum must be a positive number, got -0.2");
  CHECK(TwoPointRefusal(kExact, m, {{0, 2}}) == fit.reason);
  // A pair maximum at L: the model's own words.
  m.xmax = {kExact.length, 1.0};
  fit = FitKelvinVoigtTwoPoint(kExact, kBarMass, m, {{0, 1}});
  CHECK_FALSE(fit.ok);
  CHECK(fit.reason == SwingAmplitudeProblem(kExact, kExact.length));
  // Rebound 0 extrapolated back from a strongly damped late pair passes the
  // horizontal: v(X_a) e^-a > 2 sqrt(gL) sin 45 deg.
  m.xmax = {1.0, 1.0, 1.0, 15.0, 1.5};
  fit = FitKelvinVoigtTwoPoint(kExact, kBarMass, m, {{3, 4}});
  CHECK_FALSE(fit.ok);
  CHECK_THAT(fit.reason, Catch::Contains("would pass the horizontal"));
  // A pair without dissipation keeps its own reason.
  m.xmax = {0.2, 0.3};
  CHECK(TwoPointRefusal(kExact, m, {{0, 1}}).empty());
  CHECK_THAT(FitKelvinVoigtTwoPoint(kExact, kBarMass, m, {{0, 1}}).reason,
             Catch::Contains("no dissipation"));
  // A pair outside the measured rebounds is the caller's slip.
  CHECK_THROWS_AS(TwoPointRefusal(kExact, m, {{0, 2}}), std::invalid_argument);
}

TEST_CASE("refusals: the model's figures of a run say why they cannot be drawn") {
  // e = 1/2 per impact over 30 impacts back to the release: v0 2^30 passes the horizontal.
  const std::vector<double> xmax = {0.3, 0.15};
  const KelvinVoigtTwoPointFit fit = FitOf(kExact, xmax);
  REQUIRE(fit.ok);
  const FittedRun far{xmax, 0.5, 30};
  CHECK_THAT(ModelPeakTimesProblem(kExact, far, fit), Catch::Contains("would pass the horizontal"));
  CHECK_THAT(ModelResponseProblem(kExact, far, fit), Catch::Contains("would pass the horizontal"));
  CHECK_THROWS_AS(ModelPeakTimes(kExact, far, fit), std::domain_error);
  const FittedRun near{xmax, 0.5, 1};
  CHECK(ModelPeakTimesProblem(kExact, near, fit).empty());
  CHECK(ModelResponseProblem(kExact, near, fit).empty());
  // The problem is PredictMaximum's, in its words.
  CHECK(PredictMaximumProblem(kExact, 0.3, 0, -30, fit.log_restitution.value) ==
        ModelResponseProblem(kExact, far, fit));
}

LawRun MakeLawRun(const std::string& name, double x0, std::vector<double> xmax) {
  LawRun run;
  run.name = name;
  run.pendulum = kExact;
  run.mass = kBarMass;
  run.initial_displacement = x0;
  run.measured.xmax_sigma.assign(xmax.size(), 0.001);
  run.measured.xmax = std::move(xmax);
  return run;
}

TEST_CASE("refusals: a contact law the runs cannot take is a fit that did not run, with why") {
  ContactLawFitOptions options;
  options.use_contact_times = false;
  const std::vector<LawRun> one = {MakeLawRun("a", 0.5, {0.4, 0.3})};
  ContactLawFit fit = FitContactLaw(ContactLawKind::kHertz, one, options);
  CHECK_FALSE(fit.ok);
  CHECK_FALSE(fit.status.Ran());
  CHECK(fit.law == "hertz");
  CHECK(fit.reason == "a contact law needs two runs or more, got 1");
  std::vector<LawRun> runs = {MakeLawRun("a", 0.5, {0.4, 0.3}), MakeLawRun("b", 0.4, {0.3, NAN})};
  fit = FitContactLaw(ContactLawKind::kHuntCrossley, runs, options);
  CHECK_FALSE(fit.ok);
  CHECK(fit.law == "hunt-crossley");
  CHECK(fit.reason == "run 'b': fewer than two read maxima");
  runs[1] = MakeLawRun("b", 0.4, {0.3, 0.2});
  runs[1].measured.xmax_sigma[1] = 0.0;
  fit = FitContactLaw(ContactLawKind::kHertz, runs, options);
  CHECK(fit.reason == "run 'b': maximum 1 needs a value and a sigma > 0");
  // A non-positive mass is the caller's slip (the manifest refuses it).
  runs[1] = MakeLawRun("b", 0.4, {0.3, 0.2});
  runs[1].mass = 0.0;
  CHECK_THROWS_AS(FitContactLaw(ContactLawKind::kHertz, runs, options), std::invalid_argument);
}

}  // namespace
}  // namespace impactlab
