#include <cmath>
#include <stdexcept>

#include "campaign/campaign_internal.h"

namespace impactlab {
namespace {

constexpr double kMetresPerInch = 0.0254;
constexpr double kNewtonsPerPoundForce = 4.4482216152605;

// A unit of the kind in SI units.
double InSi(const std::string& kind, UnitSystem system) {
  const double l = system == UnitSystem::kSI ? 1.0 : kMetresPerInch;
  const double f = system == UnitSystem::kSI ? 1.0 : kNewtonsPerPoundForce;
  if (kind == "1" || kind == "s" || kind.empty()) return 1.0;
  if (kind == "length" || kind == "speed") return l;
  if (kind == "inverse_speed") return 1.0 / l;
  if (kind == "stiffness" || kind == "damping" || kind == "mass") return f / l;
  if (kind == "hertz_stiffness") return f / std::pow(l, 1.5);
  if (kind == "pressure") return f / (l * l);
  throw std::invalid_argument("no unit kind \"" + kind + "\"");
}

}  // namespace

double UnitFactor(const std::string& kind, UnitSystem from, UnitSystem to) {
  return from == to ? 1.0 : InSi(kind, from) / InSi(kind, to);
}

}  // namespace impactlab
