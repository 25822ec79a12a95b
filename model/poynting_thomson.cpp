#include "model/poynting_thomson.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>
#include <Eigen/Dense>
#include <boost/math/tools/toms748_solve.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/cpp_int.hpp>

#include "model/impact_speed_internal.h"

namespace impactlab {
namespace {

using std::numbers::pi;
using Mat3 = Eigen::Matrix3d;

// Samples per half period of the slow oscillation in the kinematic search: a
// dip of x1 below 0 shorter than 1/16 of that half period, between two samples
// at which x1 > 0 and x1' has the same sign, would be missed (docs/fitting.md).
constexpr double kSamplesPerHalfPeriod = 16.0;

void CheckModel(const PoyntingThomson& m) {
  const auto bad = [](double x) { return !(x > 0.0) || !std::isfinite(x); };
  if (bad(m.mass) || bad(m.stiffness1) || bad(m.stiffness2) || bad(m.damping)) {
    throw std::invalid_argument(
        fmt::format("Poynting-Thomson needs M, K1, K2, C > 0 and finite, got M = {}, K1 = {}, "
                    "K2 = {}, C = {}",
                    m.mass, m.stiffness1, m.stiffness2, m.damping));
  }
}

void CheckPoyntingThomsonRates(const PoyntingThomsonRates& r) {
  const auto bad = [](double x) { return !(x > 0.0) || !std::isfinite(x); };
  if (bad(r.natural_frequency) || bad(r.kappa1) || bad(r.kappa2) || bad(r.beta)) {
    throw std::invalid_argument(fmt::format(
        "Poynting-Thomson rates must be > 0 and finite, got wn = {}, kappa1 = {}, kappa2 = {}, "
        "beta = {}",
        r.natural_frequency, r.kappa1, r.kappa2, r.beta));
  }
}

// The functionals of the state the searches look at; kEnvelopeSlope is
// x1' + P x1, exp(-P tau) times the slope of g = exp(P tau) x1.
enum class Quantity { kU, kV, kForce, kEnvelopeSlope };

// ---------------------------------------------------------------------------
// The regime, decided from the given doubles, not from computed roots.
//
// Near a double root the computed roots carry errors ~sqrt(eps), near the
// triple root ~eps^(1/3): far more than the distance to the boundary (input
// doubles 1e-12 from the triple root can be 1e-39 from it in the relative
// discriminant), so the sign of omega^2 they give follows rounding. Every
// input double is exact, and so is the discriminant of a cubic whose
// coefficients are sums and products of them, evaluated in integer
// arithmetic: its sign is the regime.

enum class Regime { kComplexPair, kThreeReal, kDoubleRoot, kTripleRoot };

// The doubles the regime is decided from. For a model, p(s) times C M,
//   C M s^3 + K2 M s^2 + (K1 + K2) C s + K1 K2;
// for rates taken as given (the PoyntingThomsonRates overloads), B's own
// characteristic cubic in units of wn,
//   s^3 + beta s^2 + (kappa1 + kappa2) s + beta kappa1.
// RatesOf rounds, so within ~eps of a boundary a model and its rates may be on
// different sides: a model is classified from M, K1, K2, C.
struct ExactInputs {
  bool from_model = false;
  double mass = 0.0, stiffness1 = 0.0, stiffness2 = 0.0, damping = 0.0;  // the model
  double kappa1 = 0.0, kappa2 = 0.0, beta = 0.0;                         // the rates
};
ExactInputs ExactOf(const PoyntingThomson& m) {
  ExactInputs in;
  in.from_model = true;
  in.mass = m.mass;
  in.stiffness1 = m.stiffness1;
  in.stiffness2 = m.stiffness2;
  in.damping = m.damping;
  return in;
}
ExactInputs ExactOf(const PoyntingThomsonRates& r) {
  ExactInputs in;
  in.kappa1 = r.kappa1;
  in.kappa2 = r.kappa2;
  in.beta = r.beta;
  return in;
}

// m 2^e, exact: products and sums of doubles without rounding (the integers
// grow to a few hundred bits, or to a few thousand for wildly different
// exponents, which only costs time).
struct Dyadic {
  boost::multiprecision::cpp_int m;
  int e = 0;
};
Dyadic ToDyadic(double x) {
  int e = 0;
  const double f = std::frexp(x, &e);  // x = f 2^e, 1/2 <= |f| < 1: f 2^53 is an integer
  return {boost::multiprecision::cpp_int(static_cast<std::int64_t>(std::ldexp(f, 53))), e - 53};
}
Dyadic operator*(const Dyadic& x, const Dyadic& y) { return {x.m * y.m, x.e + y.e}; }
Dyadic operator*(int k, const Dyadic& x) { return {k * x.m, x.e}; }
Dyadic operator+(const Dyadic& x, const Dyadic& y) {
  if (x.e <= y.e) return {x.m + (y.m << (y.e - x.e)), x.e};
  return {(x.m << (x.e - y.e)) + y.m, y.e};
}
Dyadic operator-(const Dyadic& x, const Dyadic& y) { return x + (-1) * y; }

// The sign of the discriminant of a s^3 + b s^2 + c s + d, exactly:
// 18abcd - 4b^3 d + b^2 c^2 - 4ac^3 - 27a^2 d^2, > 0 for three distinct real
// roots, < 0 for a complex pair, 0 for a multiple root (triple when also
// b^2 = 3ac).
Regime ExactRegime(const ExactInputs& in) {
  Dyadic a, b, c, d;
  if (in.from_model) {
    const Dyadic m = ToDyadic(in.mass), k1 = ToDyadic(in.stiffness1), k2 = ToDyadic(in.stiffness2),
                 damping = ToDyadic(in.damping);
    a = damping * m;
    b = k2 * m;
    c = (k1 + k2) * damping;
    d = k1 * k2;
  } else {
    a = ToDyadic(1.0);
    b = ToDyadic(in.beta);
    c = ToDyadic(in.kappa1) + ToDyadic(in.kappa2);
    d = b * ToDyadic(in.kappa1);
  }
  const Dyadic bc = b * c, ad = a * d;
  const Dyadic disc =
      18 * (ad * bc) - 4 * (b * b * b * d) + bc * bc - 4 * (a * c * c * c) - 27 * (ad * ad);
  if (disc.m > 0) return Regime::kThreeReal;
  if (disc.m < 0) return Regime::kComplexPair;
  return (b * b - 3 * (a * c)).m == 0 ? Regime::kTripleRoot : Regime::kDoubleRoot;
}

// The roots in the form the evaluation uses (units of wn): r the real root
// farthest from the others, the other two -P +- sqrt(-omega^2), a = 2P,
// b = P^2 + omega^2, q_r = Q(r) = (r + P)^2 + omega^2.
struct Spectrum {
  double r = 0.0, a = 0.0, b = 0.0, p = 0.0, omega2 = 0.0, q_r = 0.0;
};

using Wide = boost::multiprecision::number<
    boost::multiprecision::cpp_bin_float<256, boost::multiprecision::digit_base_2>,
    boost::multiprecision::et_off>;

// The spectrum in 256-bit arithmetic from the exact inputs (in units of `wn`,
// the double natural frequency the evaluation scales time by), with the regime
// given, along the double-precision route (below) but without its rounding:
//  - r: the cubic shifted to t^3 + p t + q. For p > 0 its one real root has
//    p'(t) = 3t^2 + p >= p; for p < 0 the root with the sign of -q and
//    |t| >= sqrt(-p) has p'(t) >= -2p and is the one farthest from the other
//    two: simple and well separated on the scale sqrt|p| of the cluster, even
//    next to the triple root. A double-precision closed form for it, then
//    Newton; then Newton on p itself where r = t - c2/3 cancelled (a real
//    root far slower than c2/3, as at the Maxwell end of the lower branch).
//  - the pair from the identities exact at a root, a = (c2 c1 - c0)/(r^2 + c1)
//    and b = -c0/r (c2 c1 - c0 = beta kappa2, formed without cancellation),
//    omega^2 = b - a^2/4, exactly 0 at a double or triple root.
// Accurate to ~2^-256 over the distance to the boundary, so omega^2 has the
// regime's sign except within ~1e-70 of it; a complex pair there gets the
// least positive normal double (tau_c ~ 1e154/wn).
Spectrum WideSpectrum(const ExactInputs& in, Regime regime, double wn) {
  Wide c2, c1, c0, arm;  // s^3 + c2 s^2 + c1 s + c0 in units of wn, arm = c2 c1 - c0
  if (in.from_model) {
    const Wide k2 = in.stiffness2, w = wn, mass_w2 = Wide(in.mass) * w * w;
    c2 = k2 / (Wide(in.damping) * w);
    c1 = (Wide(in.stiffness1) + k2) / mass_w2;  // 1 to rounding of wn
    c0 = c2 * Wide(in.stiffness1) / mass_w2;
    arm = c2 * k2 / mass_w2;
  } else {
    c2 = in.beta;
    c1 = Wide(in.kappa1) + Wide(in.kappa2);
    c0 = c2 * Wide(in.kappa1);
    arm = c2 * Wide(in.kappa2);
  }
  const Wide shift = c2 / 3;  // s = t - c2/3
  Wide r = -shift;            // the triple root
  if (regime != Regime::kTripleRoot) {
    const Wide p = c1 - c2 * shift;
    const Wide q = c0 - shift * c1 + 2 * shift * shift * shift;
    // In units of 2^k ~ the cluster's size (an exact scaling), so that the
    // double-precision estimate neither overflows nor underflows.
    int exponent_p = 0, exponent_q = 0;
    frexp(p, &exponent_p);
    frexp(q, &exponent_q);
    const int k = std::max(exponent_p / 2, exponent_q / 3);
    const Wide ps = ldexp(p, -2 * k), qs = ldexp(q, -3 * k);
    // With t = m y, m = sqrt(|p|/3): y^3 + 3 sgn(p) y = c, c = -q/m^3, whose
    // root is 2 sinh(asinh(c/2)/3) for p > 0, and for p < 0 has the sign of c
    // and modulus 2 cos(acos(|c|/2)/3) or 2 cosh(acosh(|c|/2)/3).
    const double pd = static_cast<double>(ps), qd = static_cast<double>(qs);
    double t0 = -std::cbrt(qd);
    if (pd != 0.0) {
      const double m = std::sqrt(std::abs(pd) / 3.0), c = -qd / (m * m * m);
      const double half = std::abs(c) / 2.0, sign_c = c < 0.0 ? -1.0 : 1.0;
      const double y = pd > 0.0      ? 2.0 * std::sinh(std::asinh(c / 2.0) / 3.0)
                       : half <= 1.0 ? sign_c * 2.0 * std::cos(std::acos(half) / 3.0)
                                     : sign_c * 2.0 * std::cosh(std::acosh(half) / 3.0);
      if (std::isfinite(m * y)) t0 = m * y;
    }
    Wide t = t0;
    for (int i = 0; i < 8; ++i) {  // 53 -> 106 -> 212 -> 256 bits
      const Wide slope = 3 * t * t + ps;
      if (slope == 0) break;
      const Wide step = ((t * t + ps) * t + qs) / slope;
      t -= step;
      if (abs(step) <= ldexp(abs(t), -250)) break;
    }
    r = ldexp(t, k) - shift;
    if (abs(r) < ldexp(shift, -32)) {  // 32+ bits lost: polish on p while |p(r)| drops
      const auto cubic = [&](const Wide& x) { return ((x + c2) * x + c1) * x + c0; };
      Wide residual = abs(cubic(r));
      for (int i = 0; i < 8 && residual > 0; ++i) {
        const Wide next = r - cubic(r) / ((3 * r + 2 * c2) * r + c1);
        const Wide next_residual = abs(cubic(next));
        if (!(next_residual < residual)) break;
        r = next;
        residual = next_residual;
      }
    }
  }
  const Wide a = arm / (r * r + c1), b = -c0 / r, pair = a / 2;
  const bool multiple = regime == Regime::kDoubleRoot || regime == Regime::kTripleRoot;
  const Wide omega2 = multiple ? Wide(0) : Wide(b - pair * pair);
  Spectrum s;
  s.r = static_cast<double>(r);
  s.a = static_cast<double>(a);
  s.b = static_cast<double>(b);
  s.p = static_cast<double>(pair);
  s.omega2 = static_cast<double>(omega2);
  s.q_r = static_cast<double>((r + pair) * (r + pair) + omega2);  // (r - s2)(r - s3)
  if (regime == Regime::kComplexPair) {
    s.omega2 = std::max(s.omega2, std::numeric_limits<double>::min());
  } else {
    s.omega2 = std::min(s.omega2, 0.0);
  }
  return s;
}

// The discriminant of p(s) = s^3 + beta s^2 + k s + beta kappa1 over the sum
// of its terms' magnitudes, in double. Every term is scaled by the same power
// of two, so that the largest is ~1 whatever the magnitudes (beta from 1e-300
// to 1e300): nothing overflows, what underflows is below eps of the sum, and
// the rounding is that of the plain products, ~16 eps of the sum.
double RelativeDiscriminant(double beta, double k, double kappa1) {
  int e2 = 0, e1 = 0, e_kappa = 0;
  const double m2 = std::frexp(beta, &e2), m1 = std::frexp(k, &e1);
  const double m0 = m2 * std::frexp(kappa1, &e_kappa);  // c0 = beta kappa1: cannot underflow
  const int e0 = e2 + e_kappa;
  struct Term {
    double coefficient;
    int n2, n1, n0;  // powers of c2, c1, c0
  };
  constexpr std::array<Term, 5> kTerms = {
      {{18, 1, 1, 1}, {-4, 3, 0, 1}, {1, 2, 2, 0}, {-4, 0, 3, 0}, {-27, 0, 0, 2}}};
  const auto exponent = [&](const Term& t) { return t.n2 * e2 + t.n1 * e1 + t.n0 * e0; };
  int top = exponent(kTerms[0]);
  for (const Term& t : kTerms) top = std::max(top, exponent(t));
  double disc = 0.0, size = 0.0;
  for (const Term& t : kTerms) {
    double v = t.coefficient;
    for (int i = 0; i < t.n2; ++i) v *= m2;
    for (int i = 0; i < t.n1; ++i) v *= m1;
    for (int i = 0; i < t.n0; ++i) v *= m0;
    v = std::ldexp(v, exponent(t) - top);
    disc += v;
    size += std::abs(v);
  }
  return disc / size;
}

// The scaled system z' = B z, z = [u, v, d], z(0) = [0, 1, 0], evaluated by
// the exact Cayley-Hamilton (Newton divided-difference) form of the matrix
// exponential. With r a real root of the characteristic cubic p(s) and
// Q(s) = s^2 + a s + b = p(s)/(s - r) the quadratic of the other two roots
// (-P +- i omega, omega^2 = b - P^2 of either sign):
//
//   exp(B tau) = c0 I + c1 B + g Q(B),
//   c1 = exp(-P tau) S,  c0 = exp(-P tau) (C + P S),   (the interpolant of
//        e^{s tau} at the pair: C = cos(omega tau), S = sin(omega tau)/omega,
//        both entire in omega^2, so cosh/sinh for omega^2 < 0, 1 and tau at 0)
//   g  = the second divided difference of e^{s tau} at r and the pair,
//
// and, since Q(B) z(0) = [a, r a, r],
//   u = c1 + a g,  v = c0 + r a g,  d = c1 + r g.
// This is exp(B tau) z(0) for any B with these eigenvalues, defective or not:
// it runs unchanged through complex, double, triple and three distinct real
// roots. g is summed from its Taylor series in the scaled nodes
// X = (r + P) tau, Y = omega^2 tau^2 when they are small (X^2 + |Y| <= 9/4:
// no cancellation, which covers short times and the triple root), and
// otherwise from (e^{r tau} - c0 - c1 r)/Q(r), where Q(r) tau^2 is then not
// small; d is rearranged there as (r (e^{r tau} - c2) + b c1)/Q(r),
// c2 = exp(-P tau)(C - P S), which avoids the cancellation of c1 against r g
// when the K2-C arm is fast (r ~ -beta).
//
// r and the pair come from the exact identities at a root of p,
//   a = beta kappa2/(r^2 + kappa1 + kappa2),  b = -beta kappa1/r,
// free of cancellation; r is the real root farthest from the other two (an
// eigen-solver's estimate polished by Newton on p). Near the triple root r is
// only known to ~eps^(1/3), but a and b are computed from it so that
// (s - r)(s^2 + a s + b) = p(s) to rounding: the formula is then exact for a
// cubic within rounding of the true one, which is all the problem allows.
//
// Padé scaling and squaring (Eigen's MatrixFunctions exp) agrees with this to
// ~1e-15 over a few natural periods, but on a near-defective spectrum its
// error grows like eps (rho tau)^2 or worse: near the double- and triple-root
// boundaries, where the kinematic contact time diverges, it gave O(1) errors
// and spurious separations (docs/fitting.md).
//
// Every value is returned times exp(mu tau), mu the slowest decay rate, so that
// nothing underflows however long contact lasts.
class ScaledSystem {
 public:
  // `exact` is where the regime is decided from: the model, or these rates.
  ScaledSystem(const PoyntingThomsonRates& rates, const ExactInputs& exact)
      : kappa1_(rates.kappa1), kappa2_(rates.kappa2), beta_(rates.beta) {
    const double k = kappa1_ + kappa2_;  // 1 to rounding; kept for consistency with B
    Mat3 b_matrix;
    b_matrix << 0.0, 1.0, 0.0,    //
        -kappa1_, 0.0, -kappa2_,  //
        0.0, 1.0, -beta_;
    const Eigen::EigenSolver<Mat3> solver(b_matrix, /*computeEigenvectors=*/false);
    std::array<std::complex<double>, 3> ev;
    for (int i = 0; i < 3; ++i) ev[static_cast<std::size_t>(i)] = solver.eigenvalues()[i];
    r_ = IsolatedRealRoot(ev);
    PolishRoot();
    a_ = beta_ * kappa2_ / (r_ * r_ + k);
    b_ = -beta_ * kappa1_ / r_;
    p_ = 0.5 * a_;
    omega2_ = b_ - p_ * p_;
    double real_spread = omega2_ < 0.0 ? std::sqrt(-omega2_) : 0.0;
    // Q(r) = (r + P)^2 + omega^2 = (r - s2)(r - s3), without cancellation.
    q_r_ = omega2_ >= 0.0 ? (r_ + p_) * (r_ + p_) + omega2_
                          : (r_ + p_ - real_spread) * (r_ + p_ + real_spread);
    // The regime. The discriminant of p in double, from the rates and relative
    // to its terms' magnitudes, is within ~16 eps of the exact one (the
    // model's or the rates'; each rate is within 5 ulps of the model's):
    // beyond kAmbiguous its sign is certain and, when omega^2 agrees, the
    // double-precision roots stand (away from the boundaries nothing changes).
    // Closer, omega^2 would carry a relative error above ~1e-4, or the wrong
    // sign: the regime is then decided exactly (~2 us) and the roots
    // recomputed in 256 bits (~12 us), against ~3-5 us for a whole response
    // otherwise.
    const double disc = RelativeDiscriminant(beta_, k, kappa1_);
    constexpr double kAmbiguous = 1e-12;
    if (disc < -kAmbiguous && omega2_ > 0.0) {
      regime_ = Regime::kComplexPair;
    } else if (disc > kAmbiguous && omega2_ < 0.0) {
      regime_ = Regime::kThreeReal;
    } else {
      regime_ = ExactRegime(exact);
      const Spectrum wide = WideSpectrum(exact, regime_, rates.natural_frequency);
      r_ = wide.r;
      a_ = wide.a;
      b_ = wide.b;
      p_ = wide.p;
      omega2_ = wide.omega2;
      q_r_ = wide.q_r;
      real_spread = omega2_ < 0.0 ? std::sqrt(-omega2_) : 0.0;
    }
    // Slowest decay rate of the pair: P - sqrt(-omega^2) = b/(P + sqrt(-omega^2)).
    const double pair_slow = omega2_ >= 0.0 ? p_ : b_ / (p_ + real_spread);
    mu_ = std::max(0.0, std::min(-r_, pair_slow));
    complex_pair_ = regime_ == Regime::kComplexPair;
    omega_ = complex_pair_ ? std::sqrt(omega2_) : 0.0;
    pair_is_slowest_ = complex_pair_ && p_ <= -r_;
  }

