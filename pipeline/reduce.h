// `impactlab reduce`: a session in, a SessionResult out.
//
// Runs are independent: one that cannot be reduced is kept with its reason and
// the others go on. Runs with typed-in maxima go straight to the fit; the
// cross-run analysis and predictions follow from the runs that succeeded.
#pragma once

#include <optional>
#include <string>

#include "io/session.h"
#include "pipeline/session_result.h"

namespace impactlab {

struct ReduceOptions {
  // Overrides of the manifest's [reduction] settings (nullopt: the manifest's).
  std::optional<PendulumConvention> convention;
  std::optional<Separation> separation;
  std::string producer = "impactlab";  // recorded in the results
};

SessionResult ReduceSession(const Session& session, const ReduceOptions& options);

}  // namespace impactlab
