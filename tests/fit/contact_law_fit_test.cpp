// Contact laws fitted across runs recover the law a session was drawn from,
// within their stated uncertainty, and the comparison prefers it.
#include <cmath>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "fit/contact_law_fit.h"
#include "model/kelvin_voigt.h"
#include "model/power_law_contact.h"
#include "synth/law_session.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using testing::kBarMass;
using testing::kPendulum;

std::vector<LawRun> AsLawRuns(const std::vector<LawSessionRun>& drawn) {
  std::vector<LawRun> runs;
  for (const LawSessionRun& d : drawn) {
    LawRun r;
    r.name = std::to_string(d.initial_displacement);
    r.pendulum = kPendulum;
    r.mass = kBarMass;
    r.initial_displacement = d.initial_displacement;
    r.measured.xmax = d.xmax;
    r.measured.xmax_sigma = d.xmax_sigma;
    if (d.contact_time_sigma > 0.0) {
      r.measured.contact_time = d.contact_time;
      r.measured.contact_time_sigma = d.contact_time_sigma;
    }
    r.contact_rebound = d.contact_rebound;
    runs.push_back(r);
  }
  return runs;
}

const NamedEstimate& Parameter(const ContactLawFit& fit, const std::string& name) {
  for (const NamedEstimate& p : fit.parameters) {
    if (p.name == name) return p;
  }
  FAIL("no parameter " << name << " in " << fit.law);
  return fit.parameters.front();
}

double Pull(const NamedEstimate& p, double truth) {
  return (p.estimate.value - truth) / p.estimate.sigma;
}

// A steel-like Hunt-Crossley contact: tau_c ~ 350 us at 1 in/s, e ~ 0.8.
const HuntCrossley kHuntCrossleyTruth{kBarMass, 4.7e7, 1.5, 0.3};

}  // namespace

TEST_CASE("Hunt-Crossley across runs recovers chi and k within their sigmas", "[contact_law]") {
  LawSessionOptions options;
  options.xmax_sigma = 2e-4;
  options.seed = 7;
  const auto runs =
      AsLawRuns(DrawLawSession(kPendulum, HuntCrossleyContactLaw(kHuntCrossleyTruth), options));
  const ContactLawFit fit = FitContactLaw(ContactLawKind::kHuntCrossley, runs, {});
  REQUIRE(fit.ok);
  INFO(fit.identifiability);
  CHECK(std::abs(Pull(Parameter(fit, "damping_factor"), kHuntCrossleyTruth.damping_factor)) < 4.0);
  CHECK(std::abs(Pull(Parameter(fit, "hertz_stiffness"), kHuntCrossleyTruth.stiffness)) < 4.0);
  CHECK(fit.maxima == 30);
  CHECK(fit.contact_times == 6);
  CHECK(fit.dof == 36 - 8);
  CHECK(fit.chi2 / fit.dof < 2.5);
  CHECK_FALSE(fit.scatter.excess);
  CHECK(fit.identifiability.find("k from 6 contact times at 6 speeds") != std::string::npos);
  CHECK(fit.loo_ok);
  CHECK(fit.loo_rms_normalized < 3.0);
}

TEST_CASE("Without contact times only chi is fitted, and the sentence says why k is not",
          "[contact_law]") {
  LawSessionOptions options;
  options.contact_time_sigma = 0.0;
  const auto runs =
      AsLawRuns(DrawLawSession(kPendulum, HuntCrossleyContactLaw(kHuntCrossleyTruth), options));
  const ContactLawFit fit = FitContactLaw(ContactLawKind::kHuntCrossley, runs, {});
  REQUIRE(fit.ok);
  CHECK(fit.parameters.size() == 1);
  CHECK(std::abs(Pull(Parameter(fit, "damping_factor"), kHuntCrossleyTruth.damping_factor)) < 4.0);
  CHECK(fit.identifiability.find("k not determined") != std::string::npos);
}