  // e^{mu tau} times the scaled u, v, d.
  struct State {
    double u, v, d;
  };
  State At(double tau) const {
    const Pair pair = PairFunctions(tau);
    const double c0 = pair.c0, c1 = pair.c1;
    const double x = (r_ + p_) * tau, y = omega2_ * tau * tau;
    State z;
    if (x * x + std::abs(y) <= 2.25) {
      // g = e^{-P tau} tau^2 sum_k h_k/(k+2)!, h_k the complete homogeneous
      // symmetric polynomials of the nodes X, +-i sqrt(Y):
      // h_k = X h_{k-1} + (-Y)^{k/2} for even k.
      double h = 1.0, sum = 0.5, factorial = 2.0, even_power = 1.0;
      for (int k = 1; k <= 24; ++k) {
        h *= x;
        if (k % 2 == 0) {
          even_power *= -y;
          h += even_power;
        }
        factorial *= static_cast<double>(k + 2);
        sum += h / factorial;
      }
      const double g = tau * tau * std::exp((mu_ - p_) * tau) * sum;
      z.u = c1 + a_ * g;
      z.v = c0 + r_ * a_ * g;
      z.d = c1 + r_ * g;
    } else {
      const double e_r = std::exp((r_ + mu_) * tau);
      const double g = (e_r - c0 - c1 * r_) / q_r_;
      z.u = c1 + a_ * g;
      z.v = c0 + r_ * a_ * g;
      z.d = (r_ * (e_r - pair.c2) + b_ * c1) / q_r_;
    }
    return z;
  }

