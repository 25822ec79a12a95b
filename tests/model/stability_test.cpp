// Numerical-stability tests for model/: the pendulum, Kelvin-Voigt contact and
// the rebound sequence over the full range the project promises (X/L from 1e-9
// to 0.9, zeta from 1e-8 to 0.999 and through zeta = 1, K/M from 1e2 to 1e14).
//
// Every reference is computed here, independently of the code under test, in
// long double (64-bit mantissa, eps 1.1e-19) with series expansions where the
// closed forms lose digits, and with formulas different from the library's
// (atan2 / asinh for acos / acosh, the AGM for K(k), a closed form without
// trigonometry for sin(asin(u)/2), a bisection for inverse functions).
// A few 40-digit values computed offline with Python's mpmath 1.3 check the
// references themselves.
//
// Tolerances: each result must be within a small multiple of
// cond * eps, cond being the problem's relative condition number with respect
// to its inputs (plus one for the rounding of the result itself); where a
// problem is well conditioned that is ~1e-15, far inside the required 1e-9.
//
// Set IMPACTLAB_STABILITY_REPORT=1 to print the worst relative error observed
// per quantity (and its ratio to the tolerance) at exit.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "tests/support/precision.h"
#include "tests/support/references.h"

#include "model/contact.h"
#include "model/kelvin_voigt.h"
#include "model/pendulum.h"
#include "model/rebound_history.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using namespace testing;

// ---------------------------------------------------------------------------
// Long double references.

// sin y: Taylor series for |y| <= 1e-3 (truncation < 1e-33 relative), sinl otherwise.
LD RefSin(LD y) {
  if (fabsl(y) <= 1e-3L) {
    const LD y2 = y * y;
    return y * (1.0L - y2 / 6.0L * (1.0L - y2 / 20.0L * (1.0L - y2 / 42.0L)));
  }
  return sinl(y);
}

// Complete elliptic integral K(k) by the arithmetic-geometric mean:
// K = pi / (2 AGM(1, sqrt(1 - k^2))).
LD RefEllipK(LD k) {
  LD a = 1.0L, b = sqrtl((1.0L - k) * (1.0L + k));
  for (int i = 0; i < 40 && fabsl(a - b) > 1e-19L * a; ++i) {
    const LD next_a = 0.5L * (a + b);
    b = sqrtl(a * b);
    a = next_a;
  }
  return kPiL / (a + b);  // pi / (2 * (a + b)/2)
}

// K(k) = pi/2 sum (binom(2n,n)/4^n)^2 k^(2n): the series, to check the AGM.
LD RefEllipKSeries(LD k) {
  LD sum = 0.0L, power = 1.0L;
  for (int n = 0; n < 60; ++n, power *= k * k) {
    const LD a = CentralBinomialOver4n(n);
    sum += a * a * power;
  }
  return kPiL / 2.0L * sum;
}

// Central-difference logarithmic derivative d ln f / d ln x in long double
// (relative step 1e-6: ~1e-12 relative error, plenty for a condition number).
template <class F>
double LogDerivative(F f, LD x) {
  const LD step = 1e-6L * fabsl(x);
  return static_cast<double>(x * (f(x + step) - f(x - step)) / (2.0L * step * f(x)));
}

// d ln h / d ln zeta: in (-1, 0], analytic through zeta = 1 (value -1/3 there).
double CondH(double zeta) { return LogDerivative(RefH, zeta); }

// x(t) = v t exp(-zeta tau) S(q), tau = wn t, q = tau^2 (1 - zeta^2) and
// S(q) = sin(sqrt q)/sqrt q (sinh(sqrt -q)/sqrt -q for q < 0), by its entire
// series sum (-q)^n / (2n+1)! for |q| <= 1/2: no 0/0 at zeta = 1.
LD RefShape(LD q) {
  if (fabsl(q) <= 0.5L) {
    LD sum = 0.0L, term = 1.0L;
    for (int n = 0; n < 30; ++n) {
      sum += term;
      term *= -q / static_cast<LD>((2 * n + 2) * (2 * n + 3));
    }
    return sum;
  }
  if (q > 0.0L) return sinl(sqrtl(q)) / sqrtl(q);
  return sinhl(sqrtl(-q)) / sqrtl(-q);
}

LD RefCompression(LD wn, LD zeta, LD v, LD t) {
  const LD tau = wn * t;
  const LD q = tau * tau * (1.0L - zeta) * (1.0L + zeta);
  return v * t * expl(-zeta * tau) * RefShape(q);
}

struct KelvinVoigtRefContact {
  LD contact_time, log_restitution, peak_time, peak_compression;
};

// Kelvin-Voigt contact from the definitions: kinematic tau_c = pi/wd and
// ln e = -pi zeta/sqrt(1 - zeta^2); force tau_c = 2 h/wn and ln e = -2 zeta h;
// the peak at t* = h/wn, its height by evaluating x(t*) directly.
KelvinVoigtRefContact RefKelvinVoigt(LD wn, LD zeta, LD v, Separation separation) {
  const LD h = RefH(zeta);
  KelvinVoigtRefContact r{};
  if (separation == Separation::kKinematic) {
    const LD s = sqrtl((1.0L - zeta) * (1.0L + zeta));
    r.contact_time = kPiL / (wn * s);
    r.log_restitution = -kPiL * zeta / s;
  } else {
    r.contact_time = 2.0L * h / wn;
    r.log_restitution = -2.0L * zeta * h;
  }
  r.peak_time = h / wn;
  r.peak_compression = RefCompression(wn, zeta, v, r.peak_time);
  return r;
}

// The damping ratio whose force-separation impact gives ln e: bisection of the
// monotone -2 zeta h(zeta) = ln e in long double.
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

std::string Name(const char* what, Separation s) {
  return std::string("KV ") + SeparationName(s) + ": " + what;
}

// Damping ratios: 1e-8 .. 0.5 log-spaced, then 1 - zeta log-spaced down to
// 1e-3 (0.999), then the approach to critical damping.
std::vector<double> KinematicZetas() {
  std::vector<double> z = LogSpace(1e-8, 0.5, 160);
  for (double gap : LogSpace(0.5, 1e-3, 80)) z.push_back(1.0 - gap);
  for (double gap : {1e-4, 1e-6, 1e-9, 1e-12}) z.push_back(1.0 - gap);
  z.push_back(std::nextafter(1.0, 0.0));
  return z;
}