TEST_CASE("Hunt-Crossley with a free exponent recovers n from contact times at several speeds",
          "[contact_law]") {
  LawSessionOptions options;
  options.contact_time_sigma = 0.5e-6;
  options.seed = 11;
  const auto runs =
      AsLawRuns(DrawLawSession(kPendulum, HuntCrossleyContactLaw(kHuntCrossleyTruth), options));
  const ContactLawFit fit = FitContactLaw(ContactLawKind::kHuntCrossleyExponent, runs, {});
  REQUIRE(fit.ok);
  CHECK(std::abs(Pull(Parameter(fit, "exponent"), 1.5)) < 4.0);
  CHECK(Parameter(fit, "exponent").estimate.sigma < 0.5);
}

TEST_CASE("Kelvin-Voigt across runs recovers zeta and K; the elastic Hertz law is rejected",
          "[contact_law]") {
  const KelvinVoigt truth = KelvinVoigtFromRates(kBarMass, {std::sqrt(4.6e5 / kBarMass), 0.07});
  LawSessionOptions options;
  options.seed = 3;
  const auto runs = AsLawRuns(
      DrawLawSession(kPendulum, KelvinVoigtContactLaw(truth, Separation::kKinematic), options));
  const ContactLawFit kv = FitContactLaw(ContactLawKind::kKelvinVoigt, runs, {});
  REQUIRE(kv.ok);
  CHECK(std::abs(Pull(Parameter(kv, "damping_ratio"), 0.07)) < 4.0);
  CHECK(std::abs(Pull(Parameter(kv, "stiffness"), truth.stiffness)) < 4.0);
  const ContactLawFit hertz = FitContactLaw(ContactLawKind::kHertz, runs, {});
  REQUIRE(hertz.ok);
  CHECK(hertz.scatter.excess);
  CHECK(hertz.bic > kv.bic + 100.0);
}

TEST_CASE("On Hunt-Crossley data with strong speed dependence the comparison prefers it",
          "[contact_law]") {
  HuntCrossley strong = kHuntCrossleyTruth;
  strong.damping_factor = 1.5;  // e from ~0.6 to ~0.9 over the runs' speeds
  LawSessionOptions options;
  options.xmax_sigma = 2e-4;
  options.seed = 5;
  const auto runs = AsLawRuns(DrawLawSession(kPendulum, HuntCrossleyContactLaw(strong), options));
  const ContactLawFit hc = FitContactLaw(ContactLawKind::kHuntCrossley, runs, {});
  const ContactLawFit kv = FitContactLaw(ContactLawKind::kKelvinVoigt, runs, {});
  REQUIRE(hc.ok);
  REQUIRE(kv.ok);
  CHECK(hc.bic + 10.0 < kv.bic);
  CHECK(hc.loo_rms_normalized < kv.loo_rms_normalized);
  CHECK(kv.scatter.excess);
  CHECK(kv.scatter.Scale() > 1.0);
}

}  // namespace impactlab

namespace impactlab {

TEST_CASE("The scatter check: chi2 at its dof keeps the stated errors, far above scales them",
          "[birge]") {
  // P(chi2_20 >= 20) = 0.4579 (tables); P(chi2_20 >= 200) is ~1e-31.
  const ScatterCheck fair = CheckScatter(20.0, 20);
  CHECK(fair.p_value == Approx(0.4579).margin(1e-4));
  CHECK_FALSE(fair.excess);
  CHECK(fair.Scale() == 1.0);
  const ScatterCheck wide = CheckScatter(200.0, 20);
  CHECK(wide.excess);
  CHECK(wide.birge_ratio == Approx(std::sqrt(10.0)));
  CHECK(wide.Scale() == Approx(std::sqrt(10.0)));
  // Just significant: the 99.9 % point of chi2_10 is 29.588.
  CHECK_FALSE(CheckScatter(29.5, 10).excess);
  CHECK(CheckScatter(29.7, 10).excess);
  CHECK_FALSE(CheckScatter(5.0, 0).excess);  // no degrees of freedom: nothing to check
}

}  // namespace impactlab

