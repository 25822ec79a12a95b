// A whole text file as a string, for tests that read docs, logs and pages.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace impactlab::testing {

// Empty when the file cannot be read.
inline std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace impactlab::testing
