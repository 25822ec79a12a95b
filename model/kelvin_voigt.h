// Kelvin-Voigt contact: a spring K and a dashpot C in parallel (thesis eq. 8-12,
// 19, 37, 38, 44; physics.md).
//
//   M x'' + C x' + K x = 0,  x(0) = 0, x'(0) = v0 (x is the compression)
//   wn = sqrt(K/M), zeta = C / (2 sqrt(K M)), wd = wn sqrt(1 - zeta^2)
//   x(t) = (v0/wd) exp(-zeta wn t) sin(wd t)
//
// Contact time and restitution by separation convention (derivation in
// docs/physics.md), with h(zeta) = acos(zeta)/sqrt(1 - zeta^2), continued as
// acosh(zeta)/sqrt(zeta^2 - 1) for zeta > 1 and h(1) = 1:
//   kinematic (x = 0):       tau_c = pi / wd,          ln e = -pi zeta / sqrt(1 - zeta^2)
//   force (K x + C x' = 0):  tau_c = 2 h(zeta) / wn,   ln e = -2 zeta h(zeta)
// and in both the peak compression (v0/wn) exp(-zeta h(zeta)) at t = h(zeta)/wn.
// Kinematic separation needs zeta < 1; the force convention is continuous
// through critical damping.
#pragma once

#include "model/contact.h"

namespace impactlab {

struct KelvinVoigt {
  double mass = 0.0;       // M, mass units
  double stiffness = 0.0;  // K, force/length
  double damping = 0.0;    // C, force*time/length
};

// The same model by its rates: the form the stable formulas use.
struct KelvinVoigtRates {
  double natural_frequency = 0.0;  // wn = sqrt(K/M), rad/s
  double damping_ratio = 0.0;      // zeta = C / (2 sqrt(K M))
};

KelvinVoigtRates RatesOf(const KelvinVoigt& model);
// K = M wn^2, C = 2 zeta M wn.
KelvinVoigt KelvinVoigtFromRates(double mass, const KelvinVoigtRates& rates);

// One impact. Throws NoSeparationError for zeta >= 1 with kinematic separation,
// std::invalid_argument for non-positive M or K, negative C or non-positive speed.
ContactResponse KelvinVoigtContact(const KelvinVoigtRates& rates, double impact_speed,
                                   Separation separation);
ContactResponse KelvinVoigtContact(const KelvinVoigt& model, double impact_speed,
                                   Separation separation);

// x(t) during contact, stable at and across zeta = 1.
double KelvinVoigtCompression(const KelvinVoigtRates& rates, double impact_speed, double t);

// The restitution equivalence (eq. 44): the damping ratio whose impact keeps
// the fraction e = exp(log_restitution) of the speed. Kinematic:
// zeta = -ln e / sqrt(ln^2 e + pi^2) (eq. 36 with N = 1); force: the root of
// ln e = -2 zeta h(zeta) (monotone, bracketed). Throws std::domain_error
// unless log_restitution < 0.
double DampingRatioFromLogRestitution(double log_restitution, Separation separation);

// ln e of the restitution a damping ratio gives (independent of K and M).
double LogRestitutionFromDampingRatio(double damping_ratio, Separation separation);

// Stiffness from a measured contact time and the damping ratio (eq. 37 for
// kinematic separation: K = M pi^2 / (tau_c^2 (1 - zeta^2)); for force
// separation K = M (2 h(zeta) / tau_c)^2).
double StiffnessFromContactTime(double mass, double contact_time, double damping_ratio,
                                Separation separation);

// The ContactLaw for the rebound history.
class KelvinVoigtContactLaw final : public ContactLaw {
 public:
  KelvinVoigtContactLaw(const KelvinVoigt& model, Separation separation);
  ContactResponse Respond(double impact_speed) const override;
  double Compression(double impact_speed, double t) const override;

 private:
  KelvinVoigtRates rates_;
  Separation separation_;
};

}  // namespace impactlab
