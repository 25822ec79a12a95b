// A run's fingerprint: a hash of everything its measurement depends on (the
// manifest entries of the run and its calibrations, the apparatus and
// reduction settings, the program version, and the bytes of every input
// file). An unchanged fingerprint lets `reduce` reuse the run's earlier
// measurement from the existing results file.
#pragma once

#include <string>

#include "io/session.h"

namespace impactlab {

// 32 hex digits (XXH3-128). Throws InputError if an input file cannot be read.
std::string RunFingerprint(const Run& run, const Session& session, const std::string& producer);

}  // namespace impactlab
