// A trace's screen settings for the renderer's tests: its time base, volts
// a division and where 0 V lies (the rest left at their defaults).
#pragma once

#include "io/session.h"

namespace impactlab::testing {

inline TraceSettings SweepSettings(double time_per_div, double volts_per_div, double zero_div) {
  TraceSettings settings;
  settings.time_per_div = time_per_div;
  settings.volts_per_div = volts_per_div;
  settings.zero_div = zero_div;
  return settings;
}

}  // namespace impactlab::testing
