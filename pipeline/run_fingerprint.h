// A run's fingerprint: a hash of everything its measurement depends on (the
// manifest entries of the run and its calibrations, the apparatus and
// reduction settings as reduce resolves them: pendulum convention,
// separation; the program version and commit; the settings of the
// stages that measure this run and its calibrations, as each resolves them
// (pipeline/stage_options.h); and the bytes of every input file). An unchanged fingerprint lets
// `reduce` reuse the run's earlier measurement from the existing results file.
#pragma once

#include <string>

#include "io/session.h"
#include "pipeline/reduce_options.h"
#include "pipeline/session_result.h"

namespace impactlab {

// 32 hex digits (XXH3-128). `options`: the reduce's (producer and the
// overrides of the manifest's convention and separation, the stages'
// options and settings). Throws InputError if an input file cannot be read or
// a setting does not apply, std::invalid_argument for an unknown convention
// or separation.
std::string RunFingerprint(const Run& run, const Session& session, const ReduceOptions& options);

// Why a previous result's measurement of a run must not be reused (a value
// that is not finite, sizes that disagree: a hand-edited or corrupted file),
// e.g. "xmax[2] is nan"; empty when it may be.
std::string ReuseProblem(const RunMeasurement& previous);

}  // namespace impactlab