// Force separation also through zeta = 1 and up to 10: within a few ulps of 1,
// at 1 -/+ 1e-12 ... 1e-6, and log-spaced above.
std::vector<double> ForceZetas() {
  std::vector<double> z = KinematicZetas();
  z.push_back(1.0);
  double up = 1.0, down = 1.0;
  for (int i = 0; i < 8; ++i) {
    up = std::nextafter(up, 2.0);
    down = std::nextafter(down, 0.0);
    z.push_back(up);
    z.push_back(down);
  }
  for (double gap : {1e-12, 1e-9, 1e-6}) z.push_back(1.0 + gap);
  for (double gap : LogSpace(1e-4, 9.0, 80)) z.push_back(1.0 + gap);
  return z;
}

// ===========================================================================
// The references themselves.

TEST_CASE("stability: the long double references agree with 40-digit mpmath values") {
  // mpmath 1.3, mp.dps = 40: h(zeta) at the doubles nearest the given zeta.
  struct HCase {
    double zeta;
    LD h;
  };
  const HCase h_cases[] = {
      {1e-8, 1.570796316794896697771137155492316612708L},
      {0.999, 1.000333466723834932480559144994695313143L},
      {1.0 - 1e-6, 1.00000033333346667630903872279224623643L},
      {1.0 + 1e-6, 0.999999666666800027365047879266074615076L},
      {10.0, 0.300830214985481857784251463446704627136L},
  };
  for (const HCase& c : h_cases) {
    INFO("zeta = " << c.zeta);
    CHECK(RelErr(static_cast<double>(RefH(c.zeta)), c.h) < 2 * kEps);
    CHECK(fabsl(RefH(c.zeta) - c.h) / c.h < 1e-18L);
  }
  CHECK(RefH(1.0L) == 1.0L);

  // mpmath: ellipk(k^2) at k = sin(asin(u)/2), u the double nearest 0.9.
  const LD k = RefHalfAngleSine(static_cast<LD>(0.9));
  CHECK(fabsl(k - 0.5310885545960921433792204767628474417577L) < 1e-18L);
  CHECK(fabsl(RefEllipK(k) / 1.703540761142301465172737364810945785002L - 1.0L) < 1e-18L);

  // The AGM against the series, the closed half-angle sine against sinl(asinl()/2),
  // the asin series against atan2 where both are accurate.
  for (LD kk : {1e-10L, 1e-5L, 1e-2L, 0.1L, 0.3L}) {
    CHECK(fabsl(RefEllipK(kk) / RefEllipKSeries(kk) - 1.0L) < 1e-18L);
  }
  for (LD u : {1e-4L, 1e-3L, 0.1L, 0.5L, 0.9L}) {
    CHECK(fabsl(RefHalfAngleSine(u) / sinl(asinl(u) / 2.0L) - 1.0L) < 1e-18L);
  }
  for (LD u : {1e-6L, 1e-4L, 9.99e-4L}) {
    CHECK(fabsl(RefAsin(u) / atan2l(u, sqrtl(1.0L - u * u)) - 1.0L) < 1e-18L);
  }
  // The h series against the closed forms just outside its range.
  for (LD zeta : {1.0L - 1.0L / 16.0L, 1.0L + 1.0L / 16.0L}) {
    const LD s = sqrtl(fabsl((1.0L - zeta) * (1.0L + zeta)));
    const LD closed = zeta < 1.0L ? atan2l(s, zeta) / s : asinhl(s) / s;
    CHECK(fabsl(RefH(zeta) / closed - 1.0L) < 1e-18L);
    const LD inner = zeta < 1.0L ? zeta + 1e-6L : zeta - 1e-6L;  // inside: the series
    const LD s_in = sqrtl(fabsl((1.0L - inner) * (1.0L + inner)));
    const LD closed_in = inner < 1.0L ? atan2l(s_in, inner) / s_in : asinhl(s_in) / s_in;
    CHECK(fabsl(RefH(inner) / closed_in - 1.0L) < 1e-18L);
  }
  // The compression shape series against sin / sinh at the switch.
  CHECK(fabsl(RefShape(0.5L) / (sinl(sqrtl(0.5L)) / sqrtl(0.5L)) - 1.0L) < 1e-18L);
  CHECK(fabsl(RefShape(-0.5L) / (sinhl(sqrtl(0.5L)) / sqrtl(0.5L)) - 1.0L) < 1e-18L);
}

// ===========================================================================
// 1. Pendulum.

struct PendulumCase {
  double length, gravity;
};
constexpr PendulumCase kPendula[] = {{kL, kG}, {1.0, 9.80665}, {0.37, 9.80665}};

TEST_CASE("stability: exact pendulum keeps full precision from X/L = 1e-9 to 0.9") {
  for (const PendulumCase& pc : kPendula) {
    const Pendulum p{pc.length, pc.gravity, PendulumConvention::kExact};
    const LD L = pc.length, g = pc.gravity;
    for (double u_nominal : LogSpace(1e-9, 0.9, 400)) {
      const double x = u_nominal * pc.length;
      const LD u = static_cast<LD>(x) / L;  // the exact ratio of the doubles

      // theta_m = asin(u); cond = u / (sqrt(1 - u^2) asin u) <= 1.84 at 0.9,
      // and the library rounds u = X/L once.
      const double cond_angle = 1.0 + LogDerivative(RefAsin, u);
      CheckRel("pendulum exact: SwingAngle", SwingAngle(p, x), RefAsin(u),
               /*max_rel_error=*/4 * cond_angle * kEps, u_nominal);

      // v = 2 sqrt(gL) sin(theta_m/2); cond wrt u ~ 1 (1.65 at 0.9) plus g, L.
      const LD v_ref = 2.0L * sqrtl(g * L) * RefHalfAngleSine(u);
      const double cond_speed = 2.0 + LogDerivative(RefHalfAngleSine, u);
      CheckRel("pendulum exact: SpeedFromAmplitude", SpeedFromAmplitude(p, x), v_ref,
               /*max_rel_error=*/4 * cond_speed * kEps, u_nominal);
      CheckRel("pendulum exact: SpeedFromPeakEnergy", SpeedFromPeakEnergy(p, x), v_ref,
               /*max_rel_error=*/4 * cond_speed * kEps, u_nominal);

      // X from v: X = L sin(2 asin k), k = v / (2 sqrt(gL)); cond wrt v is
      // (1 - 2k^2)/(1 - k^2) <= 1, plus g, L.
      const double v = static_cast<double>(v_ref);
      const LD k_of_v = static_cast<LD>(v) / (2.0L * sqrtl(g * L));
      const LD x_ref = L * sinl(2.0L * RefAsin(k_of_v));
      const double cond_amplitude = 3.0;
      CheckRel("pendulum exact: AmplitudeFromSpeed", AmplitudeFromSpeed(p, v), x_ref,
               /*max_rel_error=*/4 * cond_amplitude * kEps, u_nominal);
      // Round trip X -> v -> X: the speed's error (<= 4 cond_speed eps) passes
      // through with gain <= 1, plus AmplitudeFromSpeed's own.
      CheckRel("pendulum exact: AmplitudeFromSpeed(SpeedFromAmplitude)",
               AmplitudeFromSpeed(p, SpeedFromAmplitude(p, x)), x,
               /*max_rel_error=*/4 * (cond_speed + cond_amplitude) * kEps, u_nominal);

      // Half period 2 sqrt(L/g) K(sin(theta_m/2)): K varies slowly (cond < 0.3).
      const LD k = RefHalfAngleSine(u);
      const LD t_ref = 2.0L * sqrtl(L / g) * RefEllipK(k);
      const double cond_period =
          2.0 + LogDerivative([](LD uu) { return RefEllipK(RefHalfAngleSine(uu)); }, u);
      CheckRel("pendulum exact: HalfPeriod", HalfPeriod(p, x), t_ref,
               /*max_rel_error=*/4 * cond_period * kEps, u_nominal);
    }
  }
}

