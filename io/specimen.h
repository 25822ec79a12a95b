// What a session's bars are: their material and the shape of their ends
// (the manifest's optional [specimen] table, which a run may override).
//
// A campaign groups sessions by material and end geometry, and the contact
// laws' constants follow from them where the geometry is known: Hertz's
// k = (4/3) E* sqrt(R) for spherical ends, with E* the effective modulus
// of the two bars (docs/physics.md). Every number is in the session's units
// (lengths in `in` or `m`, the modulus in `psi` or `Pa`); a number not given
// is empty.
#pragma once

#include <optional>
#include <string>

#include "options/result_fields.h"

namespace impactlab {

struct Specimen {
  std::string material;                 // a name, e.g. "AISI 1020 steel"; empty: not given
  std::string end_shape;                // "plane", "sphere" or "given_stiffness"; empty: not given
  std::optional<double> edge_radius;    // plane ends: the radius of their edge
  std::optional<double> sphere_radius;  // spherical ends: the sphere's radius
  std::optional<double> contact_stiffness;  // given_stiffness: Hertz's k
  std::optional<double> bar_length;
  std::optional<double> bar_diameter;
  std::optional<double> modulus;        // the material's handbook Young's modulus
  std::optional<double> poisson_ratio;  // and Poisson's ratio

  bool empty() const {
    return material.empty() && end_shape.empty() && !edge_radius && !sphere_radius &&
           !contact_stiffness && !bar_length && !bar_diameter && !modulus && !poisson_ratio;
  }

  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("material", IfAny(self.material), Quantity::kDimensionless, "the bars' material");
    visit("end_shape", IfAny(self.end_shape), Quantity::kDimensionless,
          "the bars' ends: plane, sphere or given_stiffness");
    visit("edge_radius", self.edge_radius, Quantity::kLength, "plane ends' edge radius");
    visit("sphere_radius", self.sphere_radius, Quantity::kLength, "spherical ends' radius");
    visit("contact_stiffness", self.contact_stiffness, Quantity::kHertzStiffness,
          "Hertz's k where it is given rather than computed from the geometry");
    visit("bar_length", self.bar_length, Quantity::kLength, "the bars' length");
    visit("bar_diameter", self.bar_diameter, Quantity::kLength, "the bars' diameter");
    visit("modulus", self.modulus, Quantity::kPressure, "the material's Young's modulus");
    visit("poisson_ratio", self.poisson_ratio, Quantity::kDimensionless,
          "the material's Poisson ratio");
  }
};

}  // namespace impactlab
