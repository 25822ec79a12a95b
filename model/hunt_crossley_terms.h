// The dimensionless Hunt-Crossley impact, templated on the scalar so that the
// fits differentiate it exactly with ceres::Jet (docs/contact-laws.md).
// Header-only: model/power_law_contact.h is the double-precision API.
//
// F = k x^n (1 + chi x'), M x'' = -F, x(0) = 0, x'(0) = v0. Scaled by the
// Hertz peak compression x* = ((n+1) M v0^2 / (2k))^(1/(n+1)) and the time
// x*/v0, with u = x/x*, w = x'/v0 and eps = chi v0:
//   u'' = -((n+1)/2) u^n (1 + eps w),   u(0) = 0, w(0) = 1.
// Energy: w dw/(1 + eps w) = -((n+1)/2) u^n du integrates exactly to
//   u^(n+1) = 2 (psi(eps) - psi(eps w)) / eps^2,   psi(y) = y - ln(1 + y),
// so (fitting-notes) the restitution obeys psi(-eps e) = psi(eps), i.e.
//   -eps e - ln(1 - eps e) = eps - ln(1 + eps),
// whatever k, M and n; and the peak is u_max^(n+1) = 2 psi(eps)/eps^2.
// Everything is written with psi2(y) = psi(y)/y^2 (-> 1/2 at y = 0), so that
// eps -> 0 (Hertz, e = 1) is a regular point and nothing is divided by eps.
//
// Contact time: dt = dx/x' becomes ds = 2 dw / ((n+1) u^n (1 + eps w)); in w
// the turning point is regular and only u = 0 is singular, like d^(-n/(n+1))
// in the distance d to it. The substitution d = rho^(n+1) removes that, and
// the integral over rho in [0, 1] is done by a fixed tanh-sinh rule (its
// nodes do not depend on the parameters, so Jets pass straight through).
#pragma once

#include <array>
#include <cmath>
#include <type_traits>
#include <vector>

