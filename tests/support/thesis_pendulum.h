// The thesis's pendulum in its inch-pound units: one bar of 2.23 lbf on a
// 22 in suspension, g = 385.644 in/s^2, the exact pendulum. Shared by the
// tests that simulate or reduce its runs.
#pragma once

#include "model/pendulum.h"

namespace impactlab::testing {

inline constexpr double kG = 385.644;          // in/s^2, the thesis's g
inline constexpr double kL = 22.0;             // in, the suspension's length
inline constexpr double kBarMass = 2.23 / kG;  // lbf s^2/in, one bar
inline const Pendulum kPendulum{kL, kG, PendulumConvention::kExact};

}  // namespace impactlab::testing
