#include "model/contact.h"

namespace impactlab {

const char* SeparationName(Separation separation) {
  return separation == Separation::kForce ? "force" : "kinematic";
}

Separation ParseSeparation(const std::string& name) {
  if (name == "kinematic") return Separation::kKinematic;
  if (name == "force") return Separation::kForce;
  throw std::invalid_argument("separation must be \"kinematic\" or \"force\", got \"" + name +
                              "\"");
}

}  // namespace impactlab