TEST_CASE("stability: thesis-convention pendulum keeps full precision from X/L = 1e-9 to 0.9") {
  for (const PendulumCase& pc : kPendula) {
    const Pendulum p{pc.length, pc.gravity, PendulumConvention::kThesis};
    const LD L = pc.length, g = pc.gravity;
    for (double u_nominal : LogSpace(1e-9, 0.9, 400)) {
      const double x = u_nominal * pc.length;
      const LD u = static_cast<LD>(x) / L;
      // theta = X/L: one rounding.
      CheckRel("pendulum thesis: SwingAngle", SwingAngle(p, x), u, /*max_rel_error=*/kEps,
               u_nominal);
      // v = X sqrt(g/L): cond 1 in X, 1/2 in g and L.
      const LD w0 = sqrtl(g / L);
      CheckRel("pendulum thesis: SpeedFromAmplitude", SpeedFromAmplitude(p, x), x * w0,
               /*max_rel_error=*/4 * 2.0 * kEps, u_nominal);
      // Energy form 2 sqrt(gL) sin(theta/2), theta = X/L: 1 - cos never formed.
      const double cond_energy = 2.0 + LogDerivative([](LD th) { return RefSin(th / 2); }, u);
      CheckRel("pendulum thesis: SpeedFromPeakEnergy", SpeedFromPeakEnergy(p, x),
               2.0L * sqrtl(g * L) * RefSin(u / 2.0L),
               /*max_rel_error=*/4 * cond_energy * kEps, u_nominal);
      const double v = static_cast<double>(x * w0);
      CheckRel("pendulum thesis: AmplitudeFromSpeed", AmplitudeFromSpeed(p, v), v / w0,
               /*max_rel_error=*/4 * 2.0 * kEps, u_nominal);
      CheckRel("pendulum thesis: HalfPeriod", HalfPeriod(p, x), kPiL / w0,
               /*max_rel_error=*/4 * 2.0 * kEps, u_nominal);
    }
  }
}

TEST_CASE("stability: speed from a 1e-8 amplitude keeps full precision where 1 - cos fails") {
  // At X/L = 1e-8, cos(X/L) = 1 - 5e-17 rounds to 1: the naive energy form
  // v = sqrt(2 g L (1 - cos(X/L))) returns 0, a 100 % error. The library uses
  // 2 sin^2(theta/2) and keeps every digit in both conventions.
  const double u = 1e-8;
  const double x = u * kL;
  const LD ul = static_cast<LD>(x) / kL;
  const double naive = std::sqrt(2.0 * kG * kL * (1.0 - std::cos(x / kL)));
  const LD ref_thesis = 2.0L * sqrtl(static_cast<LD>(kG) * kL) * RefSin(ul / 2.0L);
  const LD ref_exact = 2.0L * sqrtl(static_cast<LD>(kG) * kL) * RefHalfAngleSine(ul);
  CHECK(naive == 0.0);
  CHECK(RelErr(naive, ref_thesis) == 1.0);  // every digit lost
  CHECK(RelErr(naive, ref_thesis) > 1e-9);
  const Pendulum thesis{kL, kG, PendulumConvention::kThesis};
  const Pendulum exact{kL, kG, PendulumConvention::kExact};
  CheckRel("pendulum thesis: SpeedFromPeakEnergy at X/L = 1e-8", SpeedFromPeakEnergy(thesis, x),
           ref_thesis, /*max_rel_error=*/4 * 2.0 * kEps, u);
  CheckRel("pendulum exact: SpeedFromPeakEnergy at X/L = 1e-8", SpeedFromPeakEnergy(exact, x),
           ref_exact, /*max_rel_error=*/4 * 2.0 * kEps, u);

  // The naive form's error is eps / (X/L)^2 / 2: it already misses 1e-9 below
  // X/L ~ 3e-4, while the library stays at a few eps everywhere.
  for (double uu : LogSpace(1e-9, 1e-4, 40)) {
    const double xx = uu * kL;
    const LD ref = 2.0L * sqrtl(static_cast<LD>(kG) * kL) * RefSin(static_cast<LD>(xx) / kL / 2);
    const double naive_uu = std::sqrt(2.0 * kG * kL * (1.0 - std::cos(xx / kL)));
    INFO("X/L = " << uu);
    CHECK(RelErr(naive_uu, ref) > 1e-9);
    CHECK(RelErr(SpeedFromPeakEnergy(thesis, xx), ref) <= 4 * 2.0 * kEps);
  }
}

