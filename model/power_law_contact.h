// Power-law contacts (docs/contact-laws.md): the elastic Hertz law
// and the two ways of making it dissipate that multibody simulators use.
//
//   Hertz                F = k x^n                       (n = 3/2 for spheres)
//   Hunt-Crossley        F = k x^n (1 + chi x')          (separation at F = 0)
//   Hertz with a damper  F = k x^n + c x'
//
// All three scale by the Hertz peak compression and its time,
//   x* = ((n + 1) M v0^2 / (2 k))^(1/(n+1)),   t* = x*/v0,
// so an impact's e depends on v0 only through eps = chi v0 (Hunt-Crossley)
// or beta = c x*/(M v0) (damper), and contact time and peak compression are
// t* and x* times dimensionless numbers of n and eps (or beta).
//
// Closed forms: Hertz contact time t* 2 B(1/(n+1), 1/2)/(n+1) (B the Beta
// function), peak compression x*; Hunt-Crossley restitution from the exact
// energy relation -eps e - ln(1 - eps e) = eps - ln(1 + eps) and peak
// compression x* (2 psi(eps)/eps^2)^(1/(n+1)), psi(y) = y - ln(1 + y); its
// contact time by quadrature (model/hunt_crossley_terms.h). The damper has
// none: model/contact_integration.h integrates it.
//
// Hunt-Crossley's force is never tensile (1 + chi x' > 0 up to the exit,
// since eps e < 1), so it separates where x returns to 0 under either
// convention. With kinematic separation the damper pulls at the end (its
// force c x' < 0 at x = 0); with force separation the bodies part at
// k x^n + c x' = 0 with some compression left, as Kelvin-Voigt's do.
#pragma once

#include <string>
#include <vector>

#include "model/contact.h"

namespace impactlab {

struct Hertz {
  double mass = 0.0;       // M
  double stiffness = 0.0;  // k, force/length^n
  double exponent = 1.5;   // n
};

struct HuntCrossley {
  double mass = 0.0;            // M
  double stiffness = 0.0;       // k, force/length^n
  double exponent = 1.5;        // n
  double damping_factor = 0.0;  // chi, time/length (0: Hertz)
};

struct HertzDamper {
  double mass = 0.0;       // M
  double stiffness = 0.0;  // k, force/length^n
  double exponent = 1.5;   // n
  double damping = 0.0;    // c, force*time/length
};

// x* = ((n + 1) M v0^2 / (2 k))^(1/(n+1)): the Hertz peak compression.
double HertzPeakCompression(double mass, double stiffness, double exponent, double impact_speed);

// One impact each. Throw std::invalid_argument for non-finite or out-of-range
// parameters (M, k, v0 > 0; 0 < n <= 10; chi, c >= 0).
ContactResponse HertzContact(const Hertz& model, double impact_speed);
ContactResponse HuntCrossleyContact(const HuntCrossley& model, double impact_speed);
// Throws NoSeparationError, with the integration's reason, if the contact has
// not ended by 1e4 t* (an overdamped contact under kinematic separation
// creeps back for ever): a ContactLaw's response must have an end.
ContactResponse HertzDamperContact(const HertzDamper& model, double impact_speed,
                                   Separation separation);

// The damper's impact in the Hertz scaling (u = x/x*, s = t v0/x*) as a
// function of beta = c x*/(M v0) alone, with the derivatives in beta that the
// fits need. Where model/power_law_tables.h covers n and beta (n = 3/2,
// beta up to 1.1 kinematic, 8 force) from its Chebyshev series, to 1e-12
// relative whatever `tolerance` asks; elsewhere integrated with the
// variational equations (model/contact_integration.h) at `tolerance`. Where
// the contact does not end (no separation at that beta, or an integration
// that cannot finish) the result is !ok with the integration's reason, a
// point outside the law's domain for the fits.
struct HertzDamperScaled {
  double contact_time = 0.0;    // s_c
  double restitution = 0.0;     // e
  double d_contact_time = 0.0;  // d s_c / d beta
  double d_restitution = 0.0;   // d e / d beta
  bool ok = true;               // false: the contact does not end (the figures are 0)
  std::string reason;
};
HertzDamperScaled HertzDamperScaledImpact(double exponent, double beta, Separation separation,
                                          double tolerance = 1e-13);
// Always integrated: the tables' independent check.
HertzDamperScaled IntegrateHertzDamperScaledImpact(double exponent, double beta,
                                                   Separation separation, double tolerance = 1e-13);

// Hunt-Crossley restitution at eps = chi v0 >= 0 (1 at eps = 0), exact to a
// few ulp over eps in [0, 1e300).
double HuntCrossleyRestitution(double eps);

// Ways to set chi for a target restitution e at impact speed v0: each gives
// eps = chi v0 as a function of e. `exact` inverts the energy relation; the
// others are the published approximations, which miss e badly below ~0.7
// (fitting-notes): Hunt-Crossley 3(1 - e)/2, Lankarani-Nikravesh
// 3(1 - e^2)/4, Flores 8(1 - e)/(5 e).
enum class DampingFactorConvention { kExact, kHuntCrossley, kLankaraniNikravesh, kFlores };
const char* DampingFactorConventionName(DampingFactorConvention convention);
// "exact", "hunt-crossley", "lankarani-nikravesh", "flores"; throws std::invalid_argument.
DampingFactorConvention ParseDampingFactorConvention(const std::string& name);
// chi for target e in (0, 1] at impact speed v0 > 0. Throws std::invalid_argument.
double DampingFactorFor(double restitution, double impact_speed,
                        DampingFactorConvention convention);

// The state during contact, t since contact began (0 <= t <= contact time).
struct ContactState {
  double compression = 0.0;  // x
  double velocity = 0.0;     // x'
  double force = 0.0;        // F
};
ContactState HuntCrossleyStateAt(const HuntCrossley& model, double impact_speed, double t);
ContactState HertzDamperStateAt(const HertzDamper& model, double impact_speed, double t);

// The force history of one impact: `samples` >= 2 equally spaced times from
// contact to separation.
struct ContactHistory {
  std::vector<double> time;
  std::vector<double> compression;
  std::vector<double> velocity;
  std::vector<double> force;
};
ContactHistory HuntCrossleyHistory(const HuntCrossley& model, double impact_speed, int samples);
ContactHistory HertzDamperHistory(const HertzDamper& model, double impact_speed,
                                  Separation separation, int samples);

// ContactLaws for the rebound history and the generator: e and tau_c now
// depend on the impact speed.
class HuntCrossleyContactLaw final : public ContactLaw {
 public:
  explicit HuntCrossleyContactLaw(const HuntCrossley& model);
  ContactResponse Respond(double impact_speed) const override;
  double Compression(double impact_speed, double t) const override;

 private:
  HuntCrossley model_;
};

class HertzDamperContactLaw final : public ContactLaw {
 public:
  HertzDamperContactLaw(const HertzDamper& model, Separation separation);
  ContactResponse Respond(double impact_speed) const override;
  double Compression(double impact_speed, double t) const override;

 private:
  HertzDamper model_;
  Separation separation_;
};

}  // namespace impactlab
