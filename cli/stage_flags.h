// The stages' settings as command-line flags: one flag per setting of the
// options tree (pipeline/stage_options.h), named by its key, e.g.
// `--digitize.traces.method gaussian`, the same key as in session.toml and
// in the results file. A flag given overrides the manifest's setting.
#pragma once

#include <map>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "pipeline/stage_options.h"

namespace impactlab::cli {

class StageFlags {
 public:
  // Adds a flag for every setting whose key starts with one of `stages`
  // ("digitize", ...; all when empty), in the group "Stage settings".
  StageFlags(CLI::App& command, const std::vector<std::string>& stages = {});

  // The flags given, as settings located at their flag.
  StageSettings Given() const;

 private:
  // Owned here: CLI11 writes each flag's text into its slot while parsing.
  std::shared_ptr<std::map<std::string, std::string>> texts_;
  std::map<std::string, CLI::Option*> flags_;
};

}  // namespace impactlab::cli
