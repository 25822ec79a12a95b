// The thesis's typed-in session (sample_data/thesis-1969) reduced, as the
// report tests read it.
#pragma once

#include <filesystem>

#include "io/manifest.h"
#include "pipeline/reduce.h"

namespace impactlab::testing {

inline SessionResult Thesis() {
  const auto folder = std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "thesis-1969";
  return ReduceSession(ReadManifest(folder).session, {});
}

}  // namespace impactlab::testing