  // A quantity (times e^{mu tau}) and its derivative in tau.
  double Value(Quantity q, const State& z) const {
    switch (q) {
      case Quantity::kU:
        return z.u;
      case Quantity::kV:
        return z.v;
      case Quantity::kForce:
        return Force(z);
      case Quantity::kEnvelopeSlope:
        return z.v + p_ * z.u;
    }
    return 0.0;
  }
  double Slope(Quantity q, const State& z) const {
    // (e^{mu tau} f)' = e^{mu tau} (f' + mu f); u' = v, v' = -F, F' = (k1 + k2) v - k2 beta d.
    switch (q) {
      case Quantity::kU:
        return z.v + mu_ * z.u;
      case Quantity::kV:
        return -Force(z) + mu_ * z.v;
      case Quantity::kForce:
        return (kappa1_ + kappa2_) * z.v - kappa2_ * beta_ * z.d + mu_ * Force(z);
      case Quantity::kEnvelopeSlope:
        return -Force(z) + p_ * z.v + mu_ * (z.v + p_ * z.u);
    }
    return 0.0;
  }
  double Force(const State& z) const { return kappa1_ * z.u + kappa2_ * z.d; }

  double mu() const { return mu_; }
  bool complex_pair() const { return complex_pair_; }
  double omega() const { return omega_; }
  bool pair_is_slowest() const { return pair_is_slowest_; }
  double pair_decay() const { return p_; }
  double real_root() const { return r_; }
  double omega2() const { return omega2_; }
  Regime regime() const { return regime_; }

