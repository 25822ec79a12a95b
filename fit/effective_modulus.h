// The material constant a contact law's k holds where the bars' geometry
// makes it identifiable (docs/physics.md, "Material constants from the
// contact").
//
// Two identical bars with spherical ends of radius R meet with the total
// approach delta = 2 x (x: the compression of one bar against the plane of
// symmetry, the contact laws' x). Hertz: F = (4/3) E* sqrt(R_eff) delta^(3/2)
// with R_eff = R R / (R + R) = R/2 and 1/E* = 2 (1 - nu^2)/E, so in x
//   k = (4/3) E* sqrt(R/2) 2^(3/2) = (8/3) E* sqrt(R),
// where R is the radius of one bar's spherical end. Plane ends (an edge
// radius) and a given stiffness leave E* unidentifiable: why is in the
// sentence EffectiveModulusUnidentifiable gives.
#pragma once

#include <optional>
#include <string>

#include "io/specimen.h"
#include "model/estimate.h"

namespace impactlab {

// Why E* cannot be had from the Hertz k of bars like `specimen`; empty when
// it can (spherical ends of a given radius).
std::string EffectiveModulusUnidentifiable(const Specimen& specimen);

// Hertz's k (F = k x^(3/2), x one bar's compression) of two identical bars of
// effective modulus E* with spherical ends of radius R: (8/3) E* sqrt(R).
double HertzStiffnessOfSpheres(double effective_modulus, double sphere_radius);

// E* = 3 k / (8 sqrt(R)) from a fitted k, its standard error scaled alike
// (R is taken as exact: the manifest gives it without an uncertainty).
Estimate EffectiveModulusOfSpheres(const Estimate& hertz_stiffness, double sphere_radius);

// E* of two identical bars from the handbook's E and nu: E / (2 (1 - nu^2));
// none unless both are given.
std::optional<double> HandbookEffectiveModulus(const Specimen& specimen);

}  // namespace impactlab
