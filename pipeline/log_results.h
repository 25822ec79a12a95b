// The session's encoder/accelerometer logs, analysed for `reduce`
// (signal/log_analysis.h) and summarised for the results file.
#pragma once

#include "io/session.h"
#include "pipeline/session_result.h"
#include "signal/log_analysis.h"

namespace impactlab {

// Never throws for bad data: a log that cannot be analysed is a result with
// its status (file, line and reason).
LogResult ReduceLog(const Log& log, const LogAnalysisOptions& options);

}  // namespace impactlab
