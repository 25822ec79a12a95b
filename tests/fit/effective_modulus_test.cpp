// E* from Hertz's k for two identical bars with spherical ends: the contact
// laws' k (F = k x^(3/2), x one bar's compression against the plane of
// symmetry) against the textbook collision of two spheres, written in the
// approach delta = 2 x, the reduced mass M/2, the relative speed 2 v0 and
// R_eff = R/2 (Johnson, Contact Mechanics, sec. 11.4).
#include <catch2/catch.hpp>

#include <cmath>

#include "fit/effective_modulus.h"
#include "model/power_law_contact.h"

namespace impactlab {
namespace {

TEST_CASE("effective modulus: k = (8/3) E* sqrt(R) gives the two spheres' textbook impact") {
  const double e_star = 1.6e7;  // psi
  const double radius = 2.0;    // in
  const double mass = 0.00578;  // lbf s^2/in, one bar
  const double v0 = 5.0;        // in/s, each bar's
  const double k = HertzStiffnessOfSpheres(e_star, radius);
  const ContactResponse ours = HertzContact(Hertz{mass, k, 1.5}, v0);

  // Textbook: delta_max = (15 m v^2 / (16 E* sqrt(R_eff)))^(2/5), with m the
  // reduced mass, v the relative speed; tau = 2 B(2/5, 1/2)/(5/2) delta_max / v.
  const double m = mass / 2.0, v = 2.0 * v0, r_eff = radius / 2.0;
  const double delta_max = std::pow(15.0 * m * v * v / (16.0 * e_star * std::sqrt(r_eff)), 0.4);
  CHECK(ours.peak_compression * 2.0 == Approx(delta_max).epsilon(1e-12));
  CHECK(ours.contact_time == Approx(2.0 * std::beta(0.4, 0.5) / 2.5 * delta_max / v).epsilon(1e-9));
}

TEST_CASE("effective modulus: E* and its error from k, and the handbook's E / (2 (1 - nu^2))") {
  const Estimate e_star = EffectiveModulusOfSpheres({8.0e6, 4.0e5}, 4.0);
  CHECK(e_star.value == Approx(3.0 * 8.0e6 / 16.0));
  CHECK(e_star.sigma == Approx(3.0 * 4.0e5 / 16.0));
  CHECK(HertzStiffnessOfSpheres(e_star.value, 4.0) == Approx(8.0e6));

  Specimen steel;
  steel.modulus = 30e6;
  CHECK_FALSE(HandbookEffectiveModulus(steel));
  steel.poisson_ratio = 0.3;
  CHECK(*HandbookEffectiveModulus(steel) == Approx(30e6 / (2.0 * 0.91)));
}

TEST_CASE("effective modulus: identifiable for spherical ends of a given radius only") {
  Specimen s;
  CHECK_FALSE(EffectiveModulusUnidentifiable(s).empty());
  s.end_shape = "plane";
  s.edge_radius = 0.01;
  CHECK_FALSE(EffectiveModulusUnidentifiable(s).empty());
  s.end_shape = "given_stiffness";
  CHECK_FALSE(EffectiveModulusUnidentifiable(s).empty());
  s.end_shape = "sphere";
  CHECK_FALSE(EffectiveModulusUnidentifiable(s).empty());
  s.sphere_radius = 2.0;
  CHECK(EffectiveModulusUnidentifiable(s).empty());
}

}  // namespace
}  // namespace impactlab