 private:
  // The real eigenvalue, or of three real ones the one farthest from the others.
  static double IsolatedRealRoot(const std::array<std::complex<double>, 3>& ev) {
    std::size_t best = 0;
    double best_gap = -1.0;
    bool any_complex = false;
    for (const auto& e : ev) any_complex = any_complex || e.imag() != 0.0;
    for (std::size_t i = 0; i < 3; ++i) {
      if (any_complex) {
        if (std::abs(ev[i].imag()) < std::abs(ev[best].imag())) best = i;
        continue;
      }
      double gap = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < 3; ++j) {
        if (j != i) gap = std::min(gap, std::abs(ev[i] - ev[j]));
      }
      if (gap > best_gap) {
        best_gap = gap;
        best = i;
      }
    }
    return ev[best].real();
  }

  double Cubic(double s) const {
    return ((s + beta_) * s + (kappa1_ + kappa2_)) * s + beta_ * kappa1_;
  }
  double CubicSlope(double s) const { return (3.0 * s + 2.0 * beta_) * s + (kappa1_ + kappa2_); }
  // Newton on p from the eigen-solver's estimate, kept inside (-beta, 0)
  // (every real root lies there: p(-beta) = -beta kappa2 < 0 < p(0)), and
  // stopped as soon as |p| stops decreasing.
  void PolishRoot() {
    r_ = std::clamp(r_, -beta_, -std::numeric_limits<double>::min());
    double residual = std::abs(Cubic(r_));
    for (int i = 0; i < 50 && residual > 0.0; ++i) {
      const double slope = CubicSlope(r_);
      if (slope == 0.0) break;
      const double next = r_ - Cubic(r_) / slope;
      if (!(next > -beta_ && next < 0.0)) break;
      const double next_residual = std::abs(Cubic(next));
      if (!(next_residual < residual)) break;
      r_ = next;
      residual = next_residual;
    }
  }

