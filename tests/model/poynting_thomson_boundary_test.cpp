// Poynting-Thomson contact at its regime boundaries (model/poynting_thomson.h):
// the double-root curve of the characteristic cubic on both branches, the
// triple root, points inside the thin three-real-roots cusp next to the triple
// root (where the two cases sit, ~1e-39 from the boundary in the
// relative discriminant), the tangency edge of kinematic separation inside the
// complex region, and a few of these at extreme scales.
//
// The reference is independent of the code under test. It works in 160-bit
// binary floating point (Boost cpp_bin_float) from the input doubles, which
// are exact:
//  - roots: a real root of p(s) = s^3 + z s^2 + D s + E (z = K2/C,
//    D = (K1 + K2)/M, E = K1 K2/(C M)) by bisection on (-z, 0), where
//    p(-z) = -K2^2/(C M) < 0 < p(0); the other two from the deflated
//    quadratic, whose discriminant's sign is the regime. That sign is checked
//    against the cubic's discriminant in exact rational arithmetic;
//  - x1, x1' and F/M by residues, the inverse Laplace transforms of
//    (s + z)/p, s (s + z)/p and (D s + E)/p (v0 = 1), all times e^{mu t};
//  - the peak (first zero of x1') and the force zero after it by geometric
//    scans and bisection; for the kinematic convention, with x1 = e^{-P t} g,
//    the first negative half-wave of the pair's sinusoid on which the convex
//    g has a minimum <= 0 (no sampling of x1: see KinematicZero), then
//    bisection, all in 160 bits.
// Tolerances: max(1e-12, 16 (cond + 1) eps), cond being the first-order
// relative condition number sum_p |d ln Q/d ln p| over p = M, K1, K2, C, from
// the reference by the implicit-function theorem (Q is a zero of a signal g:
// dQ/dp = -(dg/dp)/(dg/dt), dg/dp by central differences of 1e-24 in 160
// bits); ln e gains 1/|ln e| (e itself is accurate to ~eps absolute).
// Set IMPACTLAB_STABILITY_REPORT=1 to print the worst errors.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <optional>
#include <string>
#include <vector>

#include <boost/math/constants/constants.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/cpp_int.hpp>
#include <catch2/catch.hpp>

#include "model/poynting_thomson.h"
#include "tests/support/precision.h"

namespace impactlab {
namespace {

using namespace testing;
using H = boost::multiprecision::number<
    boost::multiprecision::cpp_bin_float<160, boost::multiprecision::digit_base_2>,
    boost::multiprecision::et_off>;

const H kPiH = boost::math::constants::pi<H>();

// ---------------------------------------------------------------------------
// 160-bit reference.

struct HModel {
  H mass, k1, k2, c;
};
HModel Exact(const PoyntingThomson& m) { return {m.mass, m.stiffness1, m.stiffness2, m.damping}; }

// The sign of the discriminant of C M s^3 + K2 M s^2 + (K1 + K2) C s + K1 K2,
// in exact rational arithmetic: > 0 three distinct real roots, < 0 a complex
// pair, 0 a multiple root.
int ExactDiscriminantSign(const PoyntingThomson& m) {
  using Q = boost::multiprecision::cpp_rational;
  const Q mass(m.mass), k1(m.stiffness1), k2(m.stiffness2), c(m.damping);
  const Q a = c * mass, b = k2 * mass, cc = (k1 + k2) * c, d = k1 * k2;
  const Q disc = 18 * a * b * cc * d - 4 * b * b * b * d + b * b * cc * cc - 4 * a * cc * cc * cc -
                 27 * a * a * d * d;
  return disc > 0 ? 1 : disc < 0 ? -1 : 0;
}

struct Cx {
  H re, im;
};
Cx operator+(const Cx& x, const Cx& y) { return {x.re + y.re, x.im + y.im}; }
Cx operator*(const Cx& x, const Cx& y) {
  return {x.re * y.re - x.im * y.im, x.re * y.im + x.im * y.re};
}
Cx operator/(const Cx& x, const Cx& y) {
  const H d = y.re * y.re + y.im * y.im;
  return {(x.re * y.re + x.im * y.im) / d, (x.im * y.re - x.re * y.im) / d};
}

// x1, x1', F/M and d(F/M)/dt for v0 = 1 by residues, times e^{mu t}.
class RefSignals {
 public:
  struct Values {
    H u, v, f, ft;
  };

