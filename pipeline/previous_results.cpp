#include "pipeline/previous_results.h"

#include <algorithm>
#include <exception>

#include <fmt/format.h>

#include "pipeline/results_file.h"
#include "pipeline/run_fingerprint.h"

namespace impactlab {

std::optional<SessionResult> PreviousResults(const std::filesystem::path& path,
                                             const Session& session,
                                             std::vector<std::string>* notes) {
  // Only runs measured from traces can reuse; reading a file for none of
  // them would cost more than the typed-in runs' whole reduce.
  const auto measured_from_traces = [&](const std::string& id) {
    return std::any_of(session.runs.begin(), session.runs.end(),
                       [&](const Run& r) { return r.id == id && !r.HasTypedRebounds(); });
  };
  const bool any = std::any_of(session.runs.begin(), session.runs.end(),
                               [](const Run& r) { return !r.HasTypedRebounds(); });
  if (!any || !std::filesystem::exists(path)) return std::nullopt;
  SessionResult previous;
  try {
    previous = ReadRunMeasurements(path, measured_from_traces);
  } catch (const std::exception& e) {
    notes->push_back(fmt::format("not reusing {}: {}", path.string(), e.what()));
    return std::nullopt;
  }
  std::erase_if(previous.runs, [&](const RunResult& run) {
    if (run.measured.xmax.empty()) return false;  // nothing measured there: nothing to reuse
    const std::string problem = ReuseProblem(run.measured);
    if (problem.empty()) return false;
    notes->push_back(fmt::format("not reusing run {} from {}: {}", run.id, path.string(), problem));
    return true;
  });
  return previous;
}

}  // namespace impactlab
