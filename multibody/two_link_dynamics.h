// The manipulator's motion regimes (docs/two-link.md, "Contact"): free flight,
// the impact of the tool's tip on the surface, constrained motion along it
// with Coulomb friction, and separation.
//
// With the tip's normal row G_n and tangential row G_t of the Jacobian
// (model.Tip()), and W = G_n - mu sigma(v_t) G_t the friction-loaded normal
// row (sigma the regularised sign v_t / sqrt(v_t^2 + v_s^2), eq. 21):
//   free:         M q'' = Q - h
//   constrained:  M q'' = Q - h + W^T lambda,  G_n q'' = -a0_n
//                 (lambda the surface's normal force, eq. 20; the tip stays
//                 on the surface while lambda > 0)
//   impact:       M (q'+ - q'-) = G_n^T P_n + G_t^T P_t  (the generalized
//                 momentum equations 22-26), P from the contact's impact law
//                 (multibody/contact_impulse.h: Coulomb friction at every
//                 instant of the impulse; plastic, the paper's, by default).
#pragma once

#include "multibody/contact_impulse.h"
#include "multibody/two_link_model.h"

namespace impactlab {

TwoLinkVector FreeAcceleration(const TwoLinkModel& model, const TwoLinkVector& q,
                               const TwoLinkVector& v, const DriveVoltages& voltages);

struct ConstrainedAcceleration {
  TwoLinkVector acceleration = TwoLinkVector::Zero();
  double normal_force_n = 0.0;    // lambda: > 0 pushes the tip off the surface
  double friction_force_n = 0.0;  // along +y on the tip
};
ConstrainedAcceleration ConstrainedMotion(const TwoLinkModel& model, const TwoLinkVector& q,
                                          const TwoLinkVector& v, const DriveVoltages& voltages);

struct ImpactOutcome {
  TwoLinkVector velocity = TwoLinkVector::Zero();  // q'+
  double normal_impulse_n_s = 0.0;
  double tangential_impulse_n_s = 0.0;
  bool sticks = false;         // the tip's slip is 0 after it
  bool slip_reversed = false;  // the slip stopped during the impulse and resumed the other way
  // The work of the normal and the friction impulse (their sum is the
  // kinetic energy's change; friction's is never positive).
  double normal_work_j = 0.0, friction_work_j = 0.0;
  double normal_velocity_before_m_s = 0.0, tangential_velocity_before_m_s = 0.0;
  double normal_velocity_after_m_s = 0.0, tangential_velocity_after_m_s = 0.0;
  // |M (q'+ - q'-) - G^T P| / |M q'-|: the momentum equations' residual.
  double momentum_residual = 0.0;
};
// The impact at configuration q by the surface's impact law; one approaching
// slower than plastic_below_m_s is plastic whatever the restitution (where
// bounces accumulate, the contact becomes persistent).
ImpactOutcome Impact(const TwoLinkModel& model, const TwoLinkVector& q,
                     const TwoLinkVector& velocity_before, double plastic_below_m_s = 0.0);

ContactImpulseLaw ImpactLawOf(const TwoLinkSurface& surface);

// In constrained motion q4 is the dependent coordinate (the document's), or
// q1 where link 2 turns along the surface (|dg/dq4| small).
int DependentCoordinate(const TwoLinkModel& model, const TwoLinkVector& q);

// The loop closure: the dependent coordinate by Newton-Raphson so that the
// tip is on the surface (gap 0 to ~1e-15 m), then its speed so that the tip's
// normal velocity is 0. Returns the gap left. Throws std::domain_error when
// Newton fails.
double CloseLoop(const TwoLinkModel& model, int dependent, TwoLinkVector* q, TwoLinkVector* v);

}  // namespace impactlab
