// Hunt-Crossley's and the damper's dimensionless impact, as cheap as Hertz's
// closed forms: piecewise Chebyshev series (model/chebyshev_table.h) of
//   Hunt-Crossley   e(eps)               eps in [0, 512] (any n: e does not depend on it)
//                   s_c(eps, n)          eps in [0, 256], n in [0.5, 5] (the range a
//                                          fit of n searches)
//   Hertz + damper  s_c(beta), e(beta), n = 3/2
//                     kinematic separation: beta in [0, 1.1] (e >= 0.039; the
//                       contact never ends past beta ~ 1.215)
//                     force separation: beta in (0, 8], in z = beta^(1/3)
// each with its exact derivatives. Relative error against the quadrature
// (model/hunt_crossley_terms.h) and against an integration of the damper in
// sqrt(u) near contact and separation (tests/model/damper_reference.h),
// measured on a grid ten times denser than the nodes by
// tests/model/power_law_tables_test.cpp (which also regenerates the
// coefficients): values below 1e-10 (Hunt-Crossley's e 1e-14, its s_c
// 3e-12, the damper 3e-13 kinematic and 5e-11 under force separation),
// slopes below 2e-8. Outside its range, or for another n, each function
// returns nullopt and the caller evaluates the exact form.
#pragma once

#include <optional>

#include "model/chebyshev_table.h"
#include "model/contact.h"

namespace impactlab::power_law_tables {

// The n the damper's tables are for.
inline constexpr double kExponent = 1.5;

std::optional<ValueSlope> HuntCrossleyRestitution(double eps);
// s_c with its slopes in eps (slope_x) and in n (slope_y).
std::optional<ValueSlopes> HuntCrossleyContactTime(double exponent, double eps);

struct DamperImpact {
  ValueSlope contact_time;  // s_c and d s_c / d beta
  ValueSlope restitution;   // e and de / d beta
};
std::optional<DamperImpact> HertzDamperImpact(double exponent, double beta, Separation separation);

// The tables as stored, for the test that checks them (variables eps; beta;
// beta^(1/3) for the damper under force separation; eps and n).
enum class Table {
  kHuntCrossleyRestitution,
  kDamperKinematicContactTime,
  kDamperKinematicRestitution,
  kDamperForceContactTime,
  kDamperForceRestitution,
};
const ChebyshevTable& Stored(Table table);
const ChebyshevSurface& StoredHuntCrossleyContactTime();

}  // namespace impactlab::power_law_tables
