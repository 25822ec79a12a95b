#include "fit/effective_modulus.h"

#include <cmath>

namespace impactlab {

std::string EffectiveModulusUnidentifiable(const Specimen& specimen) {
  if (specimen.end_shape.empty()) return "the specimen does not give its end shape";
  if (specimen.end_shape == "plane") {
    return "plane ends: Hertz's k then depends on how the edges meet (their radius and the "
           "bars' misalignment), not on the material alone";
  }
  if (specimen.end_shape == "given_stiffness") {
    return "the contact stiffness is given, not made by a known geometry";
  }
  if (!specimen.sphere_radius) return "spherical ends without their sphere_radius";
  return {};
}

double HertzStiffnessOfSpheres(double effective_modulus, double sphere_radius) {
  return 8.0 / 3.0 * effective_modulus * std::sqrt(sphere_radius);
}

Estimate EffectiveModulusOfSpheres(const Estimate& hertz_stiffness, double sphere_radius) {
  const double per_k = 3.0 / (8.0 * std::sqrt(sphere_radius));
  return {hertz_stiffness.value * per_k, hertz_stiffness.sigma * per_k};
}

std::optional<double> HandbookEffectiveModulus(const Specimen& specimen) {
  if (!specimen.modulus || !specimen.poisson_ratio) return std::nullopt;
  const double nu = *specimen.poisson_ratio;
  return *specimen.modulus / (2.0 * (1.0 - nu * nu));
}

}  // namespace impactlab
