// Hunt-Crossley's and the damper's dimensionless impact for the fits'
// default exponent n = 3/2, as cheap as Hertz's closed forms: piecewise
// Chebyshev series (model/chebyshev_table.h) of
//   Hunt-Crossley   e(eps)               eps in [0, 512] (any n: e does not depend on it)
//                   s_c(eps), n = 3/2    eps in [0, 256]
//   Hertz + damper  s_c(beta), e(beta), n = 3/2
//                     kinematic separation: beta in [0, 1.1] (e >= 0.039; the
//                       contact never ends past beta ~ 1.215)
//                     force separation: beta in (0, 8], in z = beta^(1/3)
// each with its exact derivative. Relative error against the quadrature
// (model/hunt_crossley_terms.h) and against an integration of the damper in
// sqrt(u) near contact and separation (tests/model/damper_reference.h),
// measured on a grid ten times denser than the nodes by
// tests/model/power_law_tables_test.cpp (which also regenerates the
// coefficients): values below 1e-10 (Hunt-Crossley 1e-14, the damper 3e-13
// kinematic and 5e-11 under force separation), slopes below 2e-8. Outside
// its range, or for another n, each function returns nullopt and the caller
// evaluates the exact form.
#pragma once

#include <optional>

#include "model/chebyshev_table.h"
#include "model/contact.h"

namespace impactlab::power_law_tables {

// The n every n-dependent table is for.
inline constexpr double kExponent = 1.5;

std::optional<ValueSlope> HuntCrossleyRestitution(double eps);
std::optional<ValueSlope> HuntCrossleyContactTime(double exponent, double eps);

struct DamperImpact {
  ValueSlope contact_time;  // s_c and d s_c / d beta
  ValueSlope restitution;   // e and de / d beta
};
std::optional<DamperImpact> HertzDamperImpact(double exponent, double beta, Separation separation);

// The tables as stored, for the test that checks them (variables eps; beta;
// beta^(1/3) for the damper under force separation).
enum class Table {
  kHuntCrossleyRestitution,
  kHuntCrossleyContactTime,
  kDamperKinematicContactTime,
  kDamperKinematicRestitution,
  kDamperForceContactTime,
  kDamperForceRestitution,
};
const ChebyshevTable& Stored(Table table);

}  // namespace impactlab::power_law_tables
