// Numerical-stability tests for the closed-form two-point Kelvin-Voigt fit
// (fit/kelvin_voigt_two_point.h, thesis eq. 34-38): two rebound maxima that
// differ only in their last digits, over X/L from 1e-9 to 0.9, in both
// pendulum conventions and both separation conventions.
//
// The references are computed here in long double (64-bit mantissa), without
// calling the code under test and without cancellation: the speed ratio of
// the two maxima is taken apart analytically,
//   exact:  v_b/v_a = (X_b/X_a) sqrt((1 + c_a)/(1 + c_b)),  c = sqrt(1 - (X/L)^2),
//   thesis: v_b/v_a = (X_b/X_a) sin(y)/y,                    y = X_b/(2L),
// with X_b - X_a exact and c_a - c_b = (u_b - u_a)(u_b + u_a)/(c_a + c_b), so
// ln(v_b/v_a) is correct to ~1e-19 relative even where X_b/X_a = 1 - 1e-15.
//
// Conditioning: Lambda = 2 ln(v_b/v_a) has relative condition number
// ~ (|d ln v_a/d ln X_a| + |d ln v_b/d ln X_b|) / |ln(v_b/v_a)| ~ 2/|ln(X_b/X_a)|
// with respect to the measured maxima: a pair 1e-12 apart allows ~1e-3 relative
// error, a well separated pair ~1e-15. Every result must be within 4 cond eps.
//
// Set IMPACTLAB_STABILITY_REPORT=1 to print the worst errors at exit.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "tests/support/precision.h"
#include "tests/support/references.h"

#include "fit/kelvin_voigt_two_point.h"
#include "model/contact.h"
#include "model/pendulum.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using namespace testing;

template <class F>
double LogDerivative(F f, LD x) {
  const LD step = 1e-6L * fabsl(x);
  return static_cast<double>(x * (f(x + step) - f(x - step)) / (2.0L * step * f(x)));
}

// sin(y)/y - 1 by its series for small y.
LD SincMinusOne(LD y) {
  if (fabsl(y) <= 1e-2L) {
    const LD y2 = y * y;
    return -y2 / 6.0L * (1.0L - y2 / 20.0L * (1.0L - y2 / 42.0L * (1.0L - y2 / 72.0L)));
  }
  return sinl(y) / y - 1.0L;
}

LD RefForceDampingRatio(LD log_e) {
  const auto f = [](LD z) { return -2.0L * z * RefH(z); };
  LD lo = 0.0L, hi = 1.0L;
  while (f(hi) > log_e) hi *= 2.0L;
  for (int i = 0; i < 400 && hi - lo > 1e-21L * hi; ++i) {
    const LD mid = 0.5L * (lo + hi);
    (f(mid) > log_e ? lo : hi) = mid;
  }
  return 0.5L * (lo + hi);
}

// ln(v(X_b) / v(X_a)) for the pendulum's convention, without cancellation.
LD RefLogSpeedRatio(const Pendulum& p, double xa, double xb) {
  const LD L = p.length;
  const LD d = static_cast<LD>(xb) - static_cast<LD>(xa);  // exact
  const LD log_x_ratio = log1pl(d / xa);
  if (p.convention == PendulumConvention::kThesis) {
    // PENDUL: v_a = X_a sqrt(g/L), v_b = 2 sqrt(gL) sin(X_b / 2L).
    return log_x_ratio + log1pl(SincMinusOne(xb / (2.0L * L)));
  }
  const LD ua = xa / L, ub = xb / L;
  const LD ca = sqrtl((1.0L - ua) * (1.0L + ua)), cb = sqrtl((1.0L - ub) * (1.0L + ub));
  const LD ca_minus_cb = (d / L) * (ua + ub) / (ca + cb);
  return log_x_ratio + 0.5L * log1pl(ca_minus_cb / (1.0L + cb));
}

