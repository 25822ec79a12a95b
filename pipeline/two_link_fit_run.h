// `impactlab fit two-link` without its files (docs/two-link-fit.md): one
// [[log]]'s experiment, as read, turned into the fit's measurement; the fit;
// and the fitted parameters' simulation of the log's case, which the command
// writes beside the experiment so that `reduce` shows fitted against measured.
#pragma once

#include "fit/two_link_fit.h"
#include "io/log_reader.h"
#include "io/session.h"
#include "multibody/two_link_parameters.h"
#include "multibody/two_link_simulation.h"

namespace impactlab {

struct TwoLinkFitRun {
  TwoLinkFitResult fit;             // !fit.ok: the fit refused the log or the start (its reason)
  TwoLinkRecord fitted_simulation;  // the fitted parameters, the fitted case, SI; empty, !ok
                                    // ("not simulated: " and the fit's reason) when the fit
                                    // refused
};

// The experiment's channels by the simulator's names (multibody/two_link_channels.h),
// in SI, its time from 0; an encoder's step is one count at the output,
// 2 pi / (counts_per_rev gear_ratio). Channels of other names are left out.
// `experiment` is ReadLogSeries of the log's experiment file with its channels.
TwoLinkMeasurement TwoLinkMeasurementOfLog(const Log& log, const LogSeries& experiment);

// Fits `start` to the log's experiment (FitTwoLinkSimulation) and simulates
// the fitted case (a record with !ok where the model refuses it). A log or
// start the fit refuses is a run with !fit.ok and its reason; throws only what
// FitTwoLinkSimulation throws for the caller's options and keys.
TwoLinkFitRun FitTwoLinkToLog(const TwoLinkParameters& start, const Log& log,
                              const LogSeries& experiment, const TwoLinkFitOptions& options);

}  // namespace impactlab
