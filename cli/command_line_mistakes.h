// A command line CLI11 could not parse, said in the user's words: the option
// or subcommand that was mistyped, with the nearest one (io/spelling.h), rather
// than CLI11's "The following arguments were not expected", which names
// whatever was left over (often the session path).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace impactlab::cli {

// The subcommand of `parent` called `name` (or one of its aliases), or nullptr.
const CLI::App* FindSubcommand(const CLI::App& parent, const std::string& name);

// `path` is the command as typed from the top, e.g. "impactlab model".
// "model has no subcommand "kvv" (did you mean "kv"?); its subcommands are: kv, pt, ...".
std::string UnknownSubcommand(const CLI::App& parent, const std::string& path,
                              const std::string& typed);

// After `app.parse` threw: the mistake in words, ending with where to read
// more, or nullopt when CLI11's own message says it (a missing value, a value
// out of range). In order: an option no command of the line has (the nearest
// option's name, or the option whose help uses the word: `--reuse` points to
// `--fresh`), a subcommand that does not exist, a command that needs one.
std::optional<std::string> ExplainParseError(const CLI::App& app);

}  // namespace impactlab::cli