namespace impactlab {

TEST_CASE("A Hertz spring with a damper across runs recovers c and k within their sigmas",
          "[contact_law]") {
  const HertzDamper truth{kBarMass, 4.7e7, 1.5, 0.6};
  LawSessionOptions options;
  options.xmax_sigma = 2e-4;
  options.seed = 13;
  const auto runs = AsLawRuns(
      DrawLawSession(kPendulum, HertzDamperContactLaw(truth, Separation::kKinematic), options));
  ContactLawFitOptions fit_options;
  fit_options.leave_one_out = false;
  const ContactLawFit fit = FitContactLaw(ContactLawKind::kHertzDamper, runs, fit_options);
  REQUIRE(fit.ok);
  INFO(fit.identifiability);
  CHECK(std::abs(Pull(Parameter(fit, "damping"), truth.damping)) < 4.0);
  CHECK(std::abs(Pull(Parameter(fit, "hertz_stiffness"), truth.stiffness)) < 4.0);
  CHECK(fit.chi2 / fit.dof < 2.5);
  // Without contact times it says why it cannot be fitted.
  LawSessionOptions no_contact = options;
  no_contact.contact_time_sigma = 0.0;
  const ContactLawFit blind = FitContactLaw(
      ContactLawKind::kHertzDamper,
      AsLawRuns(DrawLawSession(kPendulum, HertzDamperContactLaw(truth, Separation::kKinematic),
                               no_contact)),
      fit_options);
  CHECK_FALSE(blind.ok);
  CHECK(blind.reason.find("needs contact times") != std::string::npos);
}

}  // namespace impactlab

namespace impactlab {

TEST_CASE("Each parameter's 68 % interval: linear where chi2 is quadratic, else the profile's",
          "[contact_law]") {
  LawSessionOptions options;
  options.seed = 7;
  const auto runs =
      AsLawRuns(DrawLawSession(kPendulum, HuntCrossleyContactLaw(kHuntCrossleyTruth), options));
  ContactLawFitOptions fit_options;
  fit_options.leave_one_out = false;
  const ContactLawFit fit = FitContactLaw(ContactLawKind::kHuntCrossley, runs, fit_options);
  REQUIRE(fit.ok);
  REQUIRE(fit.intervals.size() == fit.parameters.size());
  for (std::size_t i = 0; i < fit.intervals.size(); ++i) {
    const ParameterInterval& in = fit.intervals[i];
    const Estimate& e = fit.parameters[i].estimate;
    INFO(in.name);
    // Small noise: the profile rises by ~1 at +-1 sigma and the linear interval stands.
    CHECK_FALSE(in.profile);
    CHECK(in.rise_at_lower == Approx(1.0).margin(0.2));
    CHECK(in.rise_at_upper == Approx(1.0).margin(0.2));
    // exp(ln v -+ sigma/v): the log-space interval.
    CHECK(in.lower == Approx(e.value * std::exp(-e.sigma / e.value)).epsilon(1e-9));
    CHECK(in.upper == Approx(e.value * std::exp(e.sigma / e.value)).epsilon(1e-9));
  }
  // Forcing the profile everywhere (tolerance 0+) gives an interval close to the linear one.
  fit_options.profile_tolerance = 1e-9;
  const ContactLawFit profiled = FitContactLaw(ContactLawKind::kHuntCrossley, runs, fit_options);
  REQUIRE(profiled.ok);
  for (std::size_t i = 0; i < profiled.intervals.size(); ++i) {
    const ParameterInterval& in = profiled.intervals[i];
    const ParameterInterval& linear = fit.intervals[i];
    const double width = linear.upper - linear.lower;
    CHECK(in.profile);
    CHECK(std::abs(in.lower - linear.lower) < 0.1 * width);
    CHECK(std::abs(in.upper - linear.upper) < 0.1 * width);
  }
}

}  // namespace impactlab

