#include "cli/command_line_mistakes.h"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

#include "io/spelling.h"

namespace impactlab::cli {
namespace {

// The commands chosen on the line, from the top: impactlab, model, kv.
std::vector<const CLI::App*> ChosenCommands(const CLI::App& app) {
  std::vector<const CLI::App*> chain{&app};
  for (;;) {
    const std::vector<CLI::App*> chosen = chain.back()->get_subcommands();
    if (chosen.empty()) return chain;
    chain.push_back(chosen.front());
  }
}

// "model kv" for the chain impactlab, model, kv ("" for impactlab alone).
std::string CommandWords(const std::vector<const CLI::App*>& chain) {
  std::string words;
  for (std::size_t i = 1; i < chain.size(); ++i) {
    words += (words.empty() ? "" : " ") + chain[i]->get_name();
  }
  return words;
}

// Named subcommands only (CLI11 option groups are nameless subcommands).
std::vector<const CLI::App*> NamedSubcommands(const CLI::App& parent) {
  return parent.get_subcommands([](const CLI::App* sub) { return !sub->get_name().empty(); });
}

// What is left over that looks like an option: `-x`, `--word`, `--word=value`;
// a negative number is a value.
bool LooksLikeOption(const std::string& token) {
  if (token.size() < 2 || token[0] != '-') return false;
  double number = 0.0;
  return !CLI::detail::lexical_cast(token, number);
}

// The option whose help uses `word` (`reuse` is in --fresh's "instead of
// reusing ..."): for a flag named after what it turns off, or by a synonym.
const CLI::Option* OptionAbout(const CLI::App& command, const std::string& word) {
  if (word.size() < 5 || word.find_first_of(".-_") != std::string::npos) return nullptr;
  // "reuse" matches "reusing", "reused": the word less its last letter starts a word of the help.
  const std::string stem = word.substr(0, word.size() - 1);
  for (const CLI::Option* option : command.get_options()) {
    // Not the stage settings: their helps describe the physics, not the command.
    if (option->get_lnames().empty() ||
        option->get_lnames().front().find('.') != std::string::npos) {
      continue;
    }
    std::string help = option->get_description();
    std::transform(help.begin(), help.end(), help.begin(),
                   [](unsigned char c) { return std::isalnum(c) ? std::tolower(c) : ' '; });
    const std::size_t at = (" " + help).find(" " + stem);
    if (at != std::string::npos) return option;
  }
  return nullptr;
}

std::string UnknownOption(const CLI::App& command, const std::string& words,
                          const std::string& token) {
  const std::string typed = token.substr(0, token.find('='));
  const std::string bare = typed.substr(std::min(typed.find_first_not_of('-'), typed.size()));
  std::vector<std::string> long_names;
  for (const CLI::Option* option : command.get_options()) {
    for (const std::string& name : option->get_lnames()) long_names.push_back(name);
  }
  std::string hint;
  const std::optional<std::string> nearest =
      typed.starts_with("--") ? NearestWord(bare, long_names) : std::nullopt;
  if (nearest) {
    hint = fmt::format(" (did you mean \"--{}\"?)", *nearest);
  } else if (const CLI::Option* about = OptionAbout(command, bare)) {
    hint = fmt::format("; see --{}: {}", about->get_lnames().front(), about->get_description());
  }
  const std::string name = words.empty() ? "impactlab" : words;
  return fmt::format("error: {} has no option {}{}\nRun `impactlab help{}` for its options.", name,
                     typed, hint, words.empty() ? "" : " " + words);
}

}  // namespace

const CLI::App* FindSubcommand(const CLI::App& parent, const std::string& name) {
  for (const CLI::App* sub : NamedSubcommands(parent)) {
    const auto& aliases = sub->get_aliases();
    if (sub->get_name() == name || std::find(aliases.begin(), aliases.end(), name) != aliases.end())
      return sub;
  }
  return nullptr;
}

std::string UnknownSubcommand(const CLI::App& parent, const std::string& words,
                              const std::string& typed) {
  std::vector<std::string> names, known;
  for (const CLI::App* sub : NamedSubcommands(parent)) {
    names.push_back(sub->get_name());
    known.push_back(sub->get_name());
    for (const std::string& alias : sub->get_aliases()) known.push_back(alias);
  }
  if (words.empty()) {
    return fmt::format(
        "error: no command \"{}\"{}; the commands are: {}\nRun `impactlab help` for more.", typed,
        DidYouMean(typed, known), fmt::join(names, ", "));
  }
  return fmt::format(
      "error: {} has no subcommand \"{}\"{}; its subcommands are: {}\nRun `impactlab help {}` "
      "for more.",
      words, typed, DidYouMean(typed, known), fmt::join(names, ", "), words);
}

std::optional<std::string> ExplainParseError(const CLI::App& app) {
  const std::vector<const CLI::App*> chain = ChosenCommands(app);
  // A command with subcommands and none chosen: the word given instead, if
  // any (before its options, which are the subcommand's: `model kvv --mass 1`).
  const CLI::App& last = *chain.back();
  const std::string words = CommandWords(chain);
  if (chain.size() > 1 && !NamedSubcommands(last).empty() && last.get_subcommands().empty() &&
      last.get_require_subcommand_min() > 0) {
    for (const std::string& token : app.remaining(true)) {
      if (!LooksLikeOption(token)) return UnknownSubcommand(last, words, token);
    }
    std::vector<std::string> names;
    for (const CLI::App* sub : NamedSubcommands(last)) names.push_back(sub->get_name());
    return fmt::format("error: {} needs a subcommand: {}\nRun `impactlab help {}` for more.", words,
                       fmt::join(names, ", "), words);
  }
  // An unknown option, said against the command it was given to (CLI11 keeps
  // it there even when a later check, e.g. a required option, threw first).
  for (std::size_t i = chain.size(); i-- > 0;) {
    for (const std::string& token : chain[i]->remaining()) {
      if (LooksLikeOption(token)) {
        const std::vector<const CLI::App*> to(chain.begin(), chain.begin() + i + 1);
        return UnknownOption(*chain[i], CommandWords(to), token);
      }
    }
  }
  return std::nullopt;
}

}  // namespace impactlab::cli