// d ln v / d ln X for the speed the fit uses at X_a (amplitude) and X_b (energy).
double SpeedGain(const Pendulum& p, double x, bool energy_form) {
  const LD L = p.length;
  if (p.convention == PendulumConvention::kThesis) {
    if (!energy_form) return 1.0;
    return LogDerivative([&](LD xx) { return sinl(xx / (2.0L * L)); }, x);
  }
  return LogDerivative([&](LD xx) { return RefHalfAngleSine(xx / L); }, x);
}

struct FitCase {
  Pendulum pendulum;
  Separation separation;
  double xa;
  double gap;  // X_b = X_a (1 - gap)
  int impacts;
};

// Runs the fit on rebounds 0 and N and checks every estimate against the
// long double references with its own condition number.
void CheckFit(const FitCase& fc) {
  const Pendulum& p = fc.pendulum;
  const double xa = fc.xa;
  const double xb = xa * (1.0 - fc.gap);
  const int n_impacts = fc.impacts;
  const double tau = 1.2e-4;  // s, a contact time
  ReboundMeasurements m;
  for (int n = 0; n <= n_impacts; ++n) m.xmax.push_back(n == n_impacts ? xb : xa);
  m.contact_time = tau;
  TwoPointOptions options;
  options.rebounds = {0, n_impacts};
  options.separation = fc.separation;
  const KelvinVoigtTwoPointFit fit = FitKelvinVoigtTwoPoint(p, kBarMass, m, options);

  const std::string tag =
      std::string(p.convention == PendulumConvention::kExact ? "exact" : "thesis") + "/" +
      SeparationName(fc.separation) + ": ";
  INFO(tag << "X_a/L = " << xa / p.length << ", 1 - X_b/X_a = " << fc.gap << ", N = " << n_impacts);
  REQUIRE(fit.ok);

  const LD log_ratio = RefLogSpeedRatio(p, xa, xb);
  const LD log_e = log_ratio / n_impacts;
  // cond of ln e wrt (X_a, X_b, L): the speeds' gains over |ln(v_b/v_a)|, plus 1
  // for the rounding of the result.
  const double gain_a = std::abs(SpeedGain(p, xa, false));
  const double gain_b = std::abs(SpeedGain(p, xb, true));
  const double gain_l = std::abs(gain_a - gain_b);  // L enters both speeds
  const double cond_log_e =
      1.0 + (gain_a + gain_b + gain_l) / static_cast<double>(fabsl(log_ratio));
  CheckRel(tag + "ln e", fit.log_restitution.value, log_e,
           /*max_rel_error=*/4 * cond_log_e * kEps, fc.gap, "1 - Xb/Xa");
  const double cond_e = 1.0 + static_cast<double>(fabsl(log_e)) * cond_log_e;
  CheckRel(tag + "e", fit.restitution.value, expl(log_e), /*max_rel_error=*/4 * cond_e * kEps,
           fc.gap, "1 - Xb/Xa");

  // zeta and its gain d ln zeta / d ln |ln e| (<= 1).
  LD zeta;
  double zeta_gain;
  if (fc.separation == Separation::kKinematic) {
    zeta = -log_e / sqrtl(log_e * log_e + kPiL * kPiL);  // eq. 36 with Lambda = 2 N ln e
    zeta_gain = static_cast<double>(kPiL * kPiL / (log_e * log_e + kPiL * kPiL));
  } else {
    zeta = RefForceDampingRatio(log_e);
    zeta_gain = 1.0 / (1.0 + LogDerivative(RefH, zeta));
  }
  // +2: the inversion's own rounding (or its root finder's tolerance, 2^-50).
  const double cond_zeta = 2.0 + zeta_gain * cond_log_e;
  CheckRel(tag + "zeta", fit.damping_ratio.value, zeta, /*max_rel_error=*/4 * cond_zeta * kEps,
           fc.gap, "1 - Xb/Xa");
  if (cond_zeta < 1e6) {  // well conditioned: the requirement's 1e-9 holds with room
    CHECK(RelErr(fit.damping_ratio.value, zeta) <= 1e-9);
  }

  // K from tau_c and zeta (eq. 37 or the force convention), C = 2 zeta sqrt(K M).
  LD k;
  double k_zeta_gain;  // d ln K / d ln zeta
  if (fc.separation == Separation::kKinematic) {
    k = kBarMass * kPiL * kPiL / (static_cast<LD>(tau) * tau * (1.0L - zeta) * (1.0L + zeta));
    k_zeta_gain = static_cast<double>(2.0L * zeta * zeta / ((1.0L - zeta) * (1.0L + zeta)));
  } else {
    k = kBarMass * (2.0L * RefH(zeta) / tau) * (2.0L * RefH(zeta) / tau);
    k_zeta_gain = 2.0 * std::abs(LogDerivative(RefH, zeta));
  }
  REQUIRE(fit.stiffness.has_value());
  REQUIRE(fit.damping.has_value());
  // cond: M (1), tau_c (2), zeta's error times its gain, 1 for rounding.
  const double cond_k = 4.0 + k_zeta_gain * cond_zeta;
  CheckRel(tag + "K", fit.stiffness->value, k, /*max_rel_error=*/4 * cond_k * kEps, fc.gap,
           "1 - Xb/Xa");
  const double cond_c = 2.0 + cond_zeta + 0.5 * cond_k + 0.5;
  CheckRel(tag + "C", fit.damping->value, 2.0L * zeta * sqrtl(k * kBarMass),
           /*max_rel_error=*/4 * cond_c * kEps, fc.gap, "1 - Xb/Xa");

  // Predicted maxima of rebounds 0..N: the speed at X_a times e^n, back to X.
  REQUIRE(fit.predicted_xmax.size() == static_cast<std::size_t>(n_impacts + 1));
  const LD L = p.length;
  for (int n = 0; n <= n_impacts; ++n) {
    LD x_ref;
    if (p.convention == PendulumConvention::kThesis) {
      x_ref = xa * expl(n * log_e);
    } else {
      const LD k_n = RefHalfAngleSine(xa / L) * expl(n * log_e);
      x_ref = L * sinl(2.0L * RefAsin(k_n));
    }
    const double cond_x = 4.0 + n * static_cast<double>(fabsl(log_e)) * cond_log_e;
    CheckRel(tag + "predicted X_n", fit.predicted_xmax[n].value, x_ref,
             /*max_rel_error=*/4 * cond_x * kEps, fc.gap, "1 - Xb/Xa");
  }
}

