// A session folder in a temporary directory for manifest tests: a manifest
// and the (empty) files it names.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include "io/manifest.h"
#include "tests/support/temp_dir.h"

namespace impactlab::testing {

// The start of most test manifests: valid on its own.
inline const std::string kManifestHeader = R"toml(format = 1
[apparatus]
pendulum_length = 22.0
weight = 2.23
)toml";

// A session folder in a temporary directory: a manifest and the files it names.
class SessionFolder {
 public:
  std::filesystem::path path() const { return dir_.path(); }
  std::filesystem::path manifest() const { return dir_.path() / "session.toml"; }

  // Creates an (empty) file; the reader only checks that referenced files exist.
  std::filesystem::path Touch(const std::filesystem::path& relative) const {
    const std::filesystem::path full = dir_.path() / relative;
    std::filesystem::create_directories(full.parent_path());
    std::ofstream(full) << "";
    return full;
  }

  void Write(const std::string& text) const { std::ofstream(manifest()) << text; }

  ManifestReadResult Read() const { return ReadManifest(dir_.path()); }

 private:
  TempDir dir_;
};

}  // namespace impactlab::testing
