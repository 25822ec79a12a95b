// Poynting-Thomson contact (model/poynting_thomson.h) against references
// computed here, independently of the code under test, in long double:
//
//  - FactorRef: the inverse Laplace transform by partial fractions over the
//    real root r and the quadratic of the other two roots, with the pair's
//    functions cos(omega t), sin(omega t)/omega summed as entire series in
//    omega^2 (so one formula serves complex, double and real pairs). It loses
//    accuracy only where r meets the pair (the triple root).
//  - TaylorRef: a 40-term Taylor propagator of z' = B z with step ||B h|| <=
//    1/2, for the neighbourhood of the triple root.
//  - Both find the peak and the contact end by fine scans and bisection.
//  - A few 25-digit values computed offline with Python's mpmath 1.3 (80
//    digits, residues at polished roots, bisection) check the references.
//  - The thesis's Appendix A closed forms (eq. 51-71, corrected; the OCR is
//    garbled) are cross-checks in each of the four cases.
//
// Tolerances: max(1e-9, 16 (cond + 1) eps) relative, cond being the relative
// condition number of the quantity with respect to M, K1, K2, C (central
// differences of the long-double reference). ln e also carries the absolute
// floor of e itself (its error is ~eps absolute, so cond(ln e) gains
// 1/|ln e|: a nearly elastic contact has ln e ~ 1e-12 known to ~1e-4 relative).
// Set IMPACTLAB_STABILITY_REPORT=1 to print the worst errors.
#include "model/poynting_thomson.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <unsupported/Eigen/MatrixFunctions>

#include "model/kelvin_voigt.h"
#include "model/pendulum.h"
#include "model/rebound_history.h"
#include "tests/support/precision.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using namespace testing;

constexpr double kStiffness = 4.6e5;  // lbf/in, the thesis's K avg

// ---------------------------------------------------------------------------
// Long-double references.

struct LdModel {
  LD mass, k1, k2, c;
};
LdModel Ld(const PoyntingThomson& m) { return {m.mass, m.stiffness1, m.stiffness2, m.damping}; }

// Scaled parameters: wn^2 = (K1 + K2)/M, kappa_i = K_i/(K1 + K2), beta = K2/(C wn).
struct Scaled {
  LD wn, k1, k2, beta;
};
Scaled ScaledOf(const LdModel& m) {
  const LD k = m.k1 + m.k2;
  const LD wn = sqrtl(k / m.mass);
  return {wn, m.k1 / k, m.k2 / k, m.k2 / m.c / wn};
}

// p(s) = s^3 + beta s^2 + s + beta kappa1.
LD Cubic(const Scaled& s, LD x) { return ((x + s.beta) * x + 1.0L) * x + s.beta * s.k1; }
LD CubicSlope(const Scaled& s, LD x) { return (3.0L * x + 2.0L * s.beta) * x + 1.0L; }

// A real root in (-beta, 0) by bisection to the last bit (p(-beta) < 0 < p(0)).
LD BisectRoot(const Scaled& s) {
  LD lo = -s.beta, hi = 0.0L;
  for (int i = 0; i < 20000; ++i) {
    const LD mid = 0.5L * (lo + hi);
    if (mid == lo || mid == hi) break;
    (Cubic(s, mid) < 0.0L ? lo : hi) = mid;
  }
  return 0.5L * (lo + hi);
}

// p(s) = (s - r)(s^2 + a s + b); a = beta kappa2/(1 + r^2), b = -beta kappa1/r
// (exact at a root, no cancellation). r is the root farthest from the others.
struct Factored {
  LD r, a, b, p, w2;  // pair -p +- sqrt(-w2)
};
Factored Factor(const Scaled& s) {
  const auto make = [&](LD root) {
    Factored f{};
    f.r = root;
    f.a = s.beta * s.k2 / (1.0L + root * root);
    f.b = -s.beta * s.k1 / root;
    f.p = 0.5L * f.a;
    f.w2 = f.b - f.p * f.p;
    return f;
  };
  Factored f = make(BisectRoot(s));
  if (f.w2 < 0.0L) {  // three real roots: take the isolated one
    std::array<LD, 3> roots = {f.r, -f.p - sqrtl(-f.w2), 0.0L};
    roots[2] = f.b / roots[1];
    for (LD& x : roots) {
      for (int i = 0; i < 8; ++i) {
        const LD slope = CubicSlope(s, x);
        if (slope != 0.0L) x -= Cubic(s, x) / slope;
      }
    }
    int best = 0;
    LD best_gap = -1.0L;
    for (int i = 0; i < 3; ++i) {
      LD gap = 1e300L;
      for (int j = 0; j < 3; ++j) {
        if (j != i) gap = std::min(gap, fabsl(roots[i] - roots[j]));
      }
      if (gap > best_gap) {
        best_gap = gap;
        best = i;
      }
    }
    f = make(roots[best]);
  }
  return f;
}

// e^{(mu - P) t} cos(w t) and e^{(mu - P) t} sin(w t)/w, entire in w2.
void PairBasis(LD p, LD w2, LD mu, LD t, LD* c, LD* sn) {
  const LD q = w2 * t * t;
  if (fabsl(q) <= 0.25L) {
    LD cs = 0.0L, ss = 0.0L, term = 1.0L;
    for (int n = 0; n < 30; ++n) {
      cs += term;
      ss += term / static_cast<LD>(2 * n + 1);
      term *= -q / static_cast<LD>((2 * n + 1) * (2 * n + 2));
    }
    const LD e = expl((mu - p) * t);
    *c = e * cs;
    *sn = e * t * ss;
  } else if (q > 0.0L) {
    const LD w = sqrtl(w2), e = expl((mu - p) * t);
    *c = e * cosl(w * t);
    *sn = e * sinl(w * t) / w;
  } else {
    const LD w = sqrtl(-w2);
    const LD ep = expl((mu - p + w) * t), em = expl((mu - p - w) * t);
    *c = 0.5L * (ep + em);
    *sn = 0.5L * (ep - em) / w;
  }
}