  // The pair's functions times e^{mu tau}: c1 = e^{-P tau} S, c0 = e^{-P tau}
  // (C + P S), c2 = e^{-P tau} (C - P S) = c1', with C = cos(omega tau),
  // S = sin(omega tau)/omega entire in omega^2 (series for |omega^2 tau^2| <= 1).
  // For a real pair, s = -sigma1, -sigma2 with sigma1 = P - w (which may be
  // tiny: the Maxwell limit) and sigma2 = P + w, the exponential forms
  // c0 = (sigma2 e^{-sigma1 tau} - sigma1 e^{-sigma2 tau})/(2w) and
  // c2 = (sigma2 e^{-sigma2 tau} - sigma1 e^{-sigma1 tau})/(2w) avoid forming
  // C - P S as a difference of two nearly equal terms.
  struct Pair {
    double c0, c1, c2;
  };
  Pair PairFunctions(double tau) const {
    const double q = omega2_ * tau * tau;
    if (std::abs(q) <= 1.0) {
      double cs = 0.0, ss = 0.0, term = 1.0;
      for (int n = 0; n < 12; ++n) {
        cs += term;
        ss += term / static_cast<double>(2 * n + 1);
        term *= -q / static_cast<double>((2 * n + 1) * (2 * n + 2));
      }
      const double e = std::exp((mu_ - p_) * tau);
      const double c = e * cs, sn = e * tau * ss;
      return {c + p_ * sn, sn, c - p_ * sn};
    }
    if (q > 0.0) {
      const double e = std::exp((mu_ - p_) * tau);
      const double c = e * std::cos(omega_ * tau), sn = e * std::sin(omega_ * tau) / omega_;
      return {c + p_ * sn, sn, c - p_ * sn};
    }
    const double w = std::sqrt(-omega2_);
    const double sigma1 = b_ / (p_ + w), sigma2 = p_ + w;
    const double e1 = std::exp((mu_ - sigma1) * tau), e2 = std::exp((mu_ - sigma2) * tau);
    const double two_w = 2.0 * w;
    return {(sigma2 * e1 - sigma1 * e2) / two_w, (e1 - e2) / two_w,
            (sigma2 * e2 - sigma1 * e1) / two_w};
  }

