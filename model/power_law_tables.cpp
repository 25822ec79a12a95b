#include "model/power_law_tables.h"

#include <cmath>

namespace impactlab::power_law_tables {
namespace {

// kXBreaks, kXTerms, kXCoefficients for each table X; for the surface,
// kXEpsBreaks, kXExponentBreaks, kXEpsTerms, kXExponentTerms, kXCoefficients.
#include "model/power_law_tables.inc"

constexpr ChebyshevTable kTables[] = {
    {kHuntCrossleyRestitutionBreaks, kHuntCrossleyRestitutionTerms,
     kHuntCrossleyRestitutionCoefficients},
    {kDamperKinematicContactTimeBreaks, kDamperKinematicContactTimeTerms,
     kDamperKinematicContactTimeCoefficients},
    {kDamperKinematicRestitutionBreaks, kDamperKinematicRestitutionTerms,
     kDamperKinematicRestitutionCoefficients},
    {kDamperForceContactTimeBreaks, kDamperForceContactTimeTerms,
     kDamperForceContactTimeCoefficients},
    {kDamperForceRestitutionBreaks, kDamperForceRestitutionTerms,
     kDamperForceRestitutionCoefficients},
};

constexpr ChebyshevSurface kHuntCrossleyContactTime{
    kHuntCrossleyContactTimeEpsBreaks, kHuntCrossleyContactTimeExponentBreaks,
    kHuntCrossleyContactTimeEpsTerms, kHuntCrossleyContactTimeExponentTerms,
    kHuntCrossleyContactTimeCoefficients};

}  // namespace

const ChebyshevTable& Stored(Table table) { return kTables[static_cast<int>(table)]; }
const ChebyshevSurface& StoredHuntCrossleyContactTime() { return kHuntCrossleyContactTime; }

std::optional<ValueSlope> HuntCrossleyRestitution(double eps) {
  return Evaluate(Stored(Table::kHuntCrossleyRestitution), eps);
}

std::optional<ValueSlopes> HuntCrossleyContactTime(double exponent, double eps) {
  return Evaluate(kHuntCrossleyContactTime, eps, exponent);
}

std::optional<DamperImpact> HertzDamperImpact(double exponent, double beta, Separation separation) {
  if (exponent != kExponent) return std::nullopt;
  if (separation == Separation::kKinematic) {
    const auto s_c = Evaluate(Stored(Table::kDamperKinematicContactTime), beta);
    const auto e = Evaluate(Stored(Table::kDamperKinematicRestitution), beta);
    if (!s_c || !e) return std::nullopt;
    return DamperImpact{*s_c, *e};
  }
  // Under force separation the bodies part at u ~ beta^(1/n) = beta^(2/3):
  // s_c and e are series in z = beta^(1/3), not beta (whose slope is infinite
  // at 0). dz/dbeta = 1/(3 z^2); beta = 0 itself is left to the exact form.
  if (!(beta > 1e-200)) return std::nullopt;
  const double z = std::cbrt(beta);
  auto s_c = Evaluate(Stored(Table::kDamperForceContactTime), z);
  auto e = Evaluate(Stored(Table::kDamperForceRestitution), z);
  if (!s_c || !e) return std::nullopt;
  const double dz = 1.0 / (3.0 * z * z);
  s_c->slope *= dz;
  e->slope *= dz;
  return DamperImpact{*s_c, *e};
}

}  // namespace impactlab::power_law_tables