// The quantities a contact search looks at, all times e^{mu t}.
class Trajectory {
 public:
  virtual ~Trajectory() = default;
  virtual LD U(LD t) const = 0;  // x1
  virtual LD V(LD t) const = 0;  // x1'
  virtual LD F(LD t) const = 0;  // force / (M wn v0)
  virtual LD mu() const = 0;
};

// Partial fractions A/(s - r) + (B s + C)/(s^2 + a s + b) of N(s)/p(s).
class FactorRef final : public Trajectory {
 public:
  explicit FactorRef(const Scaled& s) : f_(Factor(s)) {
    u_ = Fractions(0.0L, 1.0L, s.beta);
    v_ = Fractions(1.0L, s.beta, 0.0L);
    force_ = Fractions(0.0L, 1.0L, s.beta * s.k1);
    const LD pair_slow = f_.w2 < 0.0L ? f_.p - sqrtl(-f_.w2) : f_.p;
    mu_ = std::min(-f_.r, pair_slow);
  }
  LD U(LD t) const override { return Eval(u_, t); }
  LD V(LD t) const override { return Eval(v_, t); }
  LD F(LD t) const override { return Eval(force_, t); }
  LD mu() const override { return mu_; }
  const Factored& factored() const { return f_; }

 private:
  struct Fraction {
    LD a, b, c;
  };
  Fraction Fractions(LD n2, LD n1, LD n0) const {
    const LD r = f_.r;
    const LD nr = (n2 * r + n1) * r + n0, qr = (r + f_.a) * r + f_.b;
    Fraction out{};
    out.a = nr / qr;
    out.b = n2 - out.a;
    out.c = (out.a * f_.b - n0) / r;
    return out;
  }
  LD Eval(const Fraction& fr, LD t) const {
    LD c, sn;
    PairBasis(f_.p, f_.w2, mu_, t, &c, &sn);
    return fr.a * expl((f_.r + mu_) * t) + fr.b * c + (fr.c - fr.b * f_.p) * sn;
  }
  Factored f_;
  Fraction u_{}, v_{}, force_{};
  LD mu_;
};

// z' = (B + mu) z by a 40-term Taylor propagator with ||B h|| <= 2 (the
// truncation 2^40/40! ~ 1e-36); every 16th state is cached as scans march on.
class TaylorRef final : public Trajectory {
 public:
  TaylorRef(const Scaled& s, LD mu) : s_(s), mu_(mu) {
    h_ = 2.0L / (2.0L + s.beta + s.k1 + s.k2 + fabsl(mu));
    const LD b[3][3] = {{mu, 1, 0}, {-s.k1, mu, -s.k2}, {0, 1, -s.beta + mu}};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) b_[i][j] = b[i][j];
    }
    // Columns of exp((B + mu) h): the series applied to each unit vector.
    for (int j = 0; j < 3; ++j) {
      std::array<LD, 3> unit{};
      unit[static_cast<std::size_t>(j)] = 1.0L;
      const std::array<LD, 3> col = Series(unit, h_);
      for (int i = 0; i < 3; ++i) step_[i][j] = col[static_cast<std::size_t>(i)];
    }
    cache_.push_back({0.0L, 1.0L, 0.0L});
  }
  LD U(LD t) const override { return At(t)[0]; }
  LD V(LD t) const override { return At(t)[1]; }
  LD F(LD t) const override {
    const auto z = At(t);
    return s_.k1 * z[0] + s_.k2 * z[2];
  }
  LD mu() const override { return mu_; }

 private:
  static constexpr std::size_t kStride = 16;
  std::array<LD, 3> Series(std::array<LD, 3> term, LD dt) const {
    std::array<LD, 3> sum = term;
    for (int k = 0; k < 40; ++k) {
      std::array<LD, 3> next{};
      for (int i = 0; i < 3; ++i) {
        next[static_cast<std::size_t>(i)] =
            (b_[i][0] * term[0] + b_[i][1] * term[1] + b_[i][2] * term[2]) * dt / (k + 1);
      }
      term = next;
      for (std::size_t i = 0; i < 3; ++i) sum[i] += term[i];
    }
    return sum;
  }
  std::array<LD, 3> Step(const std::array<LD, 3>& z) const {
    std::array<LD, 3> next{};
    for (int i = 0; i < 3; ++i) {
      next[static_cast<std::size_t>(i)] =
          step_[i][0] * z[0] + step_[i][1] * z[1] + step_[i][2] * z[2];
    }
    return next;
  }
  std::array<LD, 3> At(LD t) const {
    const auto n = static_cast<std::size_t>(floorl(t / h_));
    while (cache_.size() <= n / kStride) {
      std::array<LD, 3> z = cache_.back();
      for (std::size_t i = 0; i < kStride; ++i) z = Step(z);
      cache_.push_back(z);
    }
    std::array<LD, 3> z = cache_[n / kStride];
    for (std::size_t i = 0; i < n % kStride; ++i) z = Step(z);
    return Series(z, t - static_cast<LD>(n) * h_);
  }
  Scaled s_;
  LD mu_, h_;
  LD b_[3][3], step_[3][3];
  mutable std::vector<std::array<LD, 3>> cache_;
};

template <class G>
LD Bisect(const G& g, LD lo, LD hi) {
  for (int i = 0; i < 300; ++i) {
    const LD mid = 0.5L * (lo + hi);
    if (mid == lo || mid == hi) break;
    (g(mid) > 0.0L ? lo : hi) = mid;
  }
  return 0.5L * (lo + hi);
}

// The first sign change of g after `start`, with steps that grow by 3%, or
// of fixed length h.
template <class G>
std::optional<LD> ScanGeometric(const G& g, LD start, LD end) {
  for (LD t = start; t < end; t *= 1.03L) {
    if (g(t * 1.03L) <= 0.0L) return Bisect(g, t, t * 1.03L);
  }
  return std::nullopt;
}
template <class G>
std::optional<LD> ScanUniform(const G& g, LD start, LD h, LD end) {
  for (LD t = start; t < end; t += h) {
    if (g(t + h) <= 0.0L) return Bisect(g, t, t + h);
  }
  return std::nullopt;
}

