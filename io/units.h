// Unit systems of a session: every number in a manifest and a results file is in
// the session's system; `units` attributes in the results file say which.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace impactlab {

enum class UnitSystem {
  kInLbfS,  // inch, pound-force, second; mass in lbf*s^2/in (the thesis's system)
  kSI,      // metre, kilogram, newton, second
};

// Unit strings of one system, as written to `units` attributes.
struct UnitLabels {
  std::string length;        // "in" or "m"
  std::string force;         // "lbf" or "N"
  std::string mass;          // "lbf*s^2/in" or "kg"
  std::string stiffness;     // "lbf/in" or "N/m"
  std::string damping;       // "lbf*s/in" or "N*s/m"
  std::string acceleration;  // "in/s^2" or "m/s^2"
  std::string speed;         // "in/s" or "m/s"
  // A log channel's values' units ("rad", "m/s^2"): set where a channel's
  // results are written, empty elsewhere.
  std::string channel;
  std::string pressure;         // "lbf/in^2" or "Pa": a material's modulus
  std::string hertz_stiffness;  // "lbf/in^1.5" or "N/m^1.5": k of F = k x^(3/2)
};

// The manifest's name of the system: "in-lbf-s" or "SI".
std::string_view UnitSystemName(UnitSystem system);
std::optional<UnitSystem> ParseUnitSystem(std::string_view name);
UnitLabels LabelsFor(UnitSystem system);
// Standard gravity in the system's units: 385.644 in/s^2 (the value CALIBR and
// PENDUL use) or 9.80665 m/s^2.
double StandardGravity(UnitSystem system);

// A fitted parameter's unit kind (NamedEstimate::units: "length",
// "stiffness", "damping", "speed", "inverse_speed", "hertz_stiffness", or a
// unit itself, "1", "s") in the system's labels.
std::string UnitOfKind(const std::string& kind, const UnitLabels& labels);

}  // namespace impactlab
