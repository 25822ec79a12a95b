// Poynting-Thomson (standard linear solid) contact: a spring K1 from the mass
// to ground, in parallel with a spring K2 in series with a dashpot C (thesis
// eq. 13-18, 45-71; physics.md). x1 is the compression, x2 the node between K2
// and C:
//
//   M x1'' + (K1 + K2) x1 - K2 x2 = 0
//   C x2'  - K2 x1 + K2 x2 = 0,      x1(0) = x2(0) = 0, x1'(0) = v0
//
// with characteristic cubic s^3 + (K2/C) s^2 + ((K1 + K2)/M) s + K1 K2/(C M).
// The contact force is F = K1 x1 + K2 (x1 - x2) = -M x1''.
//
// Evaluation (docs/fitting.md, "Poynting-Thomson contact"): scaled variables
//   wn = sqrt((K1 + K2)/M), tau = wn t, u = wn x1/v0, v = x1'/v0, d = wn (x1 - x2)/v0,
//   kappa1 = K1/(K1 + K2), kappa2 = K2/(K1 + K2), beta = K2/(C wn),
// so that z = [u, v, d] obeys z' = B z with
//   B = [[0, 1, 0], [-kappa1, 0, -kappa2], [0, 1, -beta]],  z(0) = [0, 1, 0],
// and the scaled force is kappa1 u + kappa2 d (= -v'). z(tau) = exp(B tau) z(0)
// is evaluated by the exact Cayley-Hamilton form of the matrix exponential,
//   exp(B tau) = c0(tau) I + c1(tau) B + g(tau) Q(B),
// with r the real root of the cubic farthest from the others, Q(s) the
// quadratic of the other two, c0 + c1 s the interpolant of e^{s tau} at those
// two (cos and sin(omega tau)/omega continued as entire functions of omega^2)
// and g the second divided difference of e^{s tau} at all three (a series near
// the triple root). There is no case split by the roots: the same formulas run
// with a complex pair, a double, a triple or three distinct real roots, and
// results are continuous across those boundaries. The decay of the slowest
// mode is factored out so that nothing underflows however long contact lasts.
// The thesis's four closed forms (Appendix A) serve only as cross-checks in
// the tests. Eigen's Pade exponential of the scaled B agrees to ~1e-15 over a
// few natural periods, but squaring a near-defective matrix loses accuracy like
// eps (|s| tau)^2 over the very long contacts near the boundaries (O(1) errors
// at 1e-12 from them); this form stays within cond * eps (docs/fitting.md).
//
// Contact end, by a bracketed root search (TOMS 748) whose bracket is proven
// to hold the FIRST root (docs/fitting.md gives the Sturm-comparison argument):
//  - force: F first returns to 0. Always happens, continuous in every regime.
//  - kinematic: x1 first returns to 0. Never happens with three real roots
//    (x1 is then a sum of three exponentials with at most one more zero, and it
//    ends positive; likewise at a double or triple root), nor with a complex
//    pair whose decay is faster than the real root's when x1 does not cross
//    within the first slow period; both throw NoSeparationError. Approaching
//    the three-real-roots region from the side where the complex pair is the
//    slow mode, tau_c ~ pi/omega diverges and e underflows: log_restitution
//    stays finite.
//
// Which of these regimes applies is decided exactly, from the sign of the
// cubic's discriminant evaluated in integer arithmetic from the input doubles
// (C M s^3 + K2 M s^2 + (K1 + K2) C s + K1 K2), not from computed roots: near
// a double root those are off by ~sqrt(eps), near the triple root by
// ~eps^(1/3), far more than the distance to the boundary (doubles 1e-12 from
// the triple root can be 1e-39 from the boundary, relative to the
// discriminant's terms). Within 1e-12 of it (so relative) the roots are also
// recomputed in 256 bits from the inputs, and the responses are then accurate
// to ~eps; farther out the double-precision roots stand, within cond * eps.
#pragma once

#include <array>
#include <complex>
#include <optional>
#include <string>

#include "model/contact.h"

