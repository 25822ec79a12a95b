// A run's trace in volts, read through its photocell's calibrated curve as
// displacement (thesis Chapter III, "Reduction of data").
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "calibration/photocell_calibration.h"
#include "io/trace.h"
#include "model/displacement_history.h"

namespace impactlab {

// How far outside the calibrated voltages a trace may be read before it is
// refused (docs/reduction.md, "Dynamic photocell calibration", item 4).
struct MisreadLimits {
  // A stretch of samples beyond the calibrated voltages (and their margin) by
  // more than this fraction of the calibrated span is no displacement the bar
  // can have: a bar swings between X = 0 and about X0, as its calibration
  // did, and a photo's reading noise is a few thousandths of the span. It is
  // a line that is not the trace (a mark, a scratch, a grid line followed), 1.
  double far_beyond_span = 0.05;
  // Such a stretch is grown over the neighbours that lead out to it and back
  // (each no nearer the calibrated voltages than the one beyond it, less 3
  // sigma), across time gaps of at most this many median sample intervals
  // (a chopped trace's dashes), 1.
  double max_gap_intervals = 8.0;
  // The stretches left out may cover at most this fraction of the trace's
  // span: beyond it the trace read is mostly not the bar's, 1.
  double max_span_fraction = 1.0 / 3.0;
  // A trace whose volts span no more than the calibrated span and this
  // fraction of it could be the bar's trace shifted whole (a zero mistyped:
  // the impacts' stretches beyond X = 0, the release's pulled in): its
  // stretches far outside are not left out, 1. A line followed off the trace
  // adds its own reach to the trace's span.
  double shift_fits_span = 0.02;
  // A run whose typed X0 exceeds its calibration's by no more than this
  // fraction of it is released within the calibrated swing: what its trace
  // shows beyond the release's end of the calibrated volts before it first
  // comes within them is the hold at X0 read a little off (a bold trace's
  // edge, a grid line or a mark beside it), not a swing the calibration
  // misses, 1. Beyond it, the calibration truly may not reach.
  double release_within = 0.01;
};

// A trace converted, or why the calibration cannot convert it.
struct DisplacementConversion {
  // false: `reason` says why (a trace without samples; more than one sample
  // in fifty outside the calibrated voltages but near them: the calibration
  // does not cover what the run needs; or stretches far outside that begin
  // the trace beyond the release's end of the calibrated volts, cover more
  // than MisreadLimits allow, or lie on a trace that fits the calibrated
  // volts shifted whole); `history` and the
  // counts still hold what was converted and what was not.
  bool ok = false;
  std::string reason;
  DisplacementHistory history;
  std::size_t dropped = 0;  // samples just outside the calibrated voltages, left out
  // Stretches far outside the calibrated voltages, with the samples leading
  // out to them and back, left out as misread: first and last sample's
  // times, s; `left_out` samples in all (not counted in `dropped`).
  std::vector<std::pair<double, double>> left_out_s;
  std::size_t left_out = 0;
  // Samples from the trace's start just beyond the release's end of the
  // calibrated volts, of a run released within its calibration's swing
  // (MisreadLimits::release_within): the hold at X0, left out and not
  // counted in `dropped` (no rebound is read there).
  std::size_t hold_beyond = 0;
};

// Each sample's displacement, with its sigma from the curve's own error and
// the sample's voltage noise (its own, or the calibration's residual RMS)
// through the curve's slope. Samples outside the calibrated voltages are
// dropped, never extrapolated: more than one in fifty just outside is a
// result with `ok` false, the calibration not covering the run; stretches far
// outside are left out as misread (MisreadLimits). `run_release_x`: the run's
// typed X0, 0 where not known; a run released within its calibration's swing
// has what its trace's start shows beyond the release's end of the
// calibrated volts left out, near or far, instead of refused. Nothing is
// thrown for a trace the calibration cannot read.
DisplacementConversion DisplacementFromVolts(const Trace& trace,
                                             const CalibrationResult& calibration,
                                             const MisreadLimits& limits = {},
                                             double run_release_x = 0.0);

}  // namespace impactlab
