// A stage setting's key, "stage.field..." (internal to pipeline/): what the
// stage options and the results file share.
#pragma once

#include <string>

namespace impactlab::pipeline_internal {

// The stage a key belongs to: "digitize" for "digitize.traces.method".
inline std::string StageOf(const std::string& key) { return key.substr(0, key.find('.')); }

}  // namespace impactlab::pipeline_internal
