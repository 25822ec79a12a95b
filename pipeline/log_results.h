// The session's encoder/accelerometer logs, analysed for `reduce`
// (signal/log_analysis.h): each source's impact and channels and the
// sources' comparison as the analysis returns them.
#pragma once

#include "io/session.h"
#include "pipeline/session_result.h"
#include "signal/log_analysis.h"

namespace impactlab {

// Never throws for bad data: a log that cannot be analysed is a result with
// its status (file, line and reason).
LogResult ReduceLog(const Log& log, const LogAnalysisOptions& options);

// The one spectrum of a channel the results file keeps and the report
// plots: the post-impact segment's, which the dominant frequency is read
// from, else the whole record's; null when neither was computed.
const SegmentSpectrum* KeptSpectrum(const ChannelAnalysis& c);

}  // namespace impactlab
