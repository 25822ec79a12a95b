// The check of an impact speed that the contact laws share (internal to
// model/: only its .cpp files include it).
#pragma once

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace impactlab::model_internal {

// Throws std::invalid_argument unless the impact speed `v` is > 0 and finite.
inline void CheckImpactSpeed(double v) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    throw std::invalid_argument(fmt::format("an impact speed must be > 0, got {}", v));
  }
}

}  // namespace impactlab::model_internal
