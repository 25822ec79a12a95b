// The photocell curve the calibration tests share.
#pragma once

namespace impactlab::testing {

// A linear cell through an inverted amplifier: the volts rise with the
// displacement `x`, 0.3 V at rest, 2.0 V at the release `x0`.
inline double LinearCell(double x, double x0) { return 0.3 + 1.7 * x / x0; }

}  // namespace impactlab::testing