namespace impactlab {

struct PoyntingThomson {
  double mass = 0.0;        // M, mass units
  double stiffness1 = 0.0;  // K1, the spring from the mass to ground, force/length
  double stiffness2 = 0.0;  // K2, the spring in series with the dashpot, force/length
  double damping = 0.0;     // C, the dashpot, force*time/length
};

// The same model in the dimensionless form the evaluation uses. kappa1 and
// kappa2 are both kept (each to full relative precision) because 1 - kappa1
// loses digits when K2 << K1.
struct PoyntingThomsonRates {
  double natural_frequency = 0.0;  // wn = sqrt((K1 + K2)/M), rad/s
  double kappa1 = 0.0;             // K1/(K1 + K2)
  double kappa2 = 0.0;             // K2/(K1 + K2)
  double beta = 0.0;               // K2/(C wn): the K2-C arm's relaxation rate in units of wn
};

// Throws std::invalid_argument unless M, K1, K2 and C are positive and finite.
PoyntingThomsonRates RatesOf(const PoyntingThomson& model);

// Roots of the characteristic cubic (rad/s), for diagnostics and reports:
// roots[0] is the real root used above, roots[1], roots[2] the other two.
// complex_pair is exact (as above). Within ~1e-12 of a double or triple root,
// relative to the discriminant's terms, the roots come from 256-bit arithmetic
// and are accurate to rounding; farther out, from double precision, their
// errors stay below ~1e-4 of the distance between the nearest two.
struct PoyntingThomsonRoots {
  std::array<std::complex<double>, 3> roots;  // s, rad/s (real parts negative)
  bool complex_pair = false;                  // one real root and a complex pair
};
PoyntingThomsonRoots CharacteristicRoots(const PoyntingThomson& model);

// One impact at `impact_speed` > 0. Throws NoSeparationError where kinematic
// separation never happens (see above; the message says why and suggests force
// separation), std::invalid_argument for bad parameters or speed.
//
// The rates overload takes the rates as exact: its regime is that of B's own
// cubic s^3 + beta s^2 + (kappa1 + kappa2) s + beta kappa1 with these doubles.
// RatesOf rounds each rate, so within ~eps of a boundary a model and its rates
// can fall on different sides (and give NoSeparationError and a finite, huge
// tau_c): for a model use the model overload, as the contact law, the CLI
// and the fits do.
ContactResponse PoyntingThomsonContact(const PoyntingThomson& model, double impact_speed,
                                       Separation separation);
ContactResponse PoyntingThomsonContact(const PoyntingThomsonRates& rates, double impact_speed,
                                       Separation separation);

// The state at time t >= 0 since contact began.
struct PoyntingThomsonState {
  double compression = 0.0;  // x1, length
  double velocity = 0.0;     // x1', length/time
  double node = 0.0;         // x2, length
  double force = 0.0;        // K1 x1 + K2 (x1 - x2), force
};
PoyntingThomsonState PoyntingThomsonStateAt(const PoyntingThomson& model, double impact_speed,
                                            double t);

// x1(t) during contact (0 <= t).
double PoyntingThomsonCompression(const PoyntingThomsonRates& rates, double impact_speed, double t);

// The ContactLaw for the rebound history. A linear law: the response at unit
// speed is computed once, here, from the model (its regime), and scaled (tau_c
// and e do not depend on the speed; peak compression is proportional to it). A
// law that never separates under the chosen convention can be built; Respond
// then throws NoSeparationError with the diagnostic.
class PoyntingThomsonContactLaw final : public ContactLaw {
 public:
  PoyntingThomsonContactLaw(const PoyntingThomson& model, Separation separation);
  ContactResponse Respond(double impact_speed) const override;
  double Compression(double impact_speed, double t) const override;

 private:
  PoyntingThomsonRates rates_;
  Separation separation_;
  std::optional<ContactResponse> unit_response_;  // at impact speed 1
  std::string no_separation_;                     // why, when unit_response_ is empty
};

}  // namespace impactlab
