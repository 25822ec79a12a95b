// The two-link commands' parameter file, read and parsed (multibody/two_link_toml.h).
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/errors.h"
#include "multibody/two_link_toml.h"

namespace impactlab::cli {

// Keys the file leaves out keep their values in `base` (default: the nominal set).
inline TwoLinkParameters ReadTwoLinkParameterFile(
    const std::filesystem::path& file,
    const TwoLinkParameters& base = TwoLinkParameters::Nominal()) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError({file, "", std::nullopt}, "cannot read the file");
  std::ostringstream text;
  text << in.rdbuf();
  return ParseTwoLinkParameters(text.str(), file, base);
}

}  // namespace impactlab::cli
