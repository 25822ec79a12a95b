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
  if (!std::filesystem::exists(path)) return std::nullopt;
  SessionResult previous;
  try {
    previous = ReadResults(path);
  } catch (const std::exception& e) {
    notes->push_back(fmt::format("not reusing {}: {}", path.string(), e.what()));
    return std::nullopt;
  }
  std::erase_if(previous.runs, [&](const RunResult& run) {
    const auto in_session = std::find_if(session.runs.begin(), session.runs.end(),
                                         [&](const Run& r) { return r.id == run.id; });
    if (in_session == session.runs.end() || in_session->HasTypedRebounds()) return false;
    if (run.measured.xmax.empty()) return false;  // nothing measured there: nothing to reuse
    const std::string problem = ReuseProblem(run.measured);
    if (problem.empty()) return false;
    notes->push_back(fmt::format("not reusing run {} from {}: {}", run.id, path.string(), problem));
    return true;
  });
  return previous;
}

}  // namespace impactlab