  explicit RefSignals(const HModel& m) {
    z_ = m.k2 / m.c;
    d_ = (m.k1 + m.k2) / m.mass;
    e_ = m.k1 * m.k2 / (m.c * m.mass);
    H lo = -z_, hi = 0;
    for (int i = 0; i < 2000; ++i) {
      const H mid = (lo + hi) / 2;
      if (mid == lo || mid == hi) break;
      (Cubic(mid) < 0 ? lo : hi) = mid;
    }
    r_ = (lo + hi) / 2;
    // s^2 + a s + b = p(s)/(s - r): a = z + r, formed as K2^2/(C M (r^2 + D))
    // (from p(r) = (r + z)(r^2 + D) - K2^2/(C M) = 0), which does not cancel
    // when r ~ -z (a fast real root, large K2/C).
    const H a = m.k2 * m.k2 / (m.c * m.mass * (r_ * r_ + d_)), b = -e_ / r_;
    const H disc = a * a / 4 - b;
    complex_pair_ = disc < 0;
    if (complex_pair_) {
      pair_decay_ = a / 2;
      omega_ = sqrt(-disc);
      mu_ = std::min(-r_, pair_decay_);
    } else {
      s2_ = -a / 2 - sqrt(disc);
      s3_ = b / s2_;
      mu_ = std::min({-r_, -s2_, -s3_});
    }
    // Numerators n2 s^2 + n1 s + n0.
    const std::array<std::array<H, 3>, 4> numerators = {{
        {H(0), H(1), z_},  // x1
        {H(1), z_, H(0)},  // x1'
        {H(0), d_, e_},    // F/M
        {d_, e_, H(0)},    // (F/M)'
    }};
    for (std::size_t k = 0; k < 4; ++k) {
      const auto& n = numerators[k];
      real_res_[k] = ((n[0] * r_ + n[1]) * r_ + n[2]) / Slope(r_);
      if (complex_pair_) {
        const Cx s{-pair_decay_, omega_};
        const Cx num = Cx{n[0], 0} * s * s + Cx{n[1] * s.re + n[2], n[1] * s.im};
        const Cx den = Cx{H(3), 0} * s * s + Cx{2 * z_ * s.re + d_, 2 * z_ * s.im};
        pair_res_[k] = num / den;
      } else {
        res2_[k] = ((n[0] * s2_ + n[1]) * s2_ + n[2]) / Slope(s2_);
        res3_[k] = ((n[0] * s3_ + n[1]) * s3_ + n[2]) / Slope(s3_);
      }
    }
  }

  Values At(const H& t, const H& mu) const {
    std::array<H, 4> out;
    const H er = exp((r_ + mu) * t);
    if (complex_pair_) {
      const H ep = exp((mu - pair_decay_) * t), c = cos(omega_ * t), s = sin(omega_ * t);
      for (std::size_t k = 0; k < 4; ++k) {
        out[k] = real_res_[k] * er + 2 * ep * (pair_res_[k].re * c - pair_res_[k].im * s);
      }
    } else {
      const H e2 = exp((s2_ + mu) * t), e3 = exp((s3_ + mu) * t);
      for (std::size_t k = 0; k < 4; ++k) {
        out[k] = real_res_[k] * er + res2_[k] * e2 + res3_[k] * e3;
      }
    }
    return {out[0], out[1], out[2], out[3]};
  }
  Values At(const H& t) const { return At(t, mu_); }

  bool complex_pair() const { return complex_pair_; }
  H omega() const { return omega_; }
  H pair_decay() const { return pair_decay_; }
  H pair_phase() const { return atan2(pair_res_[0].im, pair_res_[0].re); }  // of x1's pair part
  H real_root() const { return r_; }
  H mu() const { return mu_; }
  H natural_frequency() const { return sqrt(d_); }

 private:
  H Cubic(const H& s) const { return ((s + z_) * s + d_) * s + e_; }
  H Slope(const H& s) const { return (3 * s + 2 * z_) * s + d_; }