TEST_CASE("stability: pendulum functions stay finite at the ends of their domains") {
  for (const PendulumCase& pc : kPendula) {
    for (auto convention : {PendulumConvention::kExact, PendulumConvention::kThesis}) {
      const Pendulum p{pc.length, pc.gravity, convention};
      const double below_l = std::nextafter(pc.length, 0.0);
      for (double x : {0.0, DBL_TRUE_MIN, 1e-300, 1e-9 * pc.length, 0.9 * pc.length, below_l}) {
        INFO("X = " << x << ", L = " << pc.length);
        CHECK(std::isfinite(SwingAngle(p, x)));
        CHECK(std::isfinite(SpeedFromAmplitude(p, x)));
        CHECK(std::isfinite(SpeedFromPeakEnergy(p, x)));
        CHECK(std::isfinite(HalfPeriod(p, x)));
        const double v = SpeedFromAmplitude(p, x);
        CHECK(std::isfinite(AmplitudeFromSpeed(p, v)));
        CHECK(std::isfinite(ReleaseSwingDisplacement(p, x, 0.1 * HalfPeriod(p, x))));
        CHECK(std::isfinite(ReboundDisplacement(p, v, 0.3 * HalfPeriod(p, x))));
      }
      // Out of the domain: a diagnostic, never NaN.
      CHECK_THROWS_AS(SwingAngle(p, pc.length), std::domain_error);
      CHECK_THROWS_AS(SwingAngle(p, -1e-12), std::domain_error);
      CHECK_THROWS_AS(SwingAngle(p, std::nan("")), std::domain_error);
      CHECK_THROWS_AS(AmplitudeFromSpeed(p, -1.0), std::domain_error);
    }
    // Exact: a speed that would pass the horizontal.
    const Pendulum exact{pc.length, pc.gravity, PendulumConvention::kExact};
    CHECK_THROWS_AS(AmplitudeFromSpeed(exact, 2.0 * std::sqrt(pc.gravity * pc.length)),
                    std::domain_error);
  }
}

// ===========================================================================
// 2-3. Kelvin-Voigt.

// Checks one contact against the long double reference. cond_* are the
// relative condition numbers with respect to (wn, zeta, v), with 1 added for
// the rounding of the result; `extra_zeta_eps` counts the ulps of error in
// zeta itself when it was computed from K, M, C (0 for exact rates).
void CheckContact(const ContactResponse& c, LD wn, LD zeta, LD v, Separation s, double input,
                  const std::string& tag, double zeta_error_ulps) {
  const KelvinVoigtRefContact r = RefKelvinVoigt(wn, zeta, v, s);
  const double z = static_cast<double>(zeta);
  const double ch = CondH(z);  // d ln h / d ln zeta
  const double zh = static_cast<double>(zeta * RefH(zeta));
  // Each input's relative error, in eps, beyond its own exact value: rates given
  // directly are exact (1 counts the rounding of the intermediate); from K, M, C
  // both zeta and wn carry ~2 more roundings.
  const double zeta_gain = 1.0 + zeta_error_ulps;
  const double wn_gain = 1.0 + zeta_error_ulps;

  // d ln / d ln zeta of each quantity.
  double c_time, c_log_e;
  if (s == Separation::kKinematic) {
    const double one_minus_z2 = static_cast<double>((1.0L - zeta) * (1.0L + zeta));
    c_time = z * z / one_minus_z2;
    c_log_e = 1.0 / one_minus_z2;
  } else {
    c_time = ch;
    c_log_e = 1.0 + ch;
  }
  const double c_peak_x = zh * std::abs(1.0 + ch);
  const double abs_log_e = static_cast<double>(fabsl(r.log_restitution));

  const double cond_time = 1.0 + wn_gain + zeta_gain * std::abs(c_time);
  CheckRel(Name("contact time", s) + tag, c.contact_time, r.contact_time,
           /*max_rel_error=*/4 * cond_time * kEps, input);
  const double cond_log_e = 1.0 + zeta_gain * std::abs(c_log_e);
  CheckRel(Name("ln e", s) + tag, c.log_restitution, r.log_restitution,
           /*max_rel_error=*/4 * cond_log_e * kEps, input);
  const LD e_ref = expl(r.log_restitution);
  if (e_ref >= DBL_MIN) {  // below that the true e is not a normal double
    // e = exp(ln e): cond = |ln e| cond(ln e), plus exp's own rounding.
    const double cond_e = 1.0 + abs_log_e * zeta_gain * std::abs(c_log_e);
    CheckRel(Name("e", s) + tag, c.restitution, e_ref, /*max_rel_error=*/4 * cond_e * kEps, input);
  } else {
    CHECK(c.restitution >= 0.0);
    CHECK(c.restitution <= 2 * DBL_MIN);
  }
  const double cond_peak_t = 1.0 + wn_gain + zeta_gain * std::abs(ch);
  CheckRel(Name("peak time", s) + tag, c.peak_time, r.peak_time,
           /*max_rel_error=*/4 * cond_peak_t * kEps, input);
  const double cond_peak_x = 2.0 + wn_gain + zeta_gain * c_peak_x;
  CheckRel(Name("peak compression", s) + tag, c.peak_compression, r.peak_compression,
           /*max_rel_error=*/4 * cond_peak_x * kEps, input);
  CHECK(c.separation == s);
}

TEST_CASE("stability: Kelvin-Voigt contact is accurate for zeta from 1e-8 to 0.999 and through 1") {
  const double v = 1.7;
  for (double wn : {10.0, 3.3e3, 1e7}) {
    for (Separation s : {Separation::kKinematic, Separation::kForce}) {
      const std::vector<double> zetas =
          s == Separation::kKinematic ? KinematicZetas() : ForceZetas();
      for (double zeta : zetas) {
        const ContactResponse c = KelvinVoigtContact(KelvinVoigtRates{wn, zeta}, v, s);
        CheckContact(c, wn, zeta, v, s, zeta, "", 0.0);
      }
    }
  }
}

TEST_CASE("stability: force-separation contact is continuous and smooth across zeta = 1") {
  // Slopes at zeta = 1 from the series of h (h = 1 + u/3 + ..., u = 1 - zeta):
  // d(ln e)/d zeta = -2 (h + zeta h') = -4/3, d(wn tau_c)/d zeta = 2 h' = -2/3,
  // d(wn t*)/d zeta = -1/3, d ln(peak wn / v)/d zeta = -(h + h') = -2/3.
  const double wn = 250.0, v = 0.8;
  const auto at = [&](double zeta) {
    return KelvinVoigtContact(KelvinVoigtRates{wn, zeta}, v, Separation::kForce);
  };
  const ContactResponse crit = at(1.0);
  CHECK(crit.log_restitution == -2.0);
  CHECK(RelErr(crit.contact_time, 2.0L / wn) <= kEps);
  CHECK(RelErr(crit.peak_time, 1.0L / wn) <= kEps);
  CHECK(RelErr(crit.peak_compression, v / (wn * expl(1.0L))) <= 2 * kEps);
  for (double delta : {1e-12, 1e-9, 1e-6}) {
    for (double sign : {-1.0, 1.0}) {
      const double zeta = 1.0 + sign * delta;
      const double dz = zeta - 1.0;  // exact
      const ContactResponse c = at(zeta);
      INFO("zeta = 1 + " << dz);
      // Difference from the critical value = slope * dz + O(dz^2) + rounding:
      // checked to within dz^2 + 16 eps of the value (both values carry a few
      // ulps), still ~300 times below the smallest signal, 1e-12.
      const auto near = [&](double got, double crit_value, double slope) {
        const double diff = got - crit_value;
        return std::abs(diff - slope * dz) <=
               dz * dz + 16 * kEps * std::max(1.0, std::abs(crit_value));
      };
      CHECK(near(c.log_restitution, crit.log_restitution, -4.0 / 3.0));
      CHECK(near(c.contact_time * wn, crit.contact_time * wn, -2.0 / 3.0));
      CHECK(near(c.peak_time * wn, crit.peak_time * wn, -1.0 / 3.0));
      CHECK(near(std::log(c.peak_compression / crit.peak_compression), 0.0, -2.0 / 3.0));
    }
  }
  // Monotone through the ulps around 1 (ln e decreasing, tau_c decreasing) up to rounding.
  double z = 1.0;
  for (int i = 0; i < 64; ++i) z = std::nextafter(z, 0.0);
  ContactResponse prev = at(z);
  for (int i = 0; i < 128; ++i) {
    z = std::nextafter(z, 2.0);
    const ContactResponse c = at(z);
    // Each step changes ln e by ~4/3 ulp(1): allow 8 eps of rounding, no jumps.
    CHECK(c.log_restitution <= prev.log_restitution + 8 * kEps * 2.0);
    CHECK(c.contact_time <= prev.contact_time * (1 + 8 * kEps));
    prev = c;
  }
}