std::vector<double> Gaps() {
  // Relative differences from a few ulps to well separated.
  return {8 * kEps, 1e-14, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4, 1e-2, 0.1, 0.3, 0.6};
}

TEST_CASE("stability: two maxima that differ only in the last digits give zeta as conditioned") {
  for (auto convention : {PendulumConvention::kExact, PendulumConvention::kThesis}) {
    const Pendulum p{kL, kG, convention};
    for (Separation s : {Separation::kKinematic, Separation::kForce}) {
      for (double u : {1e-9, 1e-6, 0.068 / 22.0, 0.1, 0.9}) {
        for (double gap : Gaps()) {
          for (int impacts : {1, 4}) CheckFit({p, s, u * kL, gap, impacts});
        }
      }
    }
  }
}

TEST_CASE("stability: the thesis's Table 2 pair fits to ~1e-15") {
  // 0.068 and 0.052 in (the 0.115 in case), L = 22 in: well conditioned
  // (cond ~ 8), so every estimate must be far inside 1e-9.
  for (auto convention : {PendulumConvention::kExact, PendulumConvention::kThesis}) {
    const Pendulum p{kL, kG, convention};
    for (Separation s : {Separation::kKinematic, Separation::kForce}) {
      CheckFit({p, s, 0.068, 1.0 - 0.052 / 0.068, 1});
    }
  }
}