struct RefContact {
  bool separates = true;
  LD contact_time = 0, log_restitution = 0, peak_time = 0, peak_compression = 0;
};

// `omega` (the pair's frequency, 0 for three real roots) only sets the
// kinematic scan's step, pi/(64 omega), and its end, 8 slow half-periods.
RefContact SolveRef(const Trajectory& m, const Scaled& s, LD omega, Separation separation) {
  RefContact c;
  const auto v = [&](LD t) { return m.V(t); };
  const LD tau_peak = *ScanGeometric(v, 0.01L, 1e12L);
  c.peak_time = tau_peak / s.wn;
  c.peak_compression = m.U(tau_peak) * expl(-m.mu() * tau_peak) / s.wn;
  std::optional<LD> end;
  if (separation == Separation::kKinematic) {
    const auto u = [&](LD t) { return m.U(t); };
    if (omega > 0.0L)
      end = ScanUniform(u, tau_peak, kPiL / omega / 64.0L, tau_peak + 8.0L * kPiL / omega);
  } else {
    const auto f = [&](LD t) { return m.F(t); };
    end = ScanGeometric(f, tau_peak, 1e12L);
  }
  if (!end) {
    c.separates = false;
    return c;
  }
  c.contact_time = *end / s.wn;
  c.log_restitution = logl(fabsl(m.V(*end))) - m.mu() * *end;
  return c;
}

// The reference for a model: FactorRef, or TaylorRef where r is within 0.05
// (scaled) of the pair (the triple root's neighbourhood).
RefContact Reference(const LdModel& model, Separation separation) {
  const Scaled s = ScaledOf(model);
  const FactorRef factored(s);
  const Factored& f = factored.factored();
  const LD omega = f.w2 > 0.0L ? sqrtl(f.w2) : 0.0L;
  const LD distance = sqrtl((f.r + f.p) * (f.r + f.p) + fabsl(f.w2));
  if (distance < 0.05L) return SolveRef(TaylorRef(s, factored.mu()), s, omega, separation);
  return SolveRef(factored, s, omega, separation);
}

// Relative condition numbers sum_p |d ln Q / d ln p| (p = M, K1, K2, C), by
// central differences of the reference with relative step `step`.
struct Conditions {
  double contact_time = 0, log_restitution = 0, peak_time = 0, peak_compression = 0;
};
Conditions ConditionOf(const LdModel& m, Separation separation, LD step) {
  Conditions cond;
  const RefContact base = Reference(m, separation);
  for (int p = 0; p < 4; ++p) {
    LdModel up = m, down = m;
    LD* up_field[] = {&up.mass, &up.k1, &up.k2, &up.c};
    LD* down_field[] = {&down.mass, &down.k1, &down.k2, &down.c};
    *up_field[p] *= 1.0L + step;
    *down_field[p] *= 1.0L - step;
    const RefContact hi = Reference(up, separation), lo = Reference(down, separation);
    const auto d = [&](LD RefContact::*q) {
      return static_cast<double>(fabsl((hi.*q - lo.*q) / (2.0L * step * base.*q)));
    };
    cond.contact_time += d(&RefContact::contact_time);
    cond.log_restitution += d(&RefContact::log_restitution);
    cond.peak_time += d(&RefContact::peak_time);
    cond.peak_compression += d(&RefContact::peak_compression);
  }
  return cond;
}

double Tolerance(double cond) { return std::max(1e-9, 16.0 * (cond + 1.0) * kEps); }

// Checks a model's response (v0 = 1) against the reference, both conventions.
void CheckAgainstReference(const std::string& where, const PoyntingThomson& model, LD cond_step,
                           double input) {
  for (const Separation separation : {Separation::kKinematic, Separation::kForce}) {
    const std::string name = where + " " + SeparationName(separation);
    const RefContact ref = Reference(Ld(model), separation);
    INFO(name << ": K1 = " << model.stiffness1 << ", K2 = " << model.stiffness2
              << ", C = " << model.damping);
    if (!ref.separates) {
      CHECK_THROWS_AS(PoyntingThomsonContact(model, 1.0, separation), NoSeparationError);
      continue;
    }
    const ContactResponse got = PoyntingThomsonContact(model, 1.0, separation);
    Conditions cond;  // interior points: the 1e-9 floor is far above cond * eps
    if (cond_step > 0.0L) cond = ConditionOf(Ld(model), separation, cond_step);
    CheckRel(name + " contact time", got.contact_time, ref.contact_time,
             Tolerance(cond.contact_time), input);
    CheckRel(
        name + " ln e", got.log_restitution, ref.log_restitution,
        Tolerance(cond.log_restitution + 1.0 / std::abs(static_cast<double>(ref.log_restitution))),
        input);
    CheckRel(name + " peak time", got.peak_time, ref.peak_time, Tolerance(cond.peak_time), input);
    CheckRel(name + " peak compression", got.peak_compression, ref.peak_compression,
             Tolerance(cond.peak_compression), input);
  }
}

// A model from its scaled form at the thesis's scale (M one bar, K1 + K2 = 4.6e5).
PoyntingThomson FromScaled(LD beta, LD kappa1) {
  const LD k = kStiffness, m = kBarMass;
  const LD wn = sqrtl(k / m);
  const LD k2 = (1.0L - kappa1) * k;
  return {kBarMass, static_cast<double>(kappa1 * k), static_cast<double>(k2),
          static_cast<double>(k2 / (beta * wn))};
}

std::string DistanceLabel(LD d) { return d >= 1e-7L ? "1e-6" : d >= 1e-10L ? "1e-9" : "1e-12"; }

