// The bundled sample sessions, as the tests find them.
#pragma once

#include <filesystem>

namespace impactlab::testing {

// sample_data/ in the source tree.
inline const std::filesystem::path kSampleData =
    std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data";

}  // namespace impactlab::testing