  double kappa1_, kappa2_, beta_;
  double r_ = 0.0, a_ = 0.0, b_ = 0.0, p_ = 0.0, omega2_ = 0.0, q_r_ = 0.0;
  double mu_ = 0.0, omega_ = 0.0;
  Regime regime_ = Regime::kComplexPair;
  bool complex_pair_ = false;
  bool pair_is_slowest_ = false;
};

// The root of g = Value(q) in [lo, hi], where g(lo) > 0 >= g(hi) (or the
// reverse with `negate`) and the bracket holds exactly one sign change: TOMS
// 748 to a few ulps, then one Newton step that lands within rounding.
double RootOf(const ScaledSystem& sys, Quantity q, bool negate, double lo, double hi) {
  const double sign = negate ? -1.0 : 1.0;
  const auto g = [&](double tau) { return sign * sys.Value(q, sys.At(tau)); };
  const double g_lo = g(lo), g_hi = g(hi);
  if (g_hi == 0.0) return hi;
  if (!(g_lo > 0.0) || !(g_hi < 0.0)) {
    throw std::logic_error(
        fmt::format("Poynting-Thomson: bracket [{}, {}] does not change sign ({}, {}) (a bug)", lo,
                    hi, g_lo, g_hi));
  }
  std::uintmax_t iterations = 100;
  const auto [a, b] = boost::math::tools::toms748_solve(
      g, lo, hi, g_lo, g_hi, boost::math::tools::eps_tolerance<double>(50), iterations);
  double tau = 0.5 * (a + b);
  const ScaledSystem::State z = sys.At(tau);
  const double slope = sys.Slope(q, z);
  if (slope != 0.0) {
    const double newton = tau - sys.Value(q, z) / slope;
    if (newton >= a && newton <= b) tau = newton;
  }
  return tau;
}

// First zero after `start` of a quantity that is > 0 on (0, start] and, once
// it crosses 0, stays negative for longer than the crossing time itself
// (proven for x1' and the force in docs/fitting.md): doubling from `start`
// cannot step over the negative stretch, so the bracket holds the first root.
double FirstRootByDoubling(const ScaledSystem& sys, Quantity q, double start) {
  double lo = start;
  for (int k = 0; k < 1100; ++k) {
    const double hi = 2.0 * lo;
    const double g_hi = sys.Value(q, sys.At(hi));
    if (!std::isfinite(g_hi)) break;
    if (g_hi <= 0.0) return RootOf(sys, q, false, lo, hi);
    lo = hi;
  }
  throw std::logic_error(fmt::format(
      "Poynting-Thomson: no sign change found by doubling from tau = {} (a bug)", start));
}

// Where contact ends in scaled time, and ln e, ln of the peak compression.
struct ScaledResponse {
  double tau_contact = 0.0;
  double log_restitution = 0.0;
  double tau_peak = 0.0;
  double peak_u = 0.0;  // u at the peak
};

[[noreturn]] void ThrowPoyntingThomsonNoKinematicSeparation(const PoyntingThomsonRates& r,
                                                            const std::string& why) {
  throw NoSeparationError(fmt::format(
      "Poynting-Thomson with kappa1 = K1/(K1+K2) = {:.6g}, beta = K2/(C wn) = {:.6g}: with "
      "kinematic separation the compression never returns to 0 ({}), so contact never ends; use "
      "force separation",
      r.kappa1, r.beta, why));
}

// Without a complex pair x1 never returns to 0: a sum of three decaying
// exponentials (polynomials times exponentials at a multiple root) has at most
// two zeros counted with multiplicity, one is at t = 0, and it ends positive.
void RequireComplexPair(const ScaledSystem& sys, const PoyntingThomsonRates& r) {
  switch (sys.regime()) {
    case Regime::kComplexPair:
      return;
    case Regime::kThreeReal:
      ThrowPoyntingThomsonNoKinematicSeparation(
          r,
          "the characteristic cubic has three real roots: x1 is a sum of three decaying "
          "exponentials that stays positive");
    case Regime::kDoubleRoot:
      ThrowPoyntingThomsonNoKinematicSeparation(
          r,
          "the characteristic cubic has three real roots, two of them equal: x1 is a sum of "
          "decaying exponentials, one times a polynomial in t, that stays positive");
    case Regime::kTripleRoot:
      ThrowPoyntingThomsonNoKinematicSeparation(
          r,
          "the characteristic cubic has three real roots, all equal: x1 is a decaying "
          "exponential times a polynomial in t that stays positive");
  }
}

// Kinematic contact end: first zero of u after the peak. x1 = exp(-P tau) g,
// where g is a sinusoid of frequency omega plus a positive exponential, so
// zeros only occur where the sinusoid is negative, where g is convex: one dip
// per slow period, and none before tau = pi/omega. Sampled every (pi/omega)/16
// from the peak, with every local minimum of g between samples located and
// tested. Minima of g, not of x1: g' = exp(P tau)(x1' + P x1) is a sinusoid
// plus a monotone exponential, whose sign changes samples catch, while x1'
// can be negative but for a stretch far shorter than a sample around a narrow
// dip (the pair decaying about as fast as the real root, near the triple
// root: there x1's maximum and minimum both fell between two samples and a
// later period's dip was reported).
double KinematicEnd(const ScaledSystem& sys, const PoyntingThomsonRates& r, double tau_peak) {
  RequireComplexPair(sys, r);
  const double h = pi / (kSamplesPerHalfPeriod * sys.omega());
  // If the real root decays more slowly than the pair, x1 can only cross in
  // its first slow period; otherwise it crosses eventually, and 200 periods is
  // a guard (e would be below exp(-400 pi P/omega)).
  const double periods = sys.pair_is_slowest() ? 200.0 : 2.0;
  const double end = tau_peak + periods * 2.0 * pi / sys.omega();
  ScaledSystem::State z = sys.At(tau_peak);
  for (int i = 1;; ++i) {
    const double tau = tau_peak + (i - 1) * h, tau_next = tau_peak + i * h;
    if (tau >= end) break;
    const ScaledSystem::State z_next = sys.At(tau_next);
    if (z_next.u <= 0.0) return RootOf(sys, Quantity::kU, false, tau, tau_next);
    if (sys.Value(Quantity::kEnvelopeSlope, z) < 0.0 &&
        sys.Value(Quantity::kEnvelopeSlope, z_next) > 0.0) {  // a local minimum of g
      const double tau_min = RootOf(sys, Quantity::kEnvelopeSlope, true, tau, tau_next);
      if (sys.At(tau_min).u <= 0.0) return RootOf(sys, Quantity::kU, false, tau, tau_min);
    }
    z = z_next;
  }
  if (sys.pair_is_slowest()) {
    ThrowPoyntingThomsonNoKinematicSeparation(
        r, fmt::format("it has not returned after 200 periods of the slow oscillation, tau = {:.6g}"
                       "; e would be below exp({:.6g})",
                       end, -sys.pair_decay() * end));
  }
  ThrowPoyntingThomsonNoKinematicSeparation(
      r,
      "the real root decays more slowly than the complex pair and x1 reaches a positive "
      "minimum before the dip that could take it below 0");
}

ScaledResponse Solve(const PoyntingThomsonRates& r, const ExactInputs& exact,
                     Separation separation) {
  const ScaledSystem sys(r, exact);
  if (separation == Separation::kKinematic) RequireComplexPair(sys, r);
  ScaledResponse out;
  // Peak: first zero of x1'. x1' > 0 on (0, sqrt 2) (the scaled force is at
  // most u <= tau there), so doubling starts at tau = 1.
  out.tau_peak = FirstRootByDoubling(sys, Quantity::kV, 1.0);
  out.peak_u = sys.At(out.tau_peak).u * std::exp(-sys.mu() * out.tau_peak);

  if (separation == Separation::kForce) {
    // The force stays positive while x1' > 0 (d is x1' low-pass filtered), so
    // it ends after the peak.
    out.tau_contact = FirstRootByDoubling(sys, Quantity::kForce, out.tau_peak);
  } else {
    out.tau_contact = KinematicEnd(sys, r, out.tau_peak);
  }
  // e = |x1'| at separation; in logs so that it stays finite where e underflows.
  out.log_restitution = std::log(std::abs(sys.At(out.tau_contact).v)) - sys.mu() * out.tau_contact;
  return out;
}

ContactResponse ToPhysical(const ScaledResponse& s, const PoyntingThomsonRates& r, double v,
                           Separation separation) {
  ContactResponse out;
  out.separation = separation;
  out.contact_time = s.tau_contact / r.natural_frequency;
  out.log_restitution = s.log_restitution;
  out.restitution = std::exp(s.log_restitution);
  out.peak_time = s.tau_peak / r.natural_frequency;
  out.peak_compression = v / r.natural_frequency * s.peak_u;
  return out;
}

}  // namespace