TEST_CASE("stability: Kelvin-Voigt from K, M, C is accurate for K/M from 1e2 to 1e14") {
  const double v = 0.35;
  for (double k_over_m : LogSpace(1e2, 1e14, 61)) {
    const double mass = kBarMass;
    const double stiffness = k_over_m * mass;
    for (double zeta_nominal : {1e-8, 0.0709, 0.5, 0.999, 1.0, 3.0}) {
      const double damping = 2.0 * zeta_nominal * std::sqrt(stiffness * mass);
      const KelvinVoigt model{mass, stiffness, damping};
      const LD wn = sqrtl(static_cast<LD>(stiffness) / mass);
      const LD zeta = damping / (2.0L * sqrtl(static_cast<LD>(stiffness) * mass));
      for (Separation s : {Separation::kKinematic, Separation::kForce}) {
        if (s == Separation::kKinematic && zeta_nominal >= 1.0) continue;
        // RatesOf forms zeta and wn with ~2 roundings each: they enter as input errors.
        CheckContact(KelvinVoigtContact(model, v, s), wn, zeta, v, s, k_over_m, " (K, M, C)",
                     /*zeta_error_ulps=*/2.0);
        // The contact law the rebound history uses gives the same numbers.
        const ContactResponse direct = KelvinVoigtContact(model, v, s);
        const ContactResponse law = KelvinVoigtContactLaw(model, s).Respond(v);
        CHECK(law.contact_time == direct.contact_time);
        CHECK(law.log_restitution == direct.log_restitution);
      }
    }
  }
}

TEST_CASE("stability: stiffness from contact time is accurate for K/M from 1e2 to 1e14") {
  const double mass = kBarMass;
  for (double k_over_m : LogSpace(1e2, 1e14, 61)) {
    const LD wn = sqrtl(static_cast<LD>(k_over_m));
    for (Separation s : {Separation::kKinematic, Separation::kForce}) {
      const std::vector<double> zetas =
          s == Separation::kKinematic
              ? std::vector<double>{1e-8, 1e-3, 0.0709, 0.5, 0.9, 0.999, 1.0 - 1e-9}
              : std::vector<double>{1e-8, 0.0709, 0.5, 0.999, 1.0, 1.0 + 1e-9, 2.0, 10.0};
      for (double zeta : zetas) {
        const double tau = static_cast<double>(RefKelvinVoigt(wn, zeta, 1.0L, s).contact_time);
        const LD h = RefH(zeta);
        LD k_ref;
        double c_zeta;  // d ln K / d ln zeta
        if (s == Separation::kKinematic) {
          k_ref = mass * kPiL * kPiL / (static_cast<LD>(tau) * tau * (1.0L - zeta) * (1.0L + zeta));
          c_zeta = static_cast<double>(2.0L * zeta * zeta / ((1.0L - zeta) * (1.0L + zeta)));
        } else {
          k_ref = mass * (2.0L * h / tau) * (2.0L * h / tau);
          c_zeta = 2.0 * CondH(zeta);
        }
        // cond: 1 (M) + 2 (tau_c) + |c_zeta|, plus 1 for the result's rounding.
        const double cond = 4.0 + std::abs(c_zeta);
        const double got = StiffnessFromContactTime(mass, tau, zeta, s);
        CheckRel(Name("StiffnessFromContactTime", s), got, k_ref,
                 /*max_rel_error=*/4 * cond * kEps, k_over_m);
        // And it recovers the K the contact time came from, up to tau's rounding (gain 2).
        CheckRel(Name("StiffnessFromContactTime round trip", s), got,
                 static_cast<LD>(k_over_m) * mass, /*max_rel_error=*/4 * (cond + 2.0) * kEps,
                 k_over_m);
      }
    }
  }
}

TEST_CASE("stability: compression x(t) has no 0/0 at and near critical damping") {
  const double v = 2.5;
  std::vector<double> zetas{0.5, 2.0, 1.0};
  for (double gap : {1e-4, 1e-8, 1e-12}) {
    zetas.push_back(1.0 - gap);
    zetas.push_back(1.0 + gap);
  }
  zetas.push_back(std::nextafter(1.0, 0.0));
  zetas.push_back(std::nextafter(1.0, 2.0));
  for (double wn : {10.0, 1e7}) {
    for (double zeta : zetas) {
      const KelvinVoigtRates rates{wn, zeta};
      // wn t from 1e-6 to 3 (before the zero crossing of zeta = 0.5 at 3.63).
      for (double tau : LogSpace(1e-6, 3.0, 60)) {
        const double t = tau / wn;
        const LD tl = t;
        const LD ref = RefCompression(wn, zeta, v, tl);
        // cond wrt t and wn (each enters through wn t) and zeta, plus v and rounding.
        const double c_t =
            LogDerivative([&](LD tt) { return RefCompression(wn, zeta, v, tt); }, tl);
        const double c_zeta =
            LogDerivative([&](LD zz) { return RefCompression(wn, zz, v, tl); }, zeta);
        const double cond = 2.0 + 2.0 * std::abs(c_t) + std::abs(c_zeta);
        CheckRel("KV compression x(t)", KelvinVoigtCompression(rates, v, t), ref,
                 /*max_rel_error=*/4 * cond * kEps, zeta);
      }
    }
  }
  // At the kinematic contact's end x is back to 0 up to the rounding of the phase
  // wd tau_c = pi (a few eps): |x| <= (v/wd) e * 16 eps.
  for (double zeta : {1e-8, 0.3, 0.999}) {
    const double wn = 1e4;
    const KelvinVoigtRates rates{wn, zeta};
    const ContactResponse c = KelvinVoigtContact(rates, v, Separation::kKinematic);
    const double wd = wn * std::sqrt((1.0 - zeta) * (1.0 + zeta));
    INFO("zeta = " << zeta);
    CHECK(std::abs(KelvinVoigtCompression(rates, v, c.contact_time)) <=
          16 * kEps * v / wd * c.restitution);
  }
}

