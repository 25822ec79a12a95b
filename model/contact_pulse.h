// The contact circuit's step pulse, however it was read (a scope's samples,
// a photo's strokes): high while the bars touch.
#pragma once

#include "model/estimate.h"

namespace impactlab {

// Each edge is where the trace crosses half way between its low and high
// levels.
struct ContactPulse {
  Estimate rise_s;   // rising edge, s on the trace's time axis
  Estimate fall_s;   // falling edge, s
  Estimate width_s;  // fall - rise, s: the contact time
  double low_volts = 0.0, high_volts = 0.0;
};

}  // namespace impactlab
