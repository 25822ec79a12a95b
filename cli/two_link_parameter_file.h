// The two-link commands' parameter file, read and parsed (multibody/two_link_toml.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "io/errors.h"
#include "io/session_file.h"
#include "multibody/two_link_toml.h"

namespace impactlab::cli {

// Keys the file leaves out keep their values in `base` (default: the nominal set).
inline TwoLinkParameters ReadTwoLinkParameterFile(
    const std::filesystem::path& file,
    const TwoLinkParameters& base = TwoLinkParameters::Nominal()) {
  // Opened without blocking and refused unless a regular file: a named pipe
  // given as the parameter file must not make the command wait forever.
  constexpr std::uintmax_t kMostBytes = std::uintmax_t{1} << 20;  // 1 MiB: a parameter file
  const std::vector<unsigned char> bytes = SessionFile({}, file).ReadAll(kMostBytes);
  return ParseTwoLinkParameters(std::string(bytes.begin(), bytes.end()), file, base);
}

}  // namespace impactlab::cli