// A point of the discriminant boundary: the double root -r (scaled), the
// simple root -(1 - r^2)/(2r); r < 1/sqrt 3 is the branch where the double
// root is the slow mode ("upper": large beta), r > 1/sqrt 3 where it is the
// fast one ("lower": beta -> 2, kappa1 -> 0); r = 1/sqrt 3 is the triple root.
struct BoundaryPoint {
  LD beta, kappa1;
};
BoundaryPoint OnBoundary(LD r) {
  return {(3.0L * r * r + 1.0L) / (2.0L * r), r * r * (1.0L - r * r) / (3.0L * r * r + 1.0L)};
}

// ---------------------------------------------------------------------------
// The thesis's Appendix A closed forms (eq. 51-71), corrected. Roots of
// p^3 - (K2/C) p^2 + D p - K1 K2/(C M) = 0 (eq. 50; s = -p), by Cardano
// (eq. 51-52; the OCR's "(A - B) sqrt3/4" is (A - B) sqrt3/2), then x1 and x2
// by the inverse transforms of eq. 48-49 in each case.
struct ThesisForms {
  LD z = 0;                   // K2/C
  std::vector<LD> p;          // the real decay rates (case III), or p1 (case I)
  LD pair_p = 0, pair_w = 0;  // case I: -P +- i w
  // x1 and x2 for v0 = 1 in the four cases.
  std::function<LD(LD)> x1, x2;
};

// Case I (d > 0): eq. 53-59 with the phase written as it must be
// (x1 = A e^{-p1 t} + R e^{-P t} sin(w t + phi), phi = atan2(w, z - P) -
// atan2(w, p1 - P); the OCR's signs are garbled).
ThesisForms CaseOne(const LdModel& m) {
  ThesisForms f;
  const LD z = m.k2 / m.c, dd = (m.k1 + m.k2) / m.mass, k0 = m.k1 * m.k2 / (m.c * m.mass);
  const LD a = dd - z * z / 3.0L;
  const LD b = (9.0L * z * dd - 2.0L * z * z * z - 27.0L * k0) / 27.0L;
  const LD d = sqrtl(b * b / 4.0L + a * a * a / 27.0L);
  const LD A = cbrtl(d - b / 2.0L), B = cbrtl(-d - b / 2.0L);
  const LD p1 = A + B + z / 3.0L, P = z / 3.0L - (A + B) / 2.0L, w = (A - B) * sqrtl(3.0L) / 2.0L;
  const LD den = (p1 - P) * (p1 - P) + w * w;
  const LD amp = sqrtl(((z - P) * (z - P) + w * w) / den) / w;
  const LD phi = atan2l(w, z - P) - atan2l(w, p1 - P);
  f.x1 = [=](LD t) {
    return (z - p1) / den * expl(-p1 * t) + amp * expl(-P * t) * sinl(w * t + phi);
  };
  const LD phi2 = -atan2l(w, p1 - P);
  f.x2 = [=](LD t) {
    return z / den * (expl(-p1 * t) + sqrtl(den) / w * expl(-P * t) * sinl(w * t + phi2));
  };
  f.z = z;
  f.p = {p1};
  f.pair_p = P;
  f.pair_w = w;
  return f;
}

// Case IIa (triple root p = K2/(3C)): eq. 61 and 63.
ThesisForms CaseTwoA(const LdModel& m) {
  ThesisForms f;
  const LD z = m.k2 / m.c, p = z / 3.0L;
  f.x1 = [=](LD t) { return (t + t * t * z / 3.0L) * expl(-p * t); };
  f.x2 = [=](LD t) { return t * t * z / 2.0L * expl(-p * t); };
  return f;
}

// Case IIb (p1 simple, P double): eq. 65 and 67 (the OCR drops eq. 65's t).
ThesisForms CaseTwoB(LD z, LD p1, LD P) {
  ThesisForms f;
  f.x1 = [=](LD t) {
    const LD g = p1 - P;
    return (z - p1) / (g * g) * expl(-p1 * t) +
           ((z - P) / g * t + (p1 - z) / (g * g)) * expl(-P * t);
  };
  f.x2 = [=](LD t) {
    const LD g = p1 - P;
    return z / (g * g) * (expl(-p1 * t) + (g * t - 1.0L) * expl(-P * t));
  };
  return f;
}

// Case III (three distinct real roots, d < 0): eq. 68-71.
ThesisForms CaseThree(const LdModel& m) {
  ThesisForms f;
  const LD z = m.k2 / m.c, dd = (m.k1 + m.k2) / m.mass, k0 = m.k1 * m.k2 / (m.c * m.mass);
  const LD a = dd - z * z / 3.0L;
  const LD b = (9.0L * z * dd - 2.0L * z * z * z - 27.0L * k0) / 27.0L;
  // Trigonometric form of Cardano for three real roots.
  const LD rho = sqrtl(-a / 3.0L), theta = acosl(-b / (2.0L * rho * rho * rho));
  std::vector<LD> p;
  for (int k = 0; k < 3; ++k)
    p.push_back(2.0L * rho * cosl((theta - 2.0L * kPiL * k) / 3.0L) + z / 3.0L);
  f.x1 = [=](LD t) {
    LD sum = 0.0L;
    for (int i = 0; i < 3; ++i) {
      LD den = 1.0L;
      for (int j = 0; j < 3; ++j) {
        if (j != i) den *= p[static_cast<std::size_t>(j)] - p[static_cast<std::size_t>(i)];
      }
      sum += (z - p[static_cast<std::size_t>(i)]) / den * expl(-p[static_cast<std::size_t>(i)] * t);
    }
    return sum;
  };
  f.x2 = [=](LD t) {
    LD sum = 0.0L;
    for (int i = 0; i < 3; ++i) {
      LD den = 1.0L;
      for (int j = 0; j < 3; ++j) {
        if (j != i) den *= p[static_cast<std::size_t>(j)] - p[static_cast<std::size_t>(i)];
      }
      sum += z / den * expl(-p[static_cast<std::size_t>(i)] * t);
    }
    return sum;
  };
  f.p = p;
  return f;
}

