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

void CheckRates(const PoyntingThomsonRates& r) {
  const auto bad = [](double x) { return !(x > 0.0) || !std::isfinite(x); };
  if (bad(r.natural_frequency) || bad(r.kappa1) || bad(r.kappa2) || bad(r.beta)) {
    throw std::invalid_argument(fmt::format(
        "Poynting-Thomson rates must be > 0 and finite, got wn = {}, kappa1 = {}, kappa2 = {}, "
        "beta = {}",
        r.natural_frequency, r.kappa1, r.kappa2, r.beta));
  }
}

void CheckSpeed(double v) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    throw std::invalid_argument(fmt::format("an impact speed must be > 0, got {}", v));
  }
}

// The functionals of the state the searches look at.
enum class Quantity { kU, kV, kForce };

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
  explicit ScaledSystem(const PoyntingThomsonRates& rates)
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
    const double real_spread = omega2_ < 0.0 ? std::sqrt(-omega2_) : 0.0;
    // Q(r) = (r + P)^2 + omega^2 = (r - s2)(r - s3), without cancellation.
    q_r_ = omega2_ >= 0.0 ? (r_ + p_) * (r_ + p_) + omega2_
                          : (r_ + p_ - real_spread) * (r_ + p_ + real_spread);
    // Slowest decay rate of the pair: P - sqrt(-omega^2) = b/(P + sqrt(-omega^2)).
    const double pair_slow = omega2_ >= 0.0 ? p_ : b_ / (p_ + real_spread);
    mu_ = std::max(0.0, std::min(-r_, pair_slow));
    complex_pair_ = omega2_ > 0.0;
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

[[noreturn]] void ThrowNoKinematicSeparation(const PoyntingThomsonRates& r,
                                             const std::string& why) {
  throw NoSeparationError(fmt::format(
      "Poynting-Thomson with kappa1 = K1/(K1+K2) = {:.6g}, beta = K2/(C wn) = {:.6g}: with "
      "kinematic separation the compression never returns to 0 ({}), so contact never ends; use "
      "force separation",
      r.kappa1, r.beta, why));
}

// Kinematic contact end: first zero of u after the peak. x1 = exp(-P tau) g,
// where g is a sinusoid of frequency omega plus a positive exponential, so
// zeros only occur where the sinusoid is negative, one dip per slow period, and
// none before tau = pi/omega. Sampled every (pi/omega)/16 from the peak, with
// every local minimum of u between samples located and tested.
double KinematicEnd(const ScaledSystem& sys, const PoyntingThomsonRates& r, double tau_peak) {
  if (!sys.complex_pair()) {
    ThrowNoKinematicSeparation(
        r,
        "the characteristic cubic has three real roots: x1 is a sum of three decaying "
        "exponentials that stays positive");
  }
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
    if (z.v < 0.0 && z_next.v > 0.0) {  // a local minimum of x1 between samples
      const double tau_min = RootOf(sys, Quantity::kV, true, tau, tau_next);
      if (sys.At(tau_min).u <= 0.0) return RootOf(sys, Quantity::kU, false, tau, tau_min);
    }
    z = z_next;
  }
  if (sys.pair_is_slowest()) {
    ThrowNoKinematicSeparation(
        r, fmt::format("it has not returned after 200 periods of the slow oscillation, tau = {:.6g}"
                       "; e would be below exp({:.6g})",
                       end, -sys.pair_decay() * end));
  }
  ThrowNoKinematicSeparation(
      r,
      "the real root decays more slowly than the complex pair and x1 reaches a positive "
      "minimum before the dip that could take it below 0");
}

ScaledResponse Solve(const PoyntingThomsonRates& r, Separation separation) {
  const ScaledSystem sys(r);
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
  const ScaledSystem sys(r);
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
  CheckRates(r);
  CheckSpeed(v);
  return ToPhysical(Solve(r, separation), r, v, separation);
}

ContactResponse PoyntingThomsonContact(const PoyntingThomson& m, double v, Separation separation) {
  return PoyntingThomsonContact(RatesOf(m), v, separation);
}

PoyntingThomsonState PoyntingThomsonStateAt(const PoyntingThomson& m, double v, double t) {
  const PoyntingThomsonRates r = RatesOf(m);
  CheckSpeed(v);
  if (!(t >= 0.0)) throw std::invalid_argument(fmt::format("time must be >= 0, got {}", t));
  const ScaledSystem sys(r);
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
  CheckRates(r);
  const ScaledSystem sys(r);
  const double tau = r.natural_frequency * t;
  return v / r.natural_frequency * sys.At(tau).u * std::exp(-sys.mu() * tau);
}

PoyntingThomsonContactLaw::PoyntingThomsonContactLaw(const PoyntingThomson& model,
                                                     Separation separation)
    : rates_(RatesOf(model)), separation_(separation) {
  try {
    unit_response_ = PoyntingThomsonContact(rates_, 1.0, separation);
  } catch (const NoSeparationError& e) {
    no_separation_ = e.what();
  }
}

ContactResponse PoyntingThomsonContactLaw::Respond(double v) const {
  CheckSpeed(v);
  if (!unit_response_) throw NoSeparationError(no_separation_);
  ContactResponse out = *unit_response_;
  out.peak_compression *= v;
  return out;
}

double PoyntingThomsonContactLaw::Compression(double v, double t) const {
  return PoyntingThomsonCompression(rates_, v, t);
}

}  // namespace impactlab
