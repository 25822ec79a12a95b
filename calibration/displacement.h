// A run's trace in volts, read through its photocell's calibrated curve as
// displacement (thesis Chapter III, "Reduction of data").
#pragma once

#include <cstddef>
#include <string>

#include "calibration/photocell_calibration.h"
#include "io/trace.h"
#include "model/displacement_history.h"

namespace impactlab {

// A trace converted, or why the calibration cannot convert it.
struct DisplacementConversion {
  // false: `reason` says why (a trace without samples, or more than one
  // sample in fifty outside the calibrated voltages: the calibration does
  // not cover what the run needs); `history` and the counts still hold what
  // was converted and what was not.
  bool ok = false;
  std::string reason;
  DisplacementHistory history;
  std::size_t dropped = 0;  // samples outside the calibrated voltages, left out
};

// Each sample's displacement, with its sigma from the curve's own error and
// the sample's voltage noise (its own, or the calibration's residual RMS)
// through the curve's slope. Samples outside the calibrated voltages are
// dropped, never extrapolated; more than one in fifty is a result with `ok`
// false. Nothing is thrown for a trace the calibration cannot read.
DisplacementConversion DisplacementFromVolts(const Trace& trace,
                                             const CalibrationResult& calibration);

}  // namespace impactlab