  H z_, d_, e_, r_, s2_, s3_, pair_decay_, omega_, mu_;
  bool complex_pair_ = false;
  std::array<H, 4> real_res_, res2_, res3_;
  std::array<Cx, 4> pair_res_;
};

// The zero of g in [lo, hi], g(lo) > 0 >= g(hi), to 2^-80 relative.
template <class G>
H BisectH(const G& g, H lo, H hi) {
  for (int i = 0; i < 400 && hi - lo > ldexp(abs(hi), -80); ++i) {
    const H mid = (lo + hi) / 2;
    (g(mid) > 0 ? lo : hi) = mid;
  }
  return (lo + hi) / 2;
}

// The first t after `start` with g(t) <= 0, g > 0 at start: steps of `step`
// (uniform) or times `factor` (geometric), then bisection; none before `end`.
template <class G>
std::optional<H> FirstZero(const G& g, const H& start, const H& step, double factor, const H& end) {
  H t = start;
  while (t < end) {
    const H next = factor > 1.0 ? H(t * factor) : H(t + step);
    if (g(next) <= 0) return BisectH(g, t, next);
    t = next;
  }
  return std::nullopt;
}

struct RefContactH {
  bool separates = true;
  H contact_time, log_restitution, peak_time, peak_compression;  // v0 = 1
};

// Kinematic separation, the first zero of x1 after the peak, by the structure
// of x1 = e^{-P t} g with g = m + S, m = R e^{(P + r) t} > 0 (R, the residue
// at the real root r, is positive) and S = 2|Rp| cos(omega t + arg Rp) (Rp the
// pair's residue): g < 0 only where S < 0, where g'' = (P + r)^2 m - omega^2 S
// > 0. So on each negative half-wave of S, g is convex: its minimum is the
// zero of g' (the sign of x1' + P x1) found by bisection, and x1 crosses in
// that half-wave iff g is <= 0 there. If the real root decays no faster than
// the pair, g(t + 2 pi/omega) > g(t): only the first period after the peak
// can cross. Independent of the code's sampling.
std::optional<H> KinematicZero(const RefSignals& s, const H& peak_time) {
  const H omega = s.omega(), decay = s.pair_decay(), period = 2 * kPiH / omega;
  const bool pair_slowest = decay < -s.real_root();
  const H limit = peak_time + (pair_slowest ? 400 : 1) * period;
  const auto u = [&](const H& t) { return s.At(t).u; };
  const auto slope = [&](const H& t) {
    const RefSignals::Values x = s.At(t);
    return x.v + decay * x.u;
  };
  // Negative half-waves: omega t + phase in [pi/2, 3pi/2] + 2 k pi.
  const H phase = s.pair_phase();
  for (H k = floor((omega * peak_time + phase) / (2 * kPiH)) - 1;; k += 1) {
    const H start = (kPiH / 2 + 2 * k * kPiH - phase) / omega, end = start + period / 2;
    if (end <= peak_time) continue;
    if (start > limit) return std::nullopt;
    const H left = std::max(start, peak_time);
    if (slope(left) >= 0 || slope(end) <= 0) continue;  // g's minimum at an end, where g > 0
    const H minimum = BisectH([&](const H& t) { return -slope(t); }, left, end);
    if (u(minimum) <= 0) return BisectH(u, left, minimum);
  }
}

RefContactH Solve(const RefSignals& s, Separation separation) {
  RefContactH out;
  const H wn = s.natural_frequency();
  // x1' > 0 on (0, sqrt2/wn); its first zero comes within pi/omega, and once
  // negative it stays so for pi/omega (docs/fitting.md): 5% steps are safe.
  const auto v = [&](const H& t) { return s.At(t).v; };
  const std::optional<H> peak = FirstZero(v, 1 / wn, H(0), 1.05, H(1e60) / wn);
  REQUIRE(peak);
  out.peak_time = *peak;
  out.peak_compression = s.At(out.peak_time).u * exp(-s.mu() * out.peak_time);
  std::optional<H> end;
  if (separation == Separation::kForce) {
    const auto f = [&](const H& t) { return s.At(t).f; };
    end = FirstZero(f, out.peak_time, H(0), 1.05, out.peak_time * 1e60);
  } else if (s.complex_pair()) {
    end = KinematicZero(s, out.peak_time);
  }
  if (!end) {
    out.separates = false;
    return out;
  }
  out.contact_time = *end;
  out.log_restitution = log(abs(s.At(*end).v)) - s.mu() * *end;
  return out;
}

// First-order relative condition numbers sum_p |d ln Q/d ln p|, p = M, K1, K2, C.
struct ConditionsH {
  double contact_time = 0, log_restitution = 0, peak_time = 0, peak_compression = 0;
};
ConditionsH ConditionOfH(const HModel& m, const RefSignals& base, const RefContactH& ref,
                         Separation separation) {
  ConditionsH cond;
  const H h = H(1e-24), mu = base.mu();
  const RefSignals::Values at_end = base.At(ref.contact_time, mu);
  const RefSignals::Values at_peak = base.At(ref.peak_time, mu);
  for (int p = 0; p < 4; ++p) {
    HModel up = m, down = m;
    H* up_field[] = {&up.mass, &up.k1, &up.k2, &up.c};
    H* down_field[] = {&down.mass, &down.k1, &down.k2, &down.c};
    *up_field[p] *= 1 + h;
    *down_field[p] *= 1 - h;
    const RefSignals hi(up), lo(down);
    const auto derivative = [&](const H& t, H RefSignals::Values::*q) {
      return (hi.At(t, mu).*q - lo.At(t, mu).*q) / (2 * h);
    };
    // The peak: x1'(t_p) = 0, d x1'/dt = -F/M; x1 there moves by its partial only.
    const H dpeak = -derivative(ref.peak_time, &RefSignals::Values::v) / -at_peak.f;
    cond.peak_time += static_cast<double>(abs(dpeak / ref.peak_time));
    cond.peak_compression +=
        static_cast<double>(abs(derivative(ref.peak_time, &RefSignals::Values::u) / at_peak.u));
    if (!ref.separates) continue;
    // The end: a zero of x1 (d/dt = x1') or of F (d/dt = F').
    const bool kinematic = separation == Separation::kKinematic;
    const H dend = kinematic ? H(-derivative(ref.contact_time, &RefSignals::Values::u) / at_end.v)
                             : H(-derivative(ref.contact_time, &RefSignals::Values::f) / at_end.ft);
    cond.contact_time += static_cast<double>(abs(dend / ref.contact_time));
    // ln|x1'| at the end, x1'' = -F/M; the e^{mu t} factor is common.
    const H dlog =
        (derivative(ref.contact_time, &RefSignals::Values::v) - at_end.f * dend) / at_end.v;
    cond.log_restitution += static_cast<double>(abs(dlog / ref.log_restitution));
  }
  return cond;
}

double ToleranceH(double cond) { return std::max(1e-12, 16.0 * (cond + 1.0) * kEps); }

bool Finite(const ContactResponse& c) {
  return std::isfinite(c.contact_time) && std::isfinite(c.log_restitution) &&
         std::isfinite(c.restitution) && std::isfinite(c.peak_compression) &&
         std::isfinite(c.peak_time) && c.contact_time > 0.0 && c.log_restitution <= 0.0 &&
         c.restitution >= 0.0 && c.restitution <= 1.0;
}

struct Checked {
  bool complex_pair = false;
  std::optional<ContactResponse> got;  // the code's, when it separates
  RefContactH ref;
};

// The code against the reference for one model and convention; `input` labels
// the failure messages and the worst-error record.
Checked CheckModel(const std::string& where, const PoyntingThomson& model, Separation separation,
                   double input) {
  const std::string name = where + " " + SeparationName(separation);
  INFO(name << std::setprecision(17) << ": M = " << model.mass << ", K1 = " << model.stiffness1
            << ", K2 = " << model.stiffness2 << ", C = " << model.damping);
  Checked out;
  const int sign = ExactDiscriminantSign(model);
  if (sign == 0) {  // rounded exactly onto the boundary: a multiple root (no residues)
    CHECK_FALSE(CharacteristicRoots(model).complex_pair);
    if (separation == Separation::kKinematic) {
      CHECK_THROWS_WITH(PoyntingThomsonContact(model, 1.0, separation),
                        Catch::Contains("three real roots"));
    } else {
      out.got = PoyntingThomsonContact(model, 1.0, separation);
      CHECK(Finite(*out.got));
    }
    return out;
  }
  const HModel exact = Exact(model);
  const RefSignals signals(exact);
  out.complex_pair = signals.complex_pair();
  // The reference's regime is the exact one, and the code reports it.
  CHECK(signals.complex_pair() == (sign < 0));
  CHECK(CharacteristicRoots(model).complex_pair == signals.complex_pair());
  out.ref = Solve(signals, separation);
  if (!out.ref.separates) {
    CHECK_THROWS_AS(PoyntingThomsonContact(model, 1.0, separation), NoSeparationError);
    if (!signals.complex_pair()) {
      CHECK_THROWS_WITH(PoyntingThomsonContact(model, 1.0, separation),
                        Catch::Contains("three real roots"));
    }
    const PoyntingThomsonContactLaw law(model, separation);
    CHECK_THROWS_AS(law.Respond(2.0), NoSeparationError);
    return out;
  }
  REQUIRE((separation == Separation::kForce || signals.complex_pair()));
  ContactResponse got;
  try {
    got = PoyntingThomsonContact(model, 1.0, separation);
  } catch (const NoSeparationError& e) {
    FAIL_CHECK("no separation, but the reference separates at t = "
               << static_cast<double>(out.ref.contact_time) << ": " << e.what());
    return out;
  }
  CHECK(Finite(got));
  out.got = got;
  const ConditionsH cond = ConditionOfH(exact, signals, out.ref, separation);
  const auto ld = [](const H& x) { return static_cast<LD>(x); };
  CheckRel(name + " contact time", got.contact_time, ld(out.ref.contact_time),
           ToleranceH(cond.contact_time), input);
  CheckRel(name + " ln e", got.log_restitution, ld(out.ref.log_restitution),
           ToleranceH(cond.log_restitution +
                      1.0 / std::abs(static_cast<double>(out.ref.log_restitution))),
           input);
  CheckRel(name + " peak time", got.peak_time, ld(out.ref.peak_time), ToleranceH(cond.peak_time),
           input);
  CheckRel(name + " peak compression", got.peak_compression, ld(out.ref.peak_compression),
           ToleranceH(cond.peak_compression), input);
  return out;
}

// ---------------------------------------------------------------------------
// Models from their roots, exactly in 160 bits then rounded: a monic cubic
// s^3 + c2 s^2 + c1 s + c0 with roots in the open left half-plane is
// Poynting-Thomson with K1 = M c0/c2, K2 = M c1 - K1 (> 0: c1 c2 > c0 by
// Routh-Hurwitz), C = K2/c2.
PoyntingThomson FromCubic(const H& mass, const H& c2, const H& c1, const H& c0) {
  const H k1 = mass * c0 / c2, k2 = mass * c1 - k1;
  return {static_cast<double>(mass), static_cast<double>(k1), static_cast<double>(k2),
          static_cast<double>(k2 / c2)};
}
// (s + a)^2 (s + b): the double root -a, the simple root -b. b > a is the
// branch where the double root is the slow mode (kinematic contact time
// diverges on the complex side), b < a the other; b = a the triple root.
PoyntingThomson DoubleRoot(const H& mass, const H& a, const H& b) {
  return FromCubic(mass, 2 * a + b, a * a + 2 * a * b, a * a * b);
}
// (s + b)((s + a)^2 + w^2): the real root -b, the pair -a +- i w (w^2 < 0: a
// real pair -a +- sqrt(-w^2)).
PoyntingThomson PairAndRoot(const H& mass, const H& a, const H& w2, const H& b) {
  const H q1 = 2 * a, q0 = a * a + w2;
  return FromCubic(mass, q1 + b, q0 + b * q1, b * q0);
}

PoyntingThomson WithScaledParameter(PoyntingThomson m, int parameter, double factor) {
  double* field[] = {&m.mass, &m.stiffness1, &m.stiffness2, &m.damping};
  *field[parameter] *= factor;
  return m;
}

const char* kParameterNames[] = {"M", "K1", "K2", "C"};

std::string Label(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

// ---------------------------------------------------------------------------

TEST_CASE(
    "poynting_thomson boundary: the issue's two cases have three real roots, no kinematic "
    "separation") {
  // Both are exactly (s + a)((s + a)^2 - a^2 h^2), h = 2^-20, a = 3 and
  // 3 * 4096 (every coefficient is a short dyadic): the roots -a, -a(1 +- h)
  // are real, ~1e-39 from the boundary in the relative discriminant, where
  // double-precision roots are off by ~eps^(1/3) ~ 6e-6 and once looked like a
  // complex pair (tau_c 351975, ln e -1055910).
  const double h = std::ldexp(1.0, -20);
  const std::vector<std::pair<PoyntingThomson, double>> cases = {
      {{3, 8.999999999991815, 71.99999999998363, 7.999999999998181}, 3.0},
      {{0.005859375, 294911.9999997318, 2359295.9999994636, 63.99999999998545}, 12288.0},
  };
  for (const auto& [model, a] : cases) {
    INFO("M = " << model.mass);
    CHECK(ExactDiscriminantSign(model) > 0);
    const PoyntingThomsonRoots roots = CharacteristicRoots(model);
    CHECK_FALSE(roots.complex_pair);
    std::vector<double> reported;
    for (const auto& s : roots.roots) {
      CHECK(s.imag() == 0.0);
      reported.push_back(s.real());
    }
    std::sort(reported.begin(), reported.end());
    CHECK(reported[0] == Approx(-a * (1 + h)).epsilon(1e-14));
    CHECK(reported[1] == Approx(-a).epsilon(1e-14));
    CHECK(reported[2] == Approx(-a * (1 - h)).epsilon(1e-14));
    CHECK_THROWS_AS(PoyntingThomsonContact(model, 1.0, Separation::kKinematic), NoSeparationError);
    CHECK_THROWS_WITH(
        PoyntingThomsonContact(model, 1.0, Separation::kKinematic),
        Catch::Contains("three real roots") && Catch::Contains("use force separation"));
    const PoyntingThomsonContactLaw law(model, Separation::kKinematic);
    CHECK_THROWS_AS(law.Respond(1.0), NoSeparationError);
    // The force convention ends, as the reference says.
    CheckModel("issue case", model, Separation::kForce, model.mass);
    CheckModel("issue case", model, Separation::kKinematic, model.mass);
  }
}

TEST_CASE(
    "poynting_thomson boundary: exact double and triple roots never separate "
    "kinematically") {
  // Every coefficient exact: (s + 3)^3 (the cusp point); (s + 1)^2 (s + 2),
  // the double root slow; (s + 3)^2 (s + 2), the double root fast.
  const std::vector<std::pair<PoyntingThomson, const char*>> cases = {
      {{3, 9, 72, 8}, "all equal"},
      {{1, 0.5, 4.5, 1.125}, "two of them equal"},
      {{4, 9, 75, 9.375}, "two of them equal"},
  };
  for (const auto& [model, what] : cases) {
    INFO("K1 = " << model.stiffness1);
    REQUIRE(ExactDiscriminantSign(model) == 0);
    CHECK_FALSE(CharacteristicRoots(model).complex_pair);
    CHECK_THROWS_WITH(PoyntingThomsonContact(model, 1.0, Separation::kKinematic),
                      Catch::Contains("three real roots") && Catch::Contains(what));
    // The force convention is continuous through the multiple root.
    const ContactResponse on = PoyntingThomsonContact(model, 1.0, Separation::kForce);
    CHECK(Finite(on));
    for (const double side : {-1.0, 1.0}) {
      const ContactResponse near = PoyntingThomsonContact(
          WithScaledParameter(model, 1, 1.0 + side * 1e-12), 1.0, Separation::kForce);
      CHECK(std::abs(near.contact_time / on.contact_time - 1.0) < 1e-11);
      CHECK(std::abs(near.log_restitution / on.log_restitution - 1.0) < 1e-11);
      CHECK(std::abs(near.peak_compression / on.peak_compression - 1.0) < 1e-11);
    }
  }
}

TEST_CASE(
    "poynting_thomson boundary: 1e-6, 1e-9, 1e-12 from double and triple roots, both "
    "sides, both conventions") {
  // Boundary points (s + a)^2 (s + b) for b/a from 1/8 (the double root fast)
  // through 1 (the triple root) to 8 (the double root slow), at two scales;
  // K1 or C moved by a relative distance d either way (and d = 0: the
  // boundary point rounded to doubles, ~1e-16 off it on either side).
  struct Scale {
    double mass, a;
  };
  for (const Scale scale : {Scale{3.0, 3.0}, Scale{2.23 / 385.644, 8000.0}}) {
    for (const double ratio : {0.125, 0.5, 0.9, 1.0, 1.1, 2.0, 8.0}) {
      const PoyntingThomson on = DoubleRoot(scale.mass, scale.a, H(scale.a) * ratio);
      for (const int parameter : {1, 3}) {
        for (const double d : {0.0, 1e-6, 1e-9, 1e-12}) {
          std::array<std::optional<ContactResponse>, 2> force;
          std::array<RefContactH, 2> force_ref;
          for (const int side : {0, 1}) {
            if (d == 0.0 && side == 1) continue;
            const PoyntingThomson m =
                WithScaledParameter(on, parameter, side == 0 ? 1.0 - d : 1.0 + d);
            const std::string where = "b/a = " + Label(ratio) + ", " + kParameterNames[parameter] +
                                      " " + (side == 0 ? "-" : "+") + Label(d);
            CheckModel(where, m, Separation::kKinematic, side == 0 ? -d : d);
            const Checked f = CheckModel(where, m, Separation::kForce, side == 0 ? -d : d);
            force[static_cast<std::size_t>(side)] = f.got;
            force_ref[static_cast<std::size_t>(side)] = f.ref;
          }
          // The force convention is continuous: the two sides differ as the
          // reference's do, to rounding.
          if (d > 0.0 && force[0] && force[1]) {
            const auto jump = [&](double x0, double x1, const H& r0, const H& r1) {
              return std::abs(x1 - x0) - static_cast<double>(abs(r1 - r0)) <=
                     4e-12 * std::abs(static_cast<double>(r0));
            };
            CHECK(jump(force[0]->contact_time, force[1]->contact_time, force_ref[0].contact_time,
                       force_ref[1].contact_time));
            CHECK(jump(force[0]->log_restitution, force[1]->log_restitution,
                       force_ref[0].log_restitution, force_ref[1].log_restitution));
            CHECK(std::abs(force[1]->contact_time / force[0]->contact_time - 1.0) < 20.0 * d);
          }
        }
      }
    }
  }
}

TEST_CASE(
    "poynting_thomson boundary: inside and around the three-real-roots cusp at the triple "
    "root") {
  // Roots within h = 2^-7 ... 2^-23 of -3 (M = 3): three real ones, -3 and
  // -3(1 +- h) (exact doubles, as in the issue); and complex pairs -3 +- 3ih
  // with the real root at -3 (exact), -3(1 + h) (the pair is the slow mode)
  // or -3(1 - h) (the real root is). Rounded, the last two lie ~1e-16 off
  // their construction, which near the cusp can be either side.
  for (const int k : {7, 10, 16, 20, 23}) {
    const H a = 3, h = ldexp(H(1), -k), mass = 3;
    const std::vector<std::pair<std::string, PoyntingThomson>> models = {
        {"three real", PairAndRoot(mass, a, -a * a * h * h, a)},
        {"pair, real at -3", PairAndRoot(mass, a, a * a * h * h, a)},
        {"pair slow", PairAndRoot(mass, a, a * a * h * h, a * (1 + h))},
        {"real slow", PairAndRoot(mass, a, a * a * h * h, a * (1 - h))},
    };
    for (const auto& [what, m] : models) {
      const std::string where = what + " h = 2^-" + std::to_string(k);
      for (const Separation sep : {Separation::kKinematic, Separation::kForce}) {
        CheckModel(where, m, sep, static_cast<double>(h));
      }
    }
  }
}

TEST_CASE("poynting_thomson boundary: near the boundaries at extreme scales") {
  // The upper branch far out, (s + r)^2 (s + (1 - r^2)/(2r)) in units of wn,
  // r = 1e-20: beta ~ 5e19, kappa1 ~ 1e-40, and the discriminant's terms span
  // 1e80 (the double-precision filter is scaled so that none overflows).
  const H r = H(1e-20), beta = (3 * r * r + 1) / (2 * r);
  const H kappa1 = r * r * (1 - r * r) / (3 * r * r + 1);
  for (const double d : {-1e-9, 0.0, 1e-9}) {
    const H k1 = kappa1 * (1 + d), k2 = 1 - kappa1;
    const PoyntingThomson m{1.0, static_cast<double>(k1), static_cast<double>(k2),
                            static_cast<double>(k2 / beta)};
    for (const Separation sep : {Separation::kKinematic, Separation::kForce}) {
      CheckModel("upper r = 1e-20, K1 " + Label(d), m, sep, d);
    }
  }
  // The lower branch's Maxwell end, beta -> 2 with kappa1 = 1e-20 and 1e-60:
  // the slow real root (~2 kappa1) is tiny next to beta/3, where the 256-bit
  // root is polished on p itself. Kinematic only: there the force,
  // kappa1 u + kappa2 d, cancels to ~kappa1 of its terms, beyond double
  // precision (a limit of the force evaluation, not of the regime).
  for (const double small : {1e-20, 1e-60}) {
    for (const double d : {-1e-12, 0.0, 1e-12}) {
      const PoyntingThomson m{1.0, small, 1.0, 1.0 / (2.0 * (1.0 + d))};
      CheckModel("Maxwell end kappa1 = " + Label(small) + ", beta 2(1 " + Label(d) + ")", m,
                 Separation::kKinematic, d);
    }
  }
}

// The least value of x1 (times e^{mu t}) at the minima of g = e^{P t} x1 on
// the negative half-waves of S in the first slow period after the peak (see
// KinematicZero), or 1 if g has none there: its sign says whether x1 crosses.
H FirstMinimumValue(const RefSignals& s) {
  const H peak_time = Solve(s, Separation::kForce).peak_time;
  const H omega = s.omega(), decay = s.pair_decay(), phase = s.pair_phase();
  const auto slope = [&](const H& t) {
    const RefSignals::Values x = s.At(t);
    return x.v + decay * x.u;
  };
  H least = 1;
  for (H k = floor((omega * peak_time + phase) / (2 * kPiH)) - 1;; k += 1) {
    const H start = (kPiH / 2 + 2 * k * kPiH - phase) / omega, end = start + kPiH / omega;
    if (end <= peak_time) continue;
    if (start > peak_time + 2 * kPiH / omega) return least;
    const H left = std::max(start, peak_time);
    if (slope(left) >= 0 || slope(end) <= 0) continue;
    least = std::min(least, s.At(BisectH([&](const H& t) { return -slope(t); }, left, end)).u);
  }
}

TEST_CASE(
    "poynting_thomson boundary: 1e-6, 1e-9, 1e-12 from the tangency edge of kinematic "
    "separation") {
  // Where the real root decays more slowly than the complex pair, x1 crosses
  // 0 only if its first minimum does: the edge is where that minimum touches
  // 0 (docs/fitting.md; beta = 1, kappa1 = 0.2329...). Found here by
  // bisection on kappa1 in 160 bits (M = 1, K1 + K2 = 1, C = K2/beta), then
  // approached in K1 at M = 3, K1 + K2 = 81.
  struct Edge {
    double beta, kappa1_lo, kappa1_hi;  // a bracket of the edge
  };
  for (const Edge edge : {Edge{0.5, 0.1, 0.15}, Edge{0.75, 0.2, 0.25}, Edge{1.0, 0.2, 0.25}}) {
    const auto min_at = [&](const H& kappa1) {
      return FirstMinimumValue(RefSignals(HModel{1, kappa1, 1 - kappa1, (1 - kappa1) / edge.beta}));
    };
    H lo = edge.kappa1_lo, hi = edge.kappa1_hi;  // x1's minimum > 0 at lo, < 0 at hi
    REQUIRE(min_at(lo) > 0);
    REQUIRE(min_at(hi) < 0);
    for (int i = 0; i < 56; ++i) {  // to 0.05 2^-56 ~ 7e-19, far below 1e-12 kappa1
      const H mid = (lo + hi) / 2;
      (min_at(mid) > 0 ? lo : hi) = mid;
    }
    const H kappa1 = (lo + hi) / 2;
    INFO("beta = " << edge.beta << ", edge at kappa1 = " << static_cast<double>(kappa1));
    const RefSignals at_edge(HModel{1, kappa1, 1 - kappa1, (1 - kappa1) / edge.beta});
    REQUIRE(at_edge.pair_decay() > -at_edge.real_root());  // the real root is the slow mode
    const H k = 81, mass = 3, wn = sqrt(k / mass);
    for (const double d : {1e-6, 1e-9, 1e-12}) {
      for (const double side : {-1.0, 1.0}) {
        const H k1 = kappa1 * k * (1 + side * d), k2 = (1 - kappa1) * k;
        const PoyntingThomson m{3.0, static_cast<double>(k1), static_cast<double>(k2),
                                static_cast<double>(k2 / (edge.beta * wn))};
        const std::string where =
            "tangency beta = " + Label(edge.beta) + ", K1 " + (side < 0 ? "-" : "+") + Label(d);
        const Checked c = CheckModel(where, m, Separation::kKinematic, side * d);
        CHECK(c.complex_pair);
        CHECK(c.ref.separates == (side > 0));  // the crossing side is larger kappa1
        CheckModel(where, m, Separation::kForce, side * d);
      }
    }
  }
}

TEST_CASE("poynting_thomson boundary: the rates overload classifies the rates as given") {
  // PoyntingThomsonRates are taken as exact: the regime is that of
  // s^3 + beta s^2 + (kappa1 + kappa2) s + beta kappa1. RatesOf rounds, so
  // within ~eps of a boundary the rates may fall on the other side; the
  // reference here is built from the rates (M = 1, K1 = kappa1, K2 = kappa2,
  // C = kappa2/beta in 160 bits), in units of the rates' wn.
  const std::vector<PoyntingThomson> models = {
      {3, 8.999999999991815, 71.99999999998363, 7.999999999998181},
      {0.005859375, 294911.9999997318, 2359295.9999994636, 63.99999999998545},
      {3, 9, 72, 8},
      {3, 9 * (1 + 1e-12), 72, 8},
  };
  for (const PoyntingThomson& model : models) {
    const PoyntingThomsonRates rates = RatesOf(model);
    const RefSignals ref(HModel{1, rates.kappa1, rates.kappa2, H(rates.kappa2) / rates.beta});
    // The rates' exact regime (B's cubic, exact rationals) is the reference's.
    using Q = boost::multiprecision::cpp_rational;
    const Q b(rates.beta), c = Q(rates.kappa1) + Q(rates.kappa2), d = b * Q(rates.kappa1);
    const Q disc = 18 * b * c * d - 4 * b * b * b * d + b * b * c * c - 4 * c * c * c - 27 * d * d;
    CHECK(ref.complex_pair() == (disc < 0));
    INFO("K1 = " << model.stiffness1 << ": the rates' reference has "
                 << (ref.complex_pair() ? "a complex pair" : "three real roots"));
    for (const Separation sep : {Separation::kKinematic, Separation::kForce}) {
      const RefContactH want = Solve(ref, sep);
      if (!want.separates) {
        CHECK_THROWS_AS(PoyntingThomsonContact(rates, 1.0, sep), NoSeparationError);
        continue;
      }
      const ContactResponse got = PoyntingThomsonContact(rates, 1.0, sep);
      CHECK(Finite(got));
      // Measured within 3e-12 (kinematic, tau_c ~ 1e6 at the rates) and
      // 4e-16 (force); 1e-9 leaves room for the conditioning so near the cusp.
      CheckRel(std::string("rates overload ") + SeparationName(sep) + " contact time",
               got.contact_time * rates.natural_frequency, static_cast<LD>(want.contact_time), 1e-9,
               model.stiffness1, "K1");
    }
  }
}

}  // namespace
}  // namespace impactlab