namespace impactlab::hunt_crossley {

// psi(y)/y^2 = sum_{k>=2} (-y)^(k-2)/k for y > -1, to full relative precision.
template <typename T>
T Psi2(const T& y) {
  using std::abs;
  using std::log1p;
  if (abs(y) < 0.125) {
    // 18 terms of the series: |y|^18/20 < 1e-17.
    T sum = T(0.0);
    for (int k = 19; k >= 2; --k) sum = sum * (-y) + T(1.0 / k);
    return sum;
  }
  return (y - log1p(y)) / (y * y);
}

// The restitution of an impact at eps = chi v0 >= 0: e, and 1 - eps e (kept
// apart because it underflows against 1 for large eps: eps = 100 gives
// 1 - eps e ~ 1e-42, the speed at which the damping factor 1 + chi x' would
// vanish).
struct Exit {
  double restitution = 1.0;  // e
  double gap = 1.0;          // 1 - eps e, in (0, 1]
};

// psi(-y) = psi(eps) for y = eps e in (0, 1). psi(-y) is convex and
// increasing in y: Newton from above the root converges monotonically;
// psi(-y) >= y^2/2 bounds the root. Where y > 1/2 the iteration runs on
// z = 1 - y instead, -ln z - (1 - z) = psi(eps), from z = exp(-(psi + 1))
// below its root (convex, decreasing: monotone again).
inline Exit ExitOf(double eps) {
  if (!(eps > 0.0)) return {};
  const double target = eps * eps * Psi2(eps);  // psi(eps)
  const double half = 0.5 * 0.5 * Psi2(-0.5);   // psi(-1/2)
  if (target <= half) {
    double y = std::sqrt(2.0 * target);
    for (int i = 0; i < 100; ++i) {
      const double g = y * y * Psi2(-y) - target;
      const double step = g * (1.0 - y) / y;  // g / g'(y), g'(y) = y/(1 - y)
      y -= step;
      if (!(std::abs(step) > 1e-17 * y)) break;
    }
    return {y / eps, 1.0 - y};
  }
  // Beyond psi ~ 700 the gap exp(-(psi + 1)) underflows: e = 1/eps to every digit.
  if (target > 700.0) return {1.0 / eps, 0.0};
  double z = std::exp(-(target + 1.0));
  for (int i = 0; i < 100; ++i) {
    const double phi = -std::log(z) - (1.0 - z) - target;
    const double step = phi * z / (1.0 - z);  // -phi / phi'(z), phi' = -(1 - z)/z
    z += step;
    if (!(std::abs(step) > 1e-17 * z)) break;
  }
  return {(1.0 - z) / eps, z};
}

// e(eps) in T: the double root, then for Jets its exact derivative by the
// implicit-function theorem on psi(-eps e) = psi(eps):
//   de/deps = (gap/((1 + eps) e) - e) / eps,
// written for small eps (where it cancels) as one Newton step of
// f(e) = e^2 psi2(-eps e) - psi2(eps), f'(e) = e/gap, in T.
// `exit` is ExitOf(the value of eps), for a caller that has it already.
template <typename T>
T RestitutionOf(const T& eps, const Exit& exit) {
  if constexpr (std::is_same_v<T, double>) {
    return exit.restitution;
  } else {
    const double eps0 = eps.a;
    const double e0 = exit.restitution;
    if (eps0 < 0.5) {
      const T f = T(e0 * e0) * Psi2(T(-e0) * eps) - Psi2(eps);
      return T(e0) - f * T(exit.gap / e0);
    }
    const double slope = (exit.gap / ((1.0 + eps0) * e0) - e0) / eps0;
    return T(e0) + T(slope) * (eps - T(eps0));
  }
}

template <typename T>
T RestitutionOf(const T& eps) {
  if constexpr (std::is_same_v<T, double>) {
    return ExitOf(eps).restitution;
  } else {
    return RestitutionOf(eps, ExitOf(eps.a));
  }
}

// u_max = (2 psi2(eps))^(1/(n+1)).
template <typename T>
T PeakCompression(const T& n, const T& eps) {
  using std::pow;
  return pow(T(2.0) * Psi2(eps), T(1.0) / (n + T(1.0)));
}

// A fixed tanh-sinh rule on [0, 1]: nodes x_j = 1/(1 + exp(-pi sinh(j h))),
// weights w_j = h (pi/2) cosh(j h) / (2 cosh^2((pi/2) sinh(j h))). With h = 1/8
// over |j h| <= 3.25 the dropped tails are below 1e-16 and the discretisation
// error, for integrands analytic in a strip, is of order exp(-pi^2/h).
struct TanhSinhRule {
  static constexpr int kHalf = 26;
  static constexpr int kCount = 2 * kHalf + 1;
  std::array<double, kCount> node{};
  std::array<double, kCount> weight{};
};

inline const TanhSinhRule& UnitIntervalRule() {
  static const TanhSinhRule rule = [] {
    TanhSinhRule r;
    const double h = 1.0 / 8.0;
    const double half_pi = 2.0 * std::atan(1.0);
    for (int j = -TanhSinhRule::kHalf; j <= TanhSinhRule::kHalf; ++j) {
      const double t = j * h;
      const double s = half_pi * std::sinh(t);
      const double c = std::cosh(s);
      r.node[j + TanhSinhRule::kHalf] = 1.0 / (1.0 + std::exp(-2.0 * s));
      r.weight[j + TanhSinhRule::kHalf] = h * half_pi * std::cosh(t) / (2.0 * c * c);
    }
    return r;
  }();
  return rule;
}

// Dimensionless compression and restitution times for exponent n, eps, the
// restitution e and gap = 1 - eps e (ExitOf; passed in so that a caller that
// has them does not solve twice). d is the distance in w from the end where
// u = 0, scaled to [0, 1]:
//   compression  w = 1 - d,       u^(n+1) = d H_c(d),
//                H_c = 2/(1 + eps) - 2 d psi2(q)/(1 + eps)^2,  q = -eps d/(1 + eps);
//   restitution  w = -e (1 - d),  u^(n+1) = e^2 d H_r(d),
//                H_r = 2/gap - 2 d psi2(q)/gap^2,              q = eps e d/gap,
// (both exact rearrangements of psi(a) - psi(a + h) that keep every digit as
// d -> 0). For q > 1, where H_r's two terms cancel (gap -> 0), the same
// quantity is 2 (ln(1 + q) - q gap) / ((eps e)^2 d).
// With d = rho^(n+1): ds = 2 H_c^(-n/(n+1)) / (1 + eps w) drho (compression),
// 2 e (e^2 H_r)^(-n/(n+1)) / (1 + eps w) drho (restitution); 1 + eps w in
// restitution is gap + d eps e.
template <typename T>
struct Times {
  T compression;
  T restitution;
};

template <typename T>
T RestitutionShape(const T& eps_e, const T& gap, const T& d) {
  using std::log1p;
  const T q = eps_e * d / gap;
  if (q > T(1.0)) return T(2.0) * (log1p(q) - q * gap) / (eps_e * eps_e * d);
  return T(2.0) / gap - T(2.0) * d * Psi2(q) / (gap * gap);
}

// The restitution integrand peaks, for small gap, in a layer d ~ gap, i.e.
// rho ~ gap^(1/(n+1)), and falls like 1/rho above it: one rule cannot see
// both, so [0, 1] is cut at rho_s = gap^(1/(n+1)) and then geometrically (x4)
// up to 1, with the rule on each piece (gap < 1/4, i.e. eps > ~1.5).
inline std::vector<double> RestitutionPieces(double exponent, double gap) {
  std::vector<double> cuts{0.0};
  if (gap < 0.25) {
    for (double b = std::pow(gap, 1.0 / (exponent + 1.0)); b < 1.0; b *= 4.0) cuts.push_back(b);
  }
  cuts.push_back(1.0);
  return cuts;
}

// N, the exponent's type, is T when n is fitted and double when it is
// fixed: the nodes' powers d = rho^(n+1) and the integrands' exponent are
// then plain doubles, and a Jet's pow takes a double exponent (half the
// work of pow(Jet, Jet), which is most of a fit's time).
template <typename T, typename N = T>
Times<T> ContactTimes(const N& n, const T& eps, const T& e, const T& gap) {
  using std::pow;
  const TanhSinhRule& rule = UnitIntervalRule();
  const T one(1.0);
  const N n_plus_one = n + N(1.0);
  const N power = -n / n_plus_one;
  const T lead = one + eps;
  const T eps_e = eps * e;
  Times<T> out{T(0.0), T(0.0)};
  for (int j = 0; j < TanhSinhRule::kCount; ++j) {
    const T d = T(pow(N(rule.node[j]), n_plus_one));
    const T h_c = T(2.0) / lead - T(2.0) * d * Psi2(-eps * d / lead) / (lead * lead);
    out.compression += T(rule.weight[j]) * T(2.0) * pow(h_c, power) / (one + eps * (one - d));
  }
  const auto value = [](const auto& x) {
    if constexpr (std::is_same_v<std::decay_t<decltype(x)>, double>) {
      return x;
    } else {
      return x.a;
    }
  };
  const std::vector<double> cuts = RestitutionPieces(value(n), value(gap));
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double a = cuts[k], width = cuts[k + 1] - cuts[k];
    for (int j = 0; j < TanhSinhRule::kCount; ++j) {
      const T d = T(pow(N(a + width * rule.node[j]), n_plus_one));
      const T h_r = RestitutionShape(eps_e, gap, d);
      out.restitution +=
          T(width * rule.weight[j]) * T(2.0) * e * pow(e * e * h_r, power) / (gap + d * eps_e);
    }
  }
  return out;
}

}  // namespace impactlab::hunt_crossley
