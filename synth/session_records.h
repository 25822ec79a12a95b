// What a synthetic session records about its runs: the manifest's entries, as
// a person at the scope would write them down, and the truth file's, exact.
// Both are values; synth/session_writer.h writes them. Part of
// synth/session_generator.cpp's plan -> simulate -> write.
#pragma once

#include <vector>

#include <nlohmann/json.hpp>

#include "synth/manifest_writer.h"
#include "synth/session_photos.h"
#include "synth/session_plan.h"
#include "synth/session_simulation.h"

namespace impactlab {

// The manifest without its runs and calibrations: the comment, title,
// apparatus and scope.
SessionManifest ManifestHeader(const SynthOptions& options);

// The manifest holds what was written down: scope settings to 6 significant
// digits (a delayed sweep's t0_div, a large offset, to 10), X0 to 6, typed-in
// maxima to 0.001 and their contact time to 4 digits.
std::vector<Calibration> ManifestCalibrations(const RunPlan& plan, const SimulatedRun& run,
                                              const RunPhotos& photos);
Run ManifestRun(const RunPlan& plan, const SimulatedRun& run, const RunPhotos& photos);

// The truth file's (docs/synth.md, "The truth file") run entry and
// calibration entries, in full precision.
nlohmann::json RunTruth(const RunPlan& plan, const SimulatedRun& run, const RunPhotos& photos);
std::vector<nlohmann::json> CalibrationTruths(const RunPlan& plan, const SimulatedRun& run,
                                              const RunPhotos& photos);

// The whole truth file around its runs and calibrations.
nlohmann::json SessionTruth(const SynthOptions& options, nlohmann::json runs,
                            nlohmann::json calibrations);

}  // namespace impactlab