TEST_CASE("stability: restitution equivalence round-trips for tiny and large zeta") {
  for (Separation s : {Separation::kKinematic, Separation::kForce}) {
    std::vector<double> zetas = LogSpace(1e-12, 0.5, 80);
    for (double gap : LogSpace(0.5, 1e-12, 60)) zetas.push_back(1.0 - gap);
    if (s == Separation::kForce) {
      zetas.push_back(1.0);
      for (double big : LogSpace(1.0 + 1e-12, 1e6, 60)) zetas.push_back(big);
    }
    for (double zeta : zetas) {
      // c_f = d ln|ln e| / d ln zeta > 0: ln e carries zeta with gain c_f, the
      // inverse with gain 1/c_f.
      double c_f;
      LD log_e_ref;
      if (s == Separation::kKinematic) {
        const LD s2 = (1.0L - zeta) * (1.0L + zeta);
        c_f = static_cast<double>(1.0L / s2);
        log_e_ref = -kPiL * zeta / sqrtl(s2);
      } else {
        c_f = 1.0 + CondH(zeta);
        log_e_ref = -2.0L * zeta * RefH(zeta);
      }
      const double log_e = LogRestitutionFromDampingRatio(zeta, s);
      CheckRel(Name("LogRestitutionFromDampingRatio", s), log_e, log_e_ref,
               /*max_rel_error=*/4 * (1.0 + c_f) * kEps, zeta);

      // The inverse at this double ln e, against its own reference.
      const LD zeta_ref =
          s == Separation::kKinematic
              ? -static_cast<LD>(log_e) / sqrtl(static_cast<LD>(log_e) * log_e + kPiL * kPiL)
              : RefForceDampingRatio(log_e);
      const double back = DampingRatioFromLogRestitution(log_e, s);
      CheckRel(Name("DampingRatioFromLogRestitution", s), back, zeta_ref,
               /*max_rel_error=*/4 * (1.0 + 1.0 / c_f) * kEps, zeta);
      // Round trip: ln e's error (4 (1 + c_f) eps) comes back divided by c_f.
      CheckRel(Name("zeta -> ln e -> zeta round trip", s), back, zeta,
               /*max_rel_error=*/4 * (2.0 + 2.0 / c_f) * kEps, zeta);
    }
  }
}

TEST_CASE("stability: kinematic separation with zeta >= 1 throws NoSeparationError, never NaN") {
  const double huge = std::numeric_limits<double>::max();
  for (double zeta : {1.0, std::nextafter(1.0, 2.0), 1.0 + 1e-12, 1.5, 10.0, 1e300, huge}) {
    INFO("zeta = " << zeta);
    const KelvinVoigtRates rates{1e3, zeta};
    CHECK_THROWS_AS(KelvinVoigtContact(rates, 1.0, Separation::kKinematic), NoSeparationError);
    CHECK_THROWS_WITH(KelvinVoigtContact(rates, 1.0, Separation::kKinematic),
                      Catch::Contains("never") && Catch::Contains("force"));
    CHECK_THROWS_AS(LogRestitutionFromDampingRatio(zeta, Separation::kKinematic),
                    NoSeparationError);
    CHECK_THROWS_AS(StiffnessFromContactTime(1.0, 1e-4, zeta, Separation::kKinematic),
                    NoSeparationError);
    if (zeta <= 1e300) {  // C = 2 zeta M wn must stay finite
      const KelvinVoigt model = KelvinVoigtFromRates(kBarMass, KelvinVoigtRates{1e3, zeta});
      CHECK_THROWS_AS(KelvinVoigtContactLaw(model, Separation::kKinematic).Respond(1.0),
                      NoSeparationError);
    }
  }
  // A NoSeparationError is a std::domain_error, so generic handlers catch it too.
  CHECK_THROWS_AS(KelvinVoigtContact(KelvinVoigtRates{1e3, 1.0}, 1.0, Separation::kKinematic),
                  std::domain_error);
  // And a rebound sequence with such a law reports it instead of producing NaN.
  const Pendulum p{kL, kG, PendulumConvention::kExact};
  const KelvinVoigtContactLaw law(KelvinVoigtFromRates(kBarMass, KelvinVoigtRates{1e5, 1.0}),
                                  Separation::kKinematic);
  CHECK_THROWS_AS(SimulateRebounds(p, law, 0.1, 3), NoSeparationError);
  // Restitution >= 1 (no dissipation): a diagnostic, not NaN.
  for (Separation s : {Separation::kKinematic, Separation::kForce}) {
    for (double log_e : {0.0, 1e-300, 1e-16, 0.5, std::nan("")}) {
      CHECK_THROWS_AS(DampingRatioFromLogRestitution(log_e, s), std::domain_error);
    }
    CHECK_THROWS_WITH(DampingRatioFromLogRestitution(0.1, s), Catch::Contains("restitution"));
  }
}

TEST_CASE("stability: Kelvin-Voigt results are finite for every valid input swept") {
  const std::vector<double> force_zetas = [] {
    std::vector<double> z = ForceZetas();
    for (double big : LogSpace(10.0, 1e6, 20)) z.push_back(big);
    z.push_back(0.0);
    return z;
  }();
  for (double k_over_m : LogSpace(1e2, 1e14, 13)) {
    const double wn = std::sqrt(k_over_m);
    for (double v : {1e-9, 1.0, 1e3}) {
      for (Separation s : {Separation::kKinematic, Separation::kForce}) {
        for (double zeta : force_zetas) {
          if (s == Separation::kKinematic && zeta >= 1.0) continue;
          INFO("K/M = " << k_over_m << ", v = " << v << ", zeta = " << zeta << ", "
                        << SeparationName(s));
          const KelvinVoigtRates rates{wn, zeta};
          const ContactResponse c = KelvinVoigtContact(rates, v, s);
          CHECK(std::isfinite(c.contact_time));
          CHECK(c.contact_time > 0.0);
          CHECK(std::isfinite(c.log_restitution));
          CHECK(std::isfinite(c.restitution));
          CHECK(std::isfinite(c.peak_time));
          CHECK(std::isfinite(c.peak_compression));
          CHECK(c.peak_compression > 0.0);
          for (int i = 0; i <= 10; ++i) {
            CHECK(std::isfinite(KelvinVoigtCompression(rates, v, c.contact_time * i / 10)));
          }
          CHECK(std::isfinite(StiffnessFromContactTime(kBarMass, c.contact_time, zeta, s)));
          if (c.log_restitution < 0.0) {
            CHECK(std::isfinite(DampingRatioFromLogRestitution(c.log_restitution, s)));
          }
        }
      }
    }
  }
}

