// What a reduce is asked to do (`impactlab reduce`'s options), apart from the
// reduce itself: what a run's fingerprint (pipeline/run_fingerprint.h) and
// the command line need without the orchestration.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "pipeline/session_result.h"
#include "pipeline/stage_options.h"

namespace impactlab {

// What to produce; each product includes the ones before it.
enum class Products {
  kCalibration,  // the photocell calibrations only
  kRebounds,     // and each run's measured maxima, times and contact time
  kFit,          // and the Kelvin-Voigt fits and the cross-run tables (everything)
};

// What `reduce` has done so far, for a progress display.
struct ReduceProgress {
  std::string item;  // "log case1", "calibration 0.713-right", "run 0.234"
  bool ok = true;
  bool reused = false;  // a run whose measurement came from the earlier results
  std::size_t done = 0, total = 0;
};

struct ReduceOptions {
  // Overrides of the manifest's [reduction] settings (nullopt: the manifest's).
  std::optional<PendulumConvention> convention;
  std::optional<Separation> separation;
  // Every stage's options before the manifest's settings apply to them.
  StageOptions stages;
  // Settings over the manifest's, its entries' own included (the command
  // line's; pipeline/stage_options.h).
  StageSettings overrides;
  std::string producer = "impactlab";  // recorded in the results and in every fingerprint
  Products products = Products::kFit;
  int jobs = 1;  // runs reduced in parallel (threads), >= 1
  // An earlier results file of this session: a run whose fingerprint is
  // unchanged reuses its measurement from there instead of measuring again.
  const SessionResult* previous = nullptr;
  // Called after each piece of work (a log, a calibration, a run), from the
  // thread that did it (serialised). `total` may grow while the session's
  // plan is made; it never falls.
  std::function<void(const ReduceProgress& progress)> on_progress;
};

}  // namespace impactlab
