// A run's trace in volts, read through its photocell's calibrated curve as
// displacement (thesis Chapter III, "Reduction of data").
#pragma once

#include "calibration/photocell_calibration.h"
#include "io/trace.h"
#include "model/displacement_history.h"

namespace impactlab {

// Each sample's displacement, with its sigma from the curve's own error and
// the sample's voltage noise (its own, or the calibration's residual RMS)
// through the curve's slope. Samples outside the calibrated voltages are
// dropped, never extrapolated; throws std::invalid_argument when more than
// one in fifty are: the calibration does not cover what the run needs.
DisplacementHistory DisplacementFromVolts(const Trace& trace, const CalibrationResult& calibration);

}  // namespace impactlab