// Force separation stays finite for damping ratios up to the largest double
// (zeta^2 - 1 would overflow above sqrt(DBL_MAX) ~ 1.34e154), and
// DampingRatioFromLogRestitution refuses ln e beyond any finite zeta.
TEST_CASE("stability: force separation stays finite for damping ratios up to DBL_MAX") {
  for (double zeta : {1e100, 1e154, 1.4e154, 1e200, 1e300, DBL_MAX}) {
    INFO("zeta = " << zeta);
    const KelvinVoigtRates rates{1e3, zeta};
    const ContactResponse c = KelvinVoigtContact(rates, 1.0, Separation::kForce);
    CHECK(std::isfinite(c.contact_time));
    CHECK(std::isfinite(c.log_restitution));
    CHECK(std::isfinite(c.peak_compression));
    CHECK(std::isfinite(KelvinVoigtCompression(rates, 1.0, 0.5 * c.contact_time)));
    // ln e = -2 acosh(zeta) = -2 ln(2 zeta) to double precision above 1e8.
    CHECK(RelErr(c.log_restitution, -2.0L * logl(2.0L * zeta)) <= 4 * 2.0 * kEps);
  }
  for (double log_e : {-700.0, -720.0, -1000.0, -1400.0}) {
    INFO("ln e = " << log_e);
    double zeta = std::nan("");
    try {
      zeta = DampingRatioFromLogRestitution(log_e, Separation::kForce);
    } catch (const std::domain_error&) {
      zeta = 0.0;  // a diagnostic is acceptable where zeta would overflow
    }
    CHECK(std::isfinite(zeta));
  }
}

// ===========================================================================
// 4. Rebound sequences.

// A contact law with a fixed restitution, to drive the sequence with e chosen
// to the last bit (the same for every impact).
class FixedRestitution final : public ContactLaw {
 public:
  explicit FixedRestitution(double e) : e_(e) {}
  ContactResponse Respond(double) const override {
    ContactResponse r;
    r.contact_time = 1e-4;
    r.restitution = e_;
    r.log_restitution = std::log(e_);
    r.peak_time = 0.5e-4;
    r.peak_compression = 1e-4;
    return r;
  }
  double Compression(double, double) const override { return 0.0; }

 private:
  double e_;
};

// Reference amplitudes of rebounds 0..n: v_N = v_0 e^N in long double (exact
// pendulum: v_0 = 2 sqrt(gL) sin(theta_0/2), X = L sin(2 asin(v/(2 sqrt(gL)))));
// thesis: X_N = X_0 e^N.
std::vector<LD> RefAmplitudes(const Pendulum& p, double release_x, LD e, int n) {
  const LD L = p.length;
  std::vector<LD> out;
  for (int i = 0; i <= n; ++i) {
    const LD en = powl(e, i);
    if (p.convention == PendulumConvention::kThesis) {
      out.push_back(release_x * en);
    } else {
      const LD k = RefHalfAngleSine(release_x / L) * en;
      out.push_back(i == 0 ? static_cast<LD>(release_x) : L * sinl(2.0L * RefAsin(k)));
    }
  }
  return out;
}

TEST_CASE("stability: 200 rebounds with e close to 1 and tiny amplitudes decay geometrically") {
  constexpr int kRebounds = 200;
  const double e_close = 1.0 - 0x1p-40;  // e = 1 - 9.1e-13
  const KelvinVoigt barely_damped = KelvinVoigtFromRates(kBarMass, KelvinVoigtRates{2e4, 1e-8});
  for (auto convention : {PendulumConvention::kExact, PendulumConvention::kThesis}) {
    const Pendulum p{kL, kG, convention};
    const char* conv = convention == PendulumConvention::kExact ? "exact" : "thesis";
    for (double u : {1e-9, 1e-6, 5.2e-3, 0.3}) {
      const double release_x = u * kL;
      FixedRestitution fixed(e_close);
      KelvinVoigtContactLaw kv(barely_damped, Separation::kForce);
      const ContactLaw* laws[] = {&fixed, &kv};
      for (const ContactLaw* law : laws) {
        const ReboundSequence seq = SimulateRebounds(p, *law, release_x, kRebounds);
        REQUIRE(seq.xmax.size() == kRebounds + 1);
        const double e = seq.contact.restitution;
        REQUIRE(e < 1.0);
        const std::vector<LD> ref = RefAmplitudes(p, release_x, e, kRebounds);
        // Durations: exact half period of each reference amplitude.
        LD t_ref = 0.0L;
        LD compensation = 0.0L;  // Kahan-compensated sum of the reference times
        const auto add = [&](LD term) {
          const LD y = term - compensation;
          const LD sum = t_ref + y;
          compensation = (sum - t_ref) - y;
          t_ref = sum;
        };
        const LD w0 = sqrtl(static_cast<LD>(kG) / kL);
        const auto ref_half_period = [&](LD x) {
          return convention == PendulumConvention::kThesis
                     ? kPiL / w0
                     : 2.0L / w0 * RefEllipK(RefHalfAngleSine(x / kL));
        };
        add(0.5L * ref_half_period(release_x));
        for (int n = 1; n <= kRebounds; ++n) {
          INFO(conv << " X0/L = " << u << ", e = " << e << ", rebound " << n);
          // X_n depends on e^n: cond wrt e is n (times dX/dv <= 1), and the
          // library multiplies the speed by e n times (n roundings): (n + 4) eps.
          const double cond = n + 4.0;
          CheckRel(std::string("rebounds ") + conv + ": xmax[n], 200 rebounds", seq.xmax[n], ref[n],
                   /*max_rel_error=*/4 * cond * kEps, u);
          CHECK(seq.xmax[n] < seq.xmax[n - 1]);  // strictly decreasing
          // Ratio of successive maxima: e to first order in (X/L)^2, exactly e in
          // the thesis convention; each amplitude is accurate to a few eps.
          const LD ratio_ref = ref[n] / ref[n - 1];
          CheckRel(std::string("rebounds ") + conv + ": xmax[n]/xmax[n-1]",
                   seq.xmax[n] / seq.xmax[n - 1], ratio_ref, /*max_rel_error=*/4 * 8.0 * kEps, u);
          CHECK(std::isfinite(seq.peak_time[n]));
          CHECK(std::isfinite(seq.duration[n]));
          CheckRel(std::string("rebounds ") + conv + ": duration[n]", seq.duration[n],
                   ref_half_period(ref[n]), /*max_rel_error=*/4 * 3.0 * kEps, u);
          add(static_cast<LD>(seq.contact.contact_time));
          add(0.5L * ref_half_period(ref[n]));
          // A sum of n positive terms (cond 1): recursive summation's bound (Higham
          // eq. 4.4) is (number of terms) * eps; the terms' own errors are a few eps.
          const double terms = 2.0 * n + 2.0;
          CheckRel(std::string("rebounds ") + conv + ": peak_time[n] (sum of 2n+2 terms)",
                   seq.peak_time[n], t_ref, /*max_rel_error=*/(terms + 4.0 * 3.0) * kEps, u);
          add(0.5L * ref_half_period(ref[n]));
        }
      }
    }
  }
}

