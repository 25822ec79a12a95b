// An earlier results file of the same session, which `reduce` reuses the
// unchanged runs' measurements from (docs/reduction.md, fingerprints).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/session.h"
#include "pipeline/session_result.h"

namespace impactlab {

// The results file at `path`, if there is a readable one, without the runs
// whose values must not be reused: a hand-edited or corrupted file is never
// trusted. Typed-in runs never reuse, so their values there are not looked
// at. Each thing not reused is said in a note in `notes`.
std::optional<SessionResult> PreviousResults(const std::filesystem::path& path,
                                             const Session& session,
                                             std::vector<std::string>* notes);

}  // namespace impactlab