TEST_CASE("stability: X_b >= X_a gives a diagnostic, never NaN") {
  for (auto convention : {PendulumConvention::kExact, PendulumConvention::kThesis}) {
    const Pendulum p{kL, kG, convention};
    for (double u : {1e-9, 3.1e-3, 0.5}) {
      const double xa = u * kL;
      for (double xb : {std::nextafter(xa, 2 * xa), xa * (1 + 1e-12), xa * (1 + 1e-6), 1.5 * xa}) {
        ReboundMeasurements m;
        m.xmax = {xa, xb};
        m.xmax_sigma = {1e-4 * xa, 1e-4 * xa};
        m.contact_time = 1e-4;
        m.contact_time_sigma = 1e-6;
        for (Separation s : {Separation::kKinematic, Separation::kForce}) {
          TwoPointOptions options;
          options.separation = s;
          const KelvinVoigtTwoPointFit fit = FitKelvinVoigtTwoPoint(p, kBarMass, m, options);
          INFO("X_a/L = " << u << ", X_b/X_a - 1 = " << xb / xa - 1);
          CHECK_FALSE(fit.ok);
          CHECK_THAT(fit.reason, Catch::Contains("exceeds") && Catch::Contains("no dissipation"));
          CHECK(std::isfinite(fit.log_restitution.value));
          CHECK(std::isfinite(fit.damping_ratio.value));
          CHECK(std::isfinite(fit.restitution.value));
        }
      }
      // One ulp below X_a: the speeds and the logarithm are monotone, so ln e <= 0
      // (never a spurious e > 1 reported as ok).
      for (double uu : LogSpace(1e-9, 0.9, 300)) {
        const double x = uu * kL;
        ReboundMeasurements m;
        m.xmax = {x, std::nextafter(x, 0.0)};
        const KelvinVoigtTwoPointFit fit = FitKelvinVoigtTwoPoint(p, kBarMass, m, {});
        INFO("X_a/L = " << uu);
        CHECK(fit.ok);
        CHECK(fit.log_restitution.value <= 0.0);
        CHECK(std::isfinite(fit.damping_ratio.value));
      }
      // X_b == X_a (and one ulp below): no NaN, estimates finite, uncertainties finite.
      for (double xb : {xa, std::nextafter(xa, 0.0)}) {
        ReboundMeasurements m;
        m.xmax = {xa, xb};
        m.xmax_sigma = {1e-4 * xa, 1e-4 * xa};
        m.contact_time = 1e-4;
        m.contact_time_sigma = 1e-6;
        for (Separation s : {Separation::kKinematic, Separation::kForce}) {
          TwoPointOptions options;
          options.separation = s;
          const KelvinVoigtTwoPointFit fit = FitKelvinVoigtTwoPoint(p, kBarMass, m, options);
          INFO("X_a/L = " << u << ", X_b = X_a - " << xa - xb << ", "
                          << (convention == PendulumConvention::kExact ? "exact" : "thesis"));
          for (const Estimate& e : {fit.log_restitution, fit.restitution, fit.damping_ratio}) {
            CHECK(std::isfinite(e.value));
            CHECK(std::isfinite(e.sigma));
          }
          if (fit.ok) {
            REQUIRE(fit.stiffness.has_value());
            CHECK(std::isfinite(fit.stiffness->value));
            CHECK(std::isfinite(fit.stiffness->sigma));
            CHECK(std::isfinite(fit.damping->value));
            CHECK(std::isfinite(fit.damping->sigma));
            CHECK(fit.damping_ratio.value >= 0.0);
            for (const Estimate& x : fit.predicted_xmax) CHECK(std::isfinite(x.value));
          }
          if (convention == PendulumConvention::kExact && xb == xa) {
            CHECK(fit.log_restitution.value == 0.0);
            CHECK_THAT(fit.note, Catch::Contains("equal"));
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace impactlab