PoyntingThomsonRates RatesOf(const PoyntingThomson& m) {
  CheckModel(m);
  const double k = m.stiffness1 + m.stiffness2;
  const double wn = std::sqrt(k / m.mass);
  // K2/(C wn) formed as (K2/C)/wn: C wn alone could overflow for huge C.
  return {wn, m.stiffness1 / k, m.stiffness2 / k, m.stiffness2 / m.damping / wn};
}

PoyntingThomsonRoots CharacteristicRoots(const PoyntingThomson& m) {
  const PoyntingThomsonRates r = RatesOf(m);
  const ScaledSystem sys(r, ExactOf(m));
  const double wn = r.natural_frequency;
  const double p = sys.pair_decay(), w2 = sys.omega2();
  PoyntingThomsonRoots out;
  out.complex_pair = sys.complex_pair();
  out.roots[0] = sys.real_root() * wn;
  if (out.complex_pair) {
    out.roots[1] = std::complex<double>(-p, std::sqrt(w2)) * wn;
    out.roots[2] = std::conj(out.roots[1]);
  } else {
    // -P -+ sqrt(-omega^2); the smaller in modulus as b / (P + sqrt(-omega^2)).
    const double w = std::sqrt(-w2);
    out.roots[1] = -(p + w) * wn;
    out.roots[2] = -(p * p + w2) / (p + w) * wn;
  }
  return out;
}

