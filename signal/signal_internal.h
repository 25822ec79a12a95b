// What the log analysis's .cpp files share (internal to signal/).
#pragma once

#include <numbers>

namespace impactlab::signal_internal {

// Radians per cycle: angular frequency = kTwoPi * frequency in Hz.
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

}  // namespace impactlab::signal_internal
