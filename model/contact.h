// What every contact model tells the rest of the pipeline: how long an impact
// lasts, how much speed survives it, and the compression history during it.
#pragma once

#include <stdexcept>
#include <string>

namespace impactlab {

// When contact ends (physics.md):
//  - kinematic: the compression x returns to 0 (the thesis's convention; the
//    model force is tensile at that instant);
//  - force: the contact force first returns to 0 (it never pulls).
enum class Separation { kKinematic, kForce };

const char* SeparationName(Separation separation);    // "kinematic" or "force"
Separation ParseSeparation(const std::string& name);  // throws std::invalid_argument

// One impact at `impact_speed`, x(0) = 0, x'(0) = impact_speed.
struct ContactResponse {
  double contact_time = 0.0;      // tau_c, s
  double restitution = 0.0;       // e = exit speed / impact speed
  double log_restitution = 0.0;   // ln e (stays finite where e underflows)
  double peak_compression = 0.0;  // max of x, length units
  double peak_time = 0.0;         // time of the peak since contact began, s
  Separation separation = Separation::kKinematic;
};

// A contact law the parameters of which are outside the domain where contact
// ends under the chosen convention (e.g. Kelvin-Voigt with zeta >= 1 and
// kinematic separation: x never returns to 0).
class NoSeparationError : public std::domain_error {
 public:
  using std::domain_error::domain_error;
};

// Interface the rebound history uses, so that any linear contact model
// (Kelvin-Voigt, Poynting-Thomson) drives the same pendulum sequence.
class ContactLaw {
 public:
  virtual ~ContactLaw() = default;
  // Throws NoSeparationError where contact never ends.
  virtual ContactResponse Respond(double impact_speed) const = 0;
  // Compression x(t) at time t since contact began, 0 <= t <= contact time.
  virtual double Compression(double impact_speed, double t) const = 0;
};

}  // namespace impactlab