ContactResponse PoyntingThomsonContact(const PoyntingThomsonRates& r, double v,
                                       Separation separation) {
  CheckPoyntingThomsonRates(r);
  model_internal::CheckImpactSpeed(v);
  return ToPhysical(Solve(r, ExactOf(r), separation), r, v, separation);
}

ContactResponse PoyntingThomsonContact(const PoyntingThomson& m, double v, Separation separation) {
  const PoyntingThomsonRates r = RatesOf(m);
  CheckPoyntingThomsonRates(r);
  model_internal::CheckImpactSpeed(v);
  return ToPhysical(Solve(r, ExactOf(m), separation), r, v, separation);
}

PoyntingThomsonState PoyntingThomsonStateAt(const PoyntingThomson& m, double v, double t) {
  const PoyntingThomsonRates r = RatesOf(m);
  model_internal::CheckImpactSpeed(v);
  if (!(t >= 0.0)) throw std::invalid_argument(fmt::format("time must be >= 0, got {}", t));
  const ScaledSystem sys(r, ExactOf(m));
  const double tau = r.natural_frequency * t;
  const ScaledSystem::State z = sys.At(tau);
  const double undo_shift = std::exp(-sys.mu() * tau);
  const double length = v / r.natural_frequency * undo_shift;
  PoyntingThomsonState out;
  out.compression = length * z.u;
  out.velocity = v * undo_shift * z.v;
  out.node = length * (z.u - z.d);
  out.force = m.mass * r.natural_frequency * v * undo_shift * sys.Force(z);
  return out;
}

double PoyntingThomsonCompression(const PoyntingThomsonRates& r, double v, double t) {
  CheckPoyntingThomsonRates(r);
  const ScaledSystem sys(r, ExactOf(r));
  const double tau = r.natural_frequency * t;
  return v / r.natural_frequency * sys.At(tau).u * std::exp(-sys.mu() * tau);
}

PoyntingThomsonContactLaw::PoyntingThomsonContactLaw(const PoyntingThomson& model,
                                                     Separation separation)
    : rates_(RatesOf(model)), separation_(separation) {
  try {
    // From the model, not rates_: the regime is the model's (see ExactInputs).
    unit_response_ = PoyntingThomsonContact(model, 1.0, separation);
  } catch (const NoSeparationError& e) {
    no_separation_ = e.what();
  }
}

ContactResponse PoyntingThomsonContactLaw::Respond(double v) const {
  model_internal::CheckImpactSpeed(v);
  if (!unit_response_) throw NoSeparationError(no_separation_);
  ContactResponse out = *unit_response_;
  out.peak_compression *= v;
  return out;
}

double PoyntingThomsonContactLaw::Compression(double v, double t) const {
  return PoyntingThomsonCompression(rates_, v, t);
}

}  // namespace impactlab
