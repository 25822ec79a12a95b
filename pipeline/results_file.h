// The results file, layout 1 (docs/results.md; minimum in results-layout.md).
// Written atomically (temporary file, then rename); read back for the report.
#pragma once

#include <filesystem>

#include "pipeline/session_result.h"

namespace impactlab {

inline constexpr int kResultsLayout = 1;

// Throws InputError naming the file if it cannot be written; an earlier file
// at `path` is then left as it was.
void WriteResults(const SessionResult& result, const std::filesystem::path& path);

// Throws InputError naming the file and object for a file that is not a
// layout-1 results file.
SessionResult ReadResults(const std::filesystem::path& path);

}  // namespace impactlab