TEST_CASE("stability: exact and thesis rebound sequences agree to O((X/L)^2)") {
  // Exact: X_N/L = e^N (u + u^3/8 (1 - e^(2N))) + O(u^5), thesis X_N/L = e^N u, so
  // |X_exact/X_thesis - 1| <= u^2/8 (1 + u^2); the half periods differ by
  // K(k)/(pi/2) - 1 = k^2/4 + ... <= u^2/16 (1 + u^2), k = sin(theta/2) <= u/2 (1 + u^2).
  constexpr int kRebounds = 50;
  const FixedRestitution law(0.93);
  const Pendulum exact{kL, kG, PendulumConvention::kExact};
  const Pendulum thesis{kL, kG, PendulumConvention::kThesis};
  for (double u : {1e-9, 1e-6, 1e-4, 1e-3, 1e-2, 5e-2, 0.2}) {
    const double x0 = u * kL;
    const ReboundSequence a = SimulateRebounds(exact, law, x0, kRebounds);
    const ReboundSequence b = SimulateRebounds(thesis, law, x0, kRebounds);
    for (int n = 0; n <= kRebounds; ++n) {
      INFO("X0/L = " << u << ", rebound " << n);
      const double rounding = 4 * (n + 4.0) * kEps;  // both sequences' own errors
      const double amplitude_diff = std::abs(a.xmax[n] / b.xmax[n] - 1.0);
      CHECK(amplitude_diff <= u * u / 8 * (1 + u * u) + rounding);
      const double period_diff = std::abs(a.duration[n] / b.duration[n] - 1.0);
      CHECK(period_diff <= u * u / 16 * (1 + u * u) + rounding);
      CHECK(std::isfinite(a.peak_time[n]));
    }
    // The O(u^2) is sharp: for 1e-4 <= u <= 1e-2 the first rebound's amplitudes differ by
    // u^2 (1 - e^2)/8 to within 1 %.
    if (u >= 1e-4 && u <= 1e-2) {
      const double predicted = u * u * (1 - 0.93 * 0.93) / 8;
      CHECK(std::abs(a.xmax[1] / b.xmax[1] - 1.0) == Approx(predicted).epsilon(0.01));
    }
  }
}

TEST_CASE("stability: rebounds that exceed their predecessor give a diagnostic, never NaN") {
  // e > 1 (the thesis saw rebounds above their predecessor): amplitudes grow
  // until a swing would pass the horizontal, which throws; never NaN.
  const Pendulum exact{kL, kG, PendulumConvention::kExact};
  const FixedRestitution gaining(1.05);
  const ReboundSequence grow = SimulateRebounds(exact, gaining, 1e-3 * kL, 20);
  for (std::size_t n = 1; n < grow.xmax.size(); ++n) {
    CHECK(std::isfinite(grow.xmax[n]));
    CHECK(grow.xmax[n] > grow.xmax[n - 1]);
  }
  CHECK_THROWS_AS(SimulateRebounds(exact, gaining, 0.5 * kL, 400), std::domain_error);
  CHECK_THROWS_WITH(SimulateRebounds(exact, gaining, 0.5 * kL, 400), Catch::Contains("horizontal"));
  // A measured restitution >= 1 cannot be turned into damping: diagnostic.
  CHECK_THROWS_AS(DampingRatioFromLogRestitution(std::log(1.05), Separation::kKinematic),
                  std::domain_error);
}

// In the thesis convention too, growing rebounds that would pass X = L stop
// with a std::domain_error instead of running on silently.
TEST_CASE("stability: thesis-convention rebounds past X = L give a diagnostic") {
  const Pendulum thesis{kL, kG, PendulumConvention::kThesis};
  const FixedRestitution gaining(1.05);
  CHECK_THROWS_AS(SimulateRebounds(thesis, gaining, 0.5 * kL, 400), std::domain_error);
  CHECK_THROWS_AS(AmplitudeFromSpeed(thesis, 2.0 * kL * NaturalFrequency(thesis)),
                  std::domain_error);
}

TEST_CASE("stability: sampled histories of tiny rebounds near critical damping stay finite") {
  const Pendulum p{kL, kG, PendulumConvention::kExact};
  for (double zeta : {1.0 - 1e-12, 1.0, 1.0 + 1e-12}) {
    const KelvinVoigtContactLaw law(KelvinVoigtFromRates(kBarMass, KelvinVoigtRates{3e4, zeta}),
                                    Separation::kForce);
    const ReboundSequence seq = SimulateRebounds(p, law, 1e-9 * kL, 3);
    // Sample across the first impact finely and the rest coarsely.
    const double t0 = seq.impact_time[0];
    const double tau = seq.contact.contact_time;
    for (int i = -2; i <= 22; ++i) {
      const double t = t0 + tau * i / 20;
      const double x = HistoryDisplacement(seq, p, law, t);
      INFO("zeta = " << zeta << ", t = " << t);
      CHECK(std::isfinite(x));
      if (i > 0 && i < 20) CHECK(x <= 0.0);  // compression is drawn negative
    }
    const SampledHistory h = SampleHistory(seq, p, law, 1e-3);
    CHECK(std::all_of(h.displacement.begin(), h.displacement.end(),
                      [](double x) { return std::isfinite(x); }));
  }
}

}  // namespace
}  // namespace impactlab
