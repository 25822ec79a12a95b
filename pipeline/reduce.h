// `impactlab reduce`: a session in, a SessionResult out.
//
// Runs are independent: one that cannot be reduced is kept with its reason and
// the others go on. Runs with typed-in maxima go straight to the fit; the
// cross-run analysis and predictions follow from the runs that succeeded.
#pragma once

#include "io/session.h"
#include "pipeline/reduce_options.h"
#include "pipeline/session_result.h"

namespace impactlab {

// Throws InputError for a setting of the manifest's stage tables or of
// `options.overrides` that does not apply, before any work; a run's, a
// calibration's or a log's own bad setting fails that entry alone.
SessionResult ReduceSession(const Session& session, const ReduceOptions& options);

}  // namespace impactlab