void CheckStateAgainst(const std::string& name, const PoyntingThomson& m, const ThesisForms& f,
                       double tol) {
  for (const double t : {2e-5, 1e-4, 2.5e-4, 5e-4, 1e-3}) {
    const PoyntingThomsonState s = PoyntingThomsonStateAt(m, 1.0, t);
    CheckRel(name + " x1(t)", s.compression, f.x1(t), tol, t, "t");
    CheckRel(name + " x2(t)", s.node, f.x2(t), tol, t, "t");
  }
}

// ---------------------------------------------------------------------------

TEST_CASE("poynting_thomson: matches the 25-digit mpmath values in every regime") {
  struct Case {
    double mass, k1, k2, c;
    std::vector<LD> kinematic, force;  // tau_c, ln e, peak, peak time (v0 = 1)
  };
  // Generated by an 80-digit mpmath script (docs/fitting.md): generic complex
  // pair; three real roots; 1e-9 from the upper boundary (r = 0.2); 1e-9 from
  // the triple root; the Kelvin-Voigt limit K2 = 1e6 K1; C large.
  const std::vector<Case> cases = {
      {0.0057825351878934977,
       300000,
       500000,
       20,
       {0.0004217634357147740353697829L, -0.615037552039902048623882L,
        0.0001071656945429120598478876L, 0.0001828228176460043393787482L},
       {0.0003595813149441919198918146L, -0.5020418686533210884668578L,
        0.0001071656945429120598478876L, 0.0001828228176460043393787482L}},
      {0.0057825351878934977,
       460,
       459540,
       17.174428387784793,
       {},
       {0.00289040831415224429467255L, -4.770201668283973589447788L,
        0.0003264668525393962385945479L, 0.001448355873296293407722049L}},
      {0.0057825351878934977,
       15771.4285872,
       444228.5714128,
       17.788063966615084,
       {53.32193076678271437700359L, -95116.28363675864884688447L, 0.0002403435402782817246671021L,
        0.0005684354648237269705315024L},
       {0.00112903311633780853474278L, -1.846931928564687004957306L,
        0.0002403435402782817246671021L, 0.0005684354648237269705315024L}},
      {0.0057825351878934977,
       51111.111162222223,
       408888.88883777778,
       26.468230501504287,
       {0.8219759864944798835709605L, -4223.53797103229185346699L, 0.00016311749430000253174576L,
        0.0003142161433073957256557542L},
       {0.0005825887691615898478415935L, -1.390562086800899643308664L,
        0.00016311749430000253174576L, 0.0003142161433073957256557542L}},
      {0.0057825351878934977,
       460000,
       460000000000,
       13.300000000000001,
       {0.0003551980311592495397555979L, -0.4084828890778026154137519L,
        0.00009295668701521962208896921L, 0.000162980103453775170485849L},
       {0.0003259602069075484182294816L, -0.3748589615294271881108819L,
        0.00009295668701521962208896921L, 0.000162980103453775170485849L}},
      {0.0057825351878934977,
       100000,
       360000,
       1000000,
       {0.0003522401299365882814551121L, -0.00004962035745755820497498471L,
        0.0001121200209727861370103819L, 0.0001761182940650813692111576L},
       {0.0003522330465261509558879192L, -0.00004961836176165561979444449L,
        0.0001121200209727861370103819L, 0.0001761182940650813692111576L}},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    const PoyntingThomson m{c.mass, c.k1, c.k2, c.c};
    for (const Separation sep : {Separation::kKinematic, Separation::kForce}) {
      const std::vector<LD>& want = sep == Separation::kKinematic ? c.kinematic : c.force;
      const std::string name = std::string("mpmath case ") + SeparationName(sep);
      const RefContact ref = Reference(Ld(m), sep);
      if (want.empty()) {
        CHECK_FALSE(ref.separates);
        CHECK_THROWS_AS(PoyntingThomsonContact(m, 1.0, sep), NoSeparationError);
        continue;
      }
      // The long-double references themselves, to near their precision
      // (cases 2 and 3 are 1e-9 from a boundary: cond ~ 5e8, and the
      // reference's backward error is ~20 long-double ulps).
      const double ref_tol = i == 2 || i == 3 ? 1e-8 : 1e-14;
      CheckRel(name + " reference tau_c", static_cast<double>(ref.contact_time), want[0], ref_tol,
               i);
      CheckRel(name + " reference ln e", static_cast<double>(ref.log_restitution), want[1], ref_tol,
               i);
      // The code under test: within 1e-12, or cond * eps near a boundary.
      const double tol = i == 2 || i == 3 ? 1e-6 : 1e-12;
      const ContactResponse got = PoyntingThomsonContact(m, 1.0, sep);
      CheckRel(name + " tau_c", got.contact_time, want[0], tol, i);
      CheckRel(name + " ln e", got.log_restitution, want[1],
               std::max(tol, 8 * kEps / std::abs(static_cast<double>(want[1]))), i);
      CheckRel(name + " peak", got.peak_compression, want[2], 1e-13, i);
      CheckRel(name + " peak time", got.peak_time, want[3], 1e-13, i);
    }
  }
}

TEST_CASE("poynting_thomson: agrees with long-double references for K2/K1 from 1e-6 to 1e6") {
  // beta = K2/(C wn) from 1e-3 (dashpot nearly rigid) to 1e6 (nearly free).
  for (const double ratio : LogSpace(1e-6, 1e6, 13)) {
    for (const double beta : LogSpace(1e-3, 1e6, 10)) {
      const PoyntingThomson m = FromScaled(beta, 1.0L / (1.0L + ratio));
      CheckAgainstReference("interior K2/K1", m, 0.0L, ratio);
    }
  }
}

