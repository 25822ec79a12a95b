// Closing a log file that was written (internal to synth/): what the log
// writers share.
#pragma once

#include <filesystem>
#include <fstream>
#include <optional>

#include "io/errors.h"

namespace impactlab::synth_detail {

// Closes `out`, written to `file`; throws InputError if any write to it failed.
inline void CloseLog(std::ofstream& out, const std::filesystem::path& file) {
  out.close();
  if (!out) throw InputError({file, "", std::nullopt}, "cannot write the file");
}

}  // namespace impactlab::synth_detail
