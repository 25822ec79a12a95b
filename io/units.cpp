#include "io/units.h"

namespace impactlab {

std::string_view UnitSystemName(UnitSystem system) {
  return system == UnitSystem::kSI ? "SI" : "in-lbf-s";
}

std::optional<UnitSystem> ParseUnitSystem(std::string_view name) {
  if (name == "in-lbf-s") return UnitSystem::kInLbfS;
  if (name == "SI") return UnitSystem::kSI;
  return std::nullopt;
}

UnitLabels LabelsFor(UnitSystem system) {
  if (system == UnitSystem::kSI) {
    return {"m", "N", "kg", "N/m", "N*s/m", "m/s^2", "m/s", "", "Pa", "N/m^1.5"};
  }
  return {"in",     "lbf",  "lbf*s^2/in", "lbf/in", "lbf*s/in",
          "in/s^2", "in/s", "",           "psi",    "lbf/in^1.5"};
}

double StandardGravity(UnitSystem system) { return system == UnitSystem::kSI ? 9.80665 : 385.644; }

std::string UnitOfKind(const std::string& kind, const UnitLabels& u) {
  if (kind == "length") return u.length;
  if (kind == "stiffness") return u.stiffness;
  if (kind == "damping") return u.damping;
  if (kind == "speed") return u.speed;
  if (kind == "inverse_speed") return "s/" + u.length;
  if (kind == "hertz_stiffness") return u.force + "/" + u.length + "^n";
  return kind;  // "1", "s"
}

}  // namespace impactlab