TEST_CASE(
    "poynting_thomson: accurate to cond * eps at 1e-6, 1e-9, 1e-12 from the double-root "
    "boundaries") {
  // Upper branch (the double root is the slow mode: kinematic contact time
  // diverges on the complex side) and lower branch (the double root is fast).
  for (const LD r : {0.02L, 0.1L, 0.3L, 0.5L, 0.65L, 0.8L, 0.95L}) {
    const BoundaryPoint b = OnBoundary(r);
    for (const LD d : {1e-6L, 1e-9L, 1e-12L}) {
      for (const LD side : {-1.0L, 1.0L}) {
        const PoyntingThomson m = FromScaled(b.beta, b.kappa1 * (1.0L + side * d));
        const std::string where =
            std::string(r < 0.57L ? "upper" : "lower") + " double root, " + DistanceLabel(d);
        CheckAgainstReference(where, m, 0.1L * d, static_cast<double>(side * d));
      }
    }
  }
}

TEST_CASE("poynting_thomson: accurate to cond * eps at 1e-6, 1e-9, 1e-12 from the triple root") {
  const BoundaryPoint b = OnBoundary(1.0L / sqrtl(3.0L));
  for (const LD d : {1e-6L, 1e-9L, 1e-12L}) {
    for (const LD side : {-1.0L, 1.0L}) {
      CheckAgainstReference("triple root (K1), " + DistanceLabel(d),
                            FromScaled(b.beta, b.kappa1 * (1.0L + side * d)), 0.1L * d,
                            static_cast<double>(side * d));
      CheckAgainstReference("triple root (C), " + DistanceLabel(d),
                            FromScaled(b.beta * (1.0L + side * d), b.kappa1), 0.1L * d,
                            static_cast<double>(side * d));
    }
  }
}

TEST_CASE("poynting_thomson: the force convention is continuous across every regime boundary") {
  for (const LD r : {0.1L, 0.5L, 1.0L / sqrtl(3.0L), 0.8L}) {
    const BoundaryPoint b = OnBoundary(r);
    const ContactResponse below = PoyntingThomsonContact(
        FromScaled(b.beta, b.kappa1 * (1.0L - 1e-12L)), 1.0, Separation::kForce);
    const ContactResponse on =
        PoyntingThomsonContact(FromScaled(b.beta, b.kappa1), 1.0, Separation::kForce);
    const ContactResponse above = PoyntingThomsonContact(
        FromScaled(b.beta, b.kappa1 * (1.0L + 1e-12L)), 1.0, Separation::kForce);
    INFO("r = " << static_cast<double>(r));
    // A step of 2e-12 in K1 moves these smooth quantities by ~1e-12 at most.
    for (const ContactResponse& c : {below, above}) {
      CHECK(std::abs(c.contact_time / on.contact_time - 1.0) < 1e-11);
      CHECK(std::abs(c.log_restitution / on.log_restitution - 1.0) < 1e-11);
      CHECK(std::abs(c.peak_compression / on.peak_compression - 1.0) < 1e-11);
    }
  }
}

TEST_CASE(
    "poynting_thomson: kinematic contact time diverges toward the upper boundary, ln e stays "
    "finite") {
  const BoundaryPoint b = OnBoundary(0.2L);
  double previous_time = 0.0, previous_log_e = 0.0;
  for (const LD d : {1e-3L, 1e-6L, 1e-9L, 1e-12L}) {
    const ContactResponse c = PoyntingThomsonContact(FromScaled(b.beta, b.kappa1 * (1.0L + d)), 1.0,
                                                     Separation::kKinematic);
    CHECK(std::isfinite(c.log_restitution));
    CHECK(c.contact_time > 10.0 * previous_time);  // ~ d^(-1/2)
    CHECK(c.log_restitution < 10.0 * previous_log_e);
    previous_time = c.contact_time;
    previous_log_e = c.log_restitution;
  }
  CHECK(previous_log_e < -1e6);  // e = exp(-3e6) underflows to 0 ...
  CHECK(std::exp(previous_log_e) == 0.0);
}

TEST_CASE(
    "poynting_thomson: kinematic separation with three real roots is a clear NoSeparationError") {
  // Beyond the upper boundary: three real roots.
  const BoundaryPoint upper = OnBoundary(0.2L);
  const PoyntingThomson real_roots = FromScaled(upper.beta, upper.kappa1 * 0.5L);
  REQUIRE_FALSE(CharacteristicRoots(real_roots).complex_pair);
  CHECK_THROWS_AS(PoyntingThomsonContact(real_roots, 1.0, Separation::kKinematic),
                  NoSeparationError);
  CHECK_THROWS_WITH(PoyntingThomsonContact(real_roots, 1.0, Separation::kKinematic),
                    Catch::Contains("three real roots") && Catch::Contains("force separation"));
  // The force convention is fine there, and the law can still be built.
  const ContactResponse force = PoyntingThomsonContact(real_roots, 1.0, Separation::kForce);
  CHECK(force.restitution > 0.0);
  CHECK(force.restitution < 1.0);
  const PoyntingThomsonContactLaw law(real_roots, Separation::kKinematic);
  CHECK_THROWS_AS(law.Respond(1.0), NoSeparationError);
  // Near the lower branch, on its complex side, the slow real mode keeps x1 > 0.
  const BoundaryPoint lower = OnBoundary(0.8L);
  const PoyntingThomson slow_real = FromScaled(lower.beta, lower.kappa1 * (1.0L - 1e-6L));
  REQUIRE(CharacteristicRoots(slow_real).complex_pair);
  CHECK_THROWS_WITH(PoyntingThomsonContact(slow_real, 1.0, Separation::kKinematic),
                    Catch::Contains("positive minimum"));
}

