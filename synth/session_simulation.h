// A planned run (synth/session_plan.h) simulated: the experiment, the two
// photocells, and every trace the scope shows with the settings it shows it
// with. Values only; nothing is drawn at random here that the plan has not
// seeded, and nothing is written. Part of synth/session_generator.cpp's plan
// -> simulate -> write.
#pragma once

#include <vector>

#include "io/session.h"
#include "io/trace.h"
#include "synth/experiment.h"
#include "synth/photocell.h"
#include "synth/session_plan.h"

namespace impactlab {

// One trace as the scope shows it.
struct ScopeTrace {
  std::vector<double> time_s;
  std::vector<double> volts;
  TraceSettings settings;  // the screen settings it is shown with
};

// A calibration: the bar released alone from its X0, its cell's noisy trace
// over a 0.05 s/div sweep triggered at the release.
struct SimulatedCalibration {
  double release_x = 0.0;  // the bar's X0, length units
  ScopeTrace trace;
};

struct SimulatedRun {
  ExperimentResult experiment;
  // What the manifest gives as X0: half the measured gap between the bars at release.
  double initial_displacement = 0.0;
  SimulatedPhotocell right_cell, left_cell;
  ImpactTruth shown_impact;  // the impact the contact trace shows
  // The rest is empty for typed-in maxima.
  std::vector<SimulatedCalibration> calibrations;  // as the plan's
  ScopeTrace right, left;  // the bars' displacements: 0.5 s/div from 0.1 s before the release
  ScopeTrace contact;      // the contact circuit's step: 50 us/div around the shown impact
  Trace contact_samples;   // CSV runs: the contact circuit as a digital scope samples it
};

// Throws std::domain_error with the simulation's reason when the plan's
// options do not let the model simulate the run to its end (its
// ExperimentResult is !ok): the session's options are outside the model's
// domain.
SimulatedRun SimulateRun(const RunPlan& plan);

}  // namespace impactlab
