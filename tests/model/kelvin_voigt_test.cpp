#include "model/kelvin_voigt.h"

#include <cmath>
#include <numbers>

#include <catch2/catch.hpp>

namespace impactlab {
namespace {

using std::numbers::pi;

TEST_CASE(
    "kelvin_voigt: kinematic separation gives tau_c = pi/wd and e = exp(-pi zeta/sqrt(1-zeta^2))") {
  const KelvinVoigtRates r{1000.0, 0.1};
  const ContactResponse c = KelvinVoigtContact(r, 2.0, Separation::kKinematic);
  const double wd = 1000.0 * std::sqrt(1.0 - 0.01);
  CHECK(c.contact_time == Approx(pi / wd).epsilon(1e-15));
  CHECK(c.restitution == Approx(std::exp(-pi * 0.1 / std::sqrt(0.99))).epsilon(1e-15));
  // The compression is back to zero at tau_c.
  CHECK(KelvinVoigtCompression(r, 2.0, c.contact_time) == Approx(0.0).margin(1e-15));
}

TEST_CASE("kelvin_voigt: force separation ends where K x + C x' = 0 and keeps more speed") {
  const KelvinVoigt m{1.0, 1e6, 2.0 * 0.0709 * 1e3};  // zeta = 0.0709
  const KelvinVoigtRates r = RatesOf(m);
  const ContactResponse kin = KelvinVoigtContact(m, 1.0, Separation::kKinematic);
  const ContactResponse force = KelvinVoigtContact(m, 1.0, Separation::kForce);
  CHECK(kin.restitution == Approx(0.800).margin(5e-4));  // fitting-notes.md
  CHECK(force.restitution == Approx(0.807).margin(1e-3));
  CHECK(force.contact_time < kin.contact_time);
  // Force at separation, by a central difference of x(t).
  const double t = force.contact_time, dt = 1e-9;
  const double x = KelvinVoigtCompression(r, 1.0, t);
  const double xdot =
      (KelvinVoigtCompression(r, 1.0, t + dt) - KelvinVoigtCompression(r, 1.0, t - dt)) / (2 * dt);
  CHECK(std::abs(m.stiffness * x + m.damping * xdot) < 1e-5 * m.damping);
}

TEST_CASE("kelvin_voigt: zeta >= 1 with kinematic separation is a clear error, not NaN") {
  CHECK_THROWS_AS(KelvinVoigtContact(KelvinVoigtRates{100.0, 1.0}, 1.0, Separation::kKinematic),
                  NoSeparationError);
  CHECK_THROWS_WITH(KelvinVoigtContact(KelvinVoigtRates{100.0, 1.5}, 1.0, Separation::kKinematic),
                    Catch::Contains("never") && Catch::Contains("force"));
}

TEST_CASE("kelvin_voigt: force separation is continuous through critical damping") {
  const auto at = [](double zeta) {
    return KelvinVoigtContact(KelvinVoigtRates{100.0, zeta}, 1.0, Separation::kForce);
  };
  const ContactResponse below = at(1.0 - 1e-12), crit = at(1.0), above = at(1.0 + 1e-12);
  // At zeta = 1: tau_c = 2/wn, ln e = -2, peak v/(wn e) at 1/wn.
  CHECK(crit.contact_time == Approx(0.02).epsilon(1e-15));
  CHECK(crit.log_restitution == Approx(-2.0).epsilon(1e-15));
  CHECK(crit.peak_compression == Approx(0.01 / std::exp(1.0)).epsilon(1e-15));
  for (const ContactResponse& c : {below, above}) {
    CHECK(c.contact_time == Approx(crit.contact_time).epsilon(1e-11));
    CHECK(c.log_restitution == Approx(crit.log_restitution).epsilon(1e-11));
  }
}

TEST_CASE("kelvin_voigt: restitution equivalence inverts in both conventions") {
  for (auto sep : {Separation::kKinematic, Separation::kForce}) {
    for (double zeta : {1e-8, 0.01, 0.136, 0.5, 0.999}) {
      const double log_e = LogRestitutionFromDampingRatio(zeta, sep);
      CHECK(DampingRatioFromLogRestitution(log_e, sep) == Approx(zeta).epsilon(1e-13));
    }
  }
  CHECK(DampingRatioFromLogRestitution(LogRestitutionFromDampingRatio(3.0, Separation::kForce),
                                       Separation::kForce) == Approx(3.0).epsilon(1e-13));
  CHECK_THROWS_AS(DampingRatioFromLogRestitution(0.01, Separation::kKinematic), std::domain_error);
}

TEST_CASE("kelvin_voigt: stiffness from contact time inverts the contact model (eq. 37)") {
  const double mass = 2.23 / 385.644;
  for (auto sep : {Separation::kKinematic, Separation::kForce}) {
    const KelvinVoigt m{mass, 462000.0, 7.0};
    const ContactResponse c = KelvinVoigtContact(m, 10.0, sep);
    const double zeta = RatesOf(m).damping_ratio;
    CHECK(StiffnessFromContactTime(mass, c.contact_time, zeta, sep) ==
          Approx(462000.0).epsilon(1e-13));
  }
}

TEST_CASE("kelvin_voigt: peak compression is the maximum of x(t)") {
  for (double zeta : {0.05, 0.7, 1.0, 2.5}) {
    const KelvinVoigtRates r{500.0, zeta};
    const ContactResponse c = KelvinVoigtContact(r, 3.0, Separation::kForce);
    const double peak = KelvinVoigtCompression(r, 3.0, c.peak_time);
    CHECK(peak == Approx(c.peak_compression).epsilon(1e-13));
    CHECK(KelvinVoigtCompression(r, 3.0, 0.99 * c.peak_time) < peak);
    CHECK(KelvinVoigtCompression(r, 3.0, 1.01 * c.peak_time) < peak);
  }
}

}  // namespace
}  // namespace impactlab