TEST_CASE("poynting_thomson: the thesis's Appendix A closed forms agree in all four cases") {
  // Case I: one real root and a complex pair.
  const PoyntingThomson one{kBarMass, 3e5, 5e5, 20.0};
  REQUIRE(CharacteristicRoots(one).complex_pair);
  CheckStateAgainst("case I", one, CaseOne(Ld(one)), 1e-12);
  // Case III: three distinct real roots.
  const PoyntingThomson three = FromScaled(5.0L, 1e-3L);
  REQUIRE_FALSE(CharacteristicRoots(three).complex_pair);
  CheckStateAgainst("case III", three, CaseThree(Ld(three)), 1e-12);
  // Case IIa: the triple root (the double-precision parameters are within
  // rounding of it; x1(t) at moderate t is well conditioned).
  const BoundaryPoint cusp = OnBoundary(1.0L / sqrtl(3.0L));
  const PoyntingThomson triple = FromScaled(cusp.beta, cusp.kappa1);
  CheckStateAgainst("case IIa", triple, CaseTwoA(Ld(triple)), 1e-9);
  // Case IIb: a double root, upper (slow double) and lower (fast double) branch.
  for (const LD r : {0.2L, 0.8L}) {
    const BoundaryPoint b = OnBoundary(r);
    const PoyntingThomson m = FromScaled(b.beta, b.kappa1);
    const LD wn = ScaledOf(Ld(m)).wn;
    CheckStateAgainst("case IIb", m,
                      CaseTwoB(Ld(m).k2 / Ld(m).c, (1.0L - r * r) / (2.0L * r) * wn, r * wn), 1e-8);
  }
  // The Cardano roots of eq. 51-52 are those the code reports.
  const PoyntingThomsonRoots roots = CharacteristicRoots(one);
  const ThesisForms f = CaseOne(Ld(one));
  CHECK(std::abs(roots.roots[0].real() + static_cast<double>(f.p[0])) <
        1e-12 * std::abs(roots.roots[0]));
  CHECK(std::abs(std::abs(roots.roots[1].imag()) - static_cast<double>(f.pair_w)) <
        1e-12 * std::abs(roots.roots[1]));
}

TEST_CASE(
    "poynting_thomson: Eigen's Pade exponential of the scaled matrix agrees at critical damping") {
  // fitting-notes.md: exp(A t) stays accurate at critical damping where an
  // eigen-decomposition fails. On the double-root boundary, over a few natural
  // periods, Pade scaling and squaring of the SCALED state matrix and the
  // library agree to ~1e-15 (they part ways only over very long times, where
  // squaring a near-defective matrix loses digits; of the unscaled physical
  // matrix, with entries from 1 to (K1 + K2)/M ~ 1e8, Pade loses ~1e-10).
  const BoundaryPoint b = OnBoundary(0.3L);
  const PoyntingThomson m = FromScaled(b.beta, b.kappa1);
  const PoyntingThomsonRates r = RatesOf(m);
  Eigen::Matrix3d scaled;  // z = [u, v, d]
  scaled << 0, 1, 0, -r.kappa1, 0, -r.kappa2, 0, 1, -r.beta;
  const ContactResponse force = PoyntingThomsonContact(m, 1.0, Separation::kForce);
  for (int i = 1; i <= 8; ++i) {
    const double t = force.contact_time * i / 4.0;
    const Eigen::Vector3d z = (scaled * (r.natural_frequency * t)).exp().col(1);
    const PoyntingThomsonState s = PoyntingThomsonStateAt(m, 1.0, t);
    const double length = 1.0 / r.natural_frequency;
    CHECK(std::abs(s.compression - length * z[0]) < 1e-14 * length);
    CHECK(std::abs(s.compression - s.node - length * z[2]) < 1e-14 * length);
    CHECK(std::abs(s.velocity - z[1]) < 1e-14);
  }
}

TEST_CASE("poynting_thomson: C -> infinity is elastic with K1 + K2, C -> 0 elastic with K1") {
  const double k1 = 1e5, k2 = 3.6e5;
  const double wn_all = std::sqrt((k1 + k2) / kBarMass), wn_1 = std::sqrt(k1 / kBarMass);
  for (const Separation sep : {Separation::kKinematic, Separation::kForce}) {
    double previous = 1.0;
    for (const double c : {1e6, 1e8, 1e10}) {  // dashpot ever stiffer
      const ContactResponse r =
          PoyntingThomsonContact(PoyntingThomson{kBarMass, k1, k2, c}, 1.0, sep);
      const double err =
          std::abs(r.contact_time * wn_all / std::numbers::pi - 1.0) + std::abs(r.log_restitution);
      CHECK(err < previous / 50.0);  // O(1/C)
      CHECK(r.peak_compression * wn_all == Approx(1.0).epsilon(1e-3));
      previous = err;
    }
    CHECK(previous < 1e-5);
    previous = 1.0;
    for (const double c : {1e-2, 1e-4, 1e-6}) {  // dashpot ever freer
      const ContactResponse r =
          PoyntingThomsonContact(PoyntingThomson{kBarMass, k1, k2, c}, 1.0, sep);
      const double err =
          std::abs(r.contact_time * wn_1 / std::numbers::pi - 1.0) + std::abs(r.log_restitution);
      CHECK(err < previous / 50.0);  // O(C)
      CHECK(r.peak_compression * wn_1 == Approx(1.0).epsilon(1e-3));
      previous = err;
    }
    CHECK(previous < 1e-5);
  }
}

TEST_CASE(
    "poynting_thomson: K2 -> infinity is Kelvin-Voigt with K1 and C, K2 -> 0 is elastic with K1") {
  const KelvinVoigt kv{kBarMass, 4.6e5, 13.3};
  for (const Separation sep : {Separation::kKinematic, Separation::kForce}) {
    const ContactResponse want = KelvinVoigtContact(kv, 1.0, sep);
    double previous = 1.0;
    for (const double ratio : {1e4, 1e6, 1e8}) {
      const ContactResponse got = PoyntingThomsonContact(
          PoyntingThomson{kv.mass, kv.stiffness, ratio * kv.stiffness, kv.damping}, 1.0, sep);
      const double err = std::abs(got.contact_time / want.contact_time - 1.0) +
                         std::abs(got.log_restitution / want.log_restitution - 1.0) +
                         std::abs(got.peak_compression / want.peak_compression - 1.0);
      CHECK(err < previous / 50.0);  // O(K1/K2) per factor 100
      previous = err;
    }
    CHECK(previous < 1e-7);
    const ContactResponse elastic =
        PoyntingThomsonContact(PoyntingThomson{kv.mass, kv.stiffness, 1e-6, kv.damping}, 1.0, sep);
    CHECK(elastic.contact_time * std::sqrt(kv.stiffness / kv.mass) ==
          Approx(std::numbers::pi).epsilon(1e-9));
    CHECK(std::abs(elastic.log_restitution) < 1e-9);
  }
}

