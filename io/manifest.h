// Reads and validates a session manifest (format 1) with toml++.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "io/errors.h"
#include "io/session.h"

namespace impactlab {

struct ManifestWarning {
  InputLocation where;
  std::string message;  // e.g. "unknown key (ignored)"
};

struct ManifestReadResult {
  Session session;
  std::vector<ManifestWarning> warnings;  // unknown keys and other non-fatal findings
};

// Reads `session/session.toml` (`session`: the session folder, or that
// session.toml itself). Throws InputError naming the file, the key, the line
// where known, and what was expected. Paths in the manifest must stay inside
// the folder (no absolute paths, no "..", no symbolic link leading out);
// referenced files are checked to exist.
ManifestReadResult ReadManifest(const std::filesystem::path& session);

// The session folder `session` names: itself, or the folder of a session.toml.
std::filesystem::path SessionFolderOf(const std::filesystem::path& session);

// Same, from manifest text (tests); `manifest_path` is used in messages and its
// parent folder resolves relative paths.
ManifestReadResult ParseManifest(const std::string& toml_text,
                                 const std::filesystem::path& manifest_path);

// A setting's value written as on the command line (`method=gaussian`,
// `max_order=7`, `grid_model=true`): a TOML value, or else the text itself
// as a string.
SettingValue ParseSettingText(const std::string& text);

}  // namespace impactlab
