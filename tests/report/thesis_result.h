// The thesis's typed-in session (sample_data/thesis-1969) reduced, as the
// report tests read it.
#pragma once

#include <filesystem>
#include <vector>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "report/tables.h"

namespace impactlab::testing {

inline SessionResult Thesis() {
  const auto folder = std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "thesis-1969";
  return ReduceSession(ReadManifest(folder).session, {});
}

inline std::vector<Table> ThesisTables() { return BuildTables(Thesis()); }

}  // namespace impactlab::testing