TEST_CASE("poynting_thomson: the response scales with the speed and with the units") {
  const PoyntingThomson m{kBarMass, 3e5, 5e5, 20.0};
  const ContactResponse one = PoyntingThomsonContact(m, 1.0, Separation::kForce);
  const ContactResponse fast = PoyntingThomsonContact(m, 37.0, Separation::kForce);
  CHECK(fast.contact_time == one.contact_time);
  CHECK(fast.log_restitution == one.log_restitution);
  CHECK(fast.peak_compression == Approx(37.0 * one.peak_compression).epsilon(1e-15));
  // The same model in SI units (M kg, K N/m, C N s/m): the same tau_c and e.
  const double lbf = 4.4482216152605, inch = 0.0254;
  const PoyntingThomson si{m.mass * lbf / inch, m.stiffness1 * lbf / inch,
                           m.stiffness2 * lbf / inch, m.damping * lbf / inch};
  const ContactResponse s = PoyntingThomsonContact(si, inch, Separation::kForce);
  CHECK(s.contact_time == Approx(one.contact_time).epsilon(1e-14));
  CHECK(s.log_restitution == Approx(one.log_restitution).epsilon(1e-14));
  CHECK(s.peak_compression == Approx(one.peak_compression * inch).epsilon(1e-14));
}

TEST_CASE("poynting_thomson: the contact ends where x1 or the force returns to 0, after the peak") {
  const PoyntingThomson m{kBarMass, 3e5, 5e5, 20.0};
  for (const Separation sep : {Separation::kKinematic, Separation::kForce}) {
    const ContactResponse c = PoyntingThomsonContact(m, 2.0, sep);
    const PoyntingThomsonState end = PoyntingThomsonStateAt(m, 2.0, c.contact_time);
    const PoyntingThomsonState peak = PoyntingThomsonStateAt(m, 2.0, c.peak_time);
    const double force_scale = (m.stiffness1 + m.stiffness2) * c.peak_compression;
    if (sep == Separation::kKinematic) {
      CHECK(std::abs(end.compression) < 1e-14 * c.peak_compression);
    } else {
      CHECK(std::abs(end.force) < 1e-14 * force_scale);
      CHECK(end.compression > 0.0);  // still compressed when the force lets go
    }
    CHECK(end.velocity == Approx(-2.0 * c.restitution).epsilon(1e-14));
    CHECK(std::abs(peak.velocity) < 1e-14 * 2.0);
    CHECK(peak.compression == Approx(c.peak_compression).epsilon(1e-15));
    CHECK(c.peak_time < c.contact_time);
    CHECK(c.restitution < 1.0);
  }
}

TEST_CASE("poynting_thomson: drives the rebound history like Kelvin-Voigt in its limit") {
  const Pendulum pendulum{22.0, 385.644, PendulumConvention::kExact};
  const KelvinVoigt kv{kBarMass, 4.6e5, 13.3};
  const PoyntingThomsonContactLaw pt(
      PoyntingThomson{kv.mass, kv.stiffness, 1e8 * kv.stiffness, kv.damping},
      Separation::kKinematic);
  const KelvinVoigtContactLaw kv_law(kv, Separation::kKinematic);
  const ReboundSequence a = SimulateRebounds(pendulum, pt, 0.4, 6);
  const ReboundSequence b = SimulateRebounds(pendulum, kv_law, 0.4, 6);
  for (std::size_t n = 0; n < a.xmax.size(); ++n) {
    CHECK(a.xmax[n] == Approx(b.xmax[n]).epsilon(1e-8));
    CHECK(a.peak_time[n] == Approx(b.peak_time[n]).epsilon(1e-8));
  }
  // The compression during impact 1 follows the model.
  const double t = a.impact_time[0] + 0.5 * a.contact.contact_time;
  CHECK(HistoryDisplacement(a, pendulum, pt, t) ==
        Approx(-PoyntingThomsonStateAt({kv.mass, kv.stiffness, 1e8 * kv.stiffness, kv.damping},
                                       a.impact_speed[0], 0.5 * a.contact.contact_time)
                    .compression)
            .epsilon(1e-12));
}

TEST_CASE("poynting_thomson: bad parameters are invalid_argument") {
  CHECK_THROWS_AS(
      PoyntingThomsonContact(PoyntingThomson{0.0, 1.0, 1.0, 1.0}, 1.0, Separation::kForce),
      std::invalid_argument);
  CHECK_THROWS_AS(
      PoyntingThomsonContact(PoyntingThomson{1.0, -1.0, 1.0, 1.0}, 1.0, Separation::kForce),
      std::invalid_argument);
  CHECK_THROWS_AS(
      PoyntingThomsonContact(PoyntingThomson{1.0, 1.0, 1.0, 0.0}, 1.0, Separation::kForce),
      std::invalid_argument);
  CHECK_THROWS_AS(
      PoyntingThomsonContact(PoyntingThomson{1.0, 1.0, 1.0, 1.0}, 0.0, Separation::kForce),
      std::invalid_argument);
  CHECK_THROWS_AS(
      PoyntingThomsonContact(PoyntingThomson{1.0, 1.0, NAN, 1.0}, 1.0, Separation::kForce),
      std::invalid_argument);
}

}  // namespace
}  // namespace impactlab