namespace impactlab {
namespace {

TEST_CASE("What the data can inform: no contact time fixes no k, one speed fixes no n",
          "[contact_law]") {
  LawSessionOptions options;
  options.contact_time_sigma = 0.5e-6;
  options.seed = 11;
  const std::vector<LawRun> timed =
      AsLawRuns(DrawLawSession(kPendulum, HuntCrossleyContactLaw(kHuntCrossleyTruth), options));
  const ContactLawFitOptions fit_options;
  // Contact times at several speeds: every law can be fitted, n among them
  // (the test above recovers it within sigma < 0.5).
  for (const ContactLawKind kind :
       {ContactLawKind::kKelvinVoigt, ContactLawKind::kHertz, ContactLawKind::kHuntCrossley,
        ContactLawKind::kHuntCrossleyExponent, ContactLawKind::kHertzDamper}) {
    INFO(ContactLawName(kind));
    CHECK(ContactLawUninformed(kind, timed, fit_options).empty());
  }
  // Without contact times: the maxima fix zeta and chi, nothing else.
  std::vector<LawRun> untimed = timed;
  for (LawRun& run : untimed) run.measured.contact_time.reset();
  CHECK(ContactLawUninformed(ContactLawKind::kKelvinVoigt, untimed, fit_options).empty());
  CHECK(ContactLawUninformed(ContactLawKind::kHuntCrossley, untimed, fit_options).empty());
  CHECK_THAT(ContactLawUninformed(ContactLawKind::kHertz, untimed, fit_options),
             Catch::Contains("no run has its own contact time"));
  CHECK_THAT(ContactLawUninformed(ContactLawKind::kHertzDamper, untimed, fit_options),
             Catch::Contains("c k^(-1/(n+1))"));
  CHECK_THAT(ContactLawUninformed(ContactLawKind::kHuntCrossleyExponent, untimed, fit_options),
             Catch::Contains("no run has its own contact time"));
  // The maxima alone, by choice: the same.
  ContactLawFitOptions maxima_only;
  maxima_only.use_contact_times = false;
  CHECK_FALSE(ContactLawUninformed(ContactLawKind::kHertz, timed, maxima_only).empty());
  // Every contact time at one speed: k is fixed, n is not.
  std::vector<LawRun> one_speed = timed;
  for (LawRun& run : one_speed) {
    run.initial_displacement = timed.front().initial_displacement;
    run.contact_rebound = -1;  // the release's impact, at the speed X0 gives
  }
  CHECK(ContactLawUninformed(ContactLawKind::kHertz, one_speed, fit_options).empty());
  CHECK_THAT(ContactLawUninformed(ContactLawKind::kHuntCrossleyExponent, one_speed, fit_options),
             Catch::Contains("would fix n to"));
}

}  // namespace
}  // namespace impactlab

namespace impactlab {

TEST_CASE(
    "A damper law whose impact cannot be integrated to an end fails alone with its reason, "
    "and the other laws on the same runs stand",
    "[contact_law]") {
  // Kelvin-Voigt runs at zeta = 0.7 (e ~ 0.046, kinematic separation). The
  // damper starts at beta = 2 zeta = 1.4, past the ~1.215 beyond which its
  // contact never ends under kinematic separation: the integration says so
  // as a value, the fit's solver cannot start, and that fit alone fails.
  const double stiffness = 4.7e5;
  const double critical = 2.0 * std::sqrt(stiffness * kBarMass);
  const KelvinVoigt truth{kBarMass, stiffness, 0.7 * critical};
  LawSessionOptions options;
  options.initial_displacements = {0.3, 0.4, 0.5, 0.6};
  options.maxima = 3;
  options.first_rebound = 0;
  options.xmax_sigma = 1e-5;
  options.seed = 5;
  const std::vector<LawRun> runs = AsLawRuns(
      DrawLawSession(kPendulum, KelvinVoigtContactLaw(truth, Separation::kKinematic), options));
  const HertzDamperScaled start = HertzDamperScaledImpact(1.5, 1.4, Separation::kKinematic, 1e-9);
  CHECK_FALSE(start.ok);
  CHECK_THAT(start.reason, Catch::Contains("had not ended"));
  ContactLawFitOptions fit_options;
  fit_options.leave_one_out = false;
  fit_options.intervals = false;
  const ContactLawFit damper = FitContactLaw(ContactLawKind::kHertzDamper, runs, fit_options);
  CHECK_FALSE(damper.ok);
  CHECK(damper.law == ContactLawName(ContactLawKind::kHertzDamper));
  CHECK_THAT(damper.reason, Catch::StartsWith("the solver failed"));
  const ContactLawFit kelvin_voigt = FitContactLaw(ContactLawKind::kKelvinVoigt, runs, fit_options);
  CHECK(kelvin_voigt.ok);
  const ContactLawFit hertz = FitContactLaw(ContactLawKind::kHertz, runs, fit_options);
  CHECK(hertz.status.Ran());
}

}  // namespace impactlab
