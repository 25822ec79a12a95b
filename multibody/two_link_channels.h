// The names a two-link session's [[log]] gives its channels (docs/two-link.md):
// the encoders by the coordinate they read through the gear (q1: gearbox A's
// output, q4: gearbox B's), the accelerometers in TwoLinkSensor's order. The
// session writer names the channels so and the fit finds them so.
#pragma once

#include "multibody/two_link_model.h"

namespace impactlab {

inline constexpr const char* kTwoLinkEncoderAChannel = "q1";
inline constexpr const char* kTwoLinkEncoderBChannel = "q4";
inline constexpr const char* kTwoLinkAccelerometerChannels[kTwoLinkAccelerometers] = {"a1", "a2",
                                                                                      "a3", "a4"};

}  // namespace impactlab
