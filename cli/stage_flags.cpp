#include "cli/stage_flags.h"

#include <algorithm>
#include <utility>
#include <variant>

#include <fmt/format.h>

#include "cli/commands.h"

namespace impactlab::cli {
StageFlags::StageFlags(CLI::App& command, const std::vector<std::string>& stages)
    : texts_(std::make_shared<std::map<std::string, std::string>>()) {
  const StageOptions defaults;
  ForEachSetting(defaults, [&](const std::string& key, const auto& field, const char* help) {
    using Field = std::decay_t<decltype(field)>;
    const std::string stage = key.substr(0, key.find('.'));
    if (!stages.empty() && std::find(stages.begin(), stages.end(), stage) == stages.end()) return;
    const std::string description = fmt::format("{} ({}; default {})", help, SettingKind<Field>(),
                                                SettingText(ToSettingValue(field)));
    flags_[key] = command.add_option("--" + key, (*texts_)[key], description)
                      ->group("Stage settings (also session.toml's [" + stage + "] table)")
                      ->type_name("");
  });
}

StageSettings StageFlags::Given() const {
  std::vector<std::pair<std::string, std::string>> given;
  for (const auto& [key, flag] : flags_) {
    if (flag->count() > 0) given.emplace_back(key, texts_->at(key));
  }
  return CommandLineSettings(given);
}

void AddSettingsCommand(CLI::App& app, Action& action) {
  app.add_subcommand("settings",
                     "List every stage setting: its key (in session.toml's stage tables, as a "
                     "--flag of reduce, in the results file), kind, default and meaning")
      ->callback([&action] {
        action = [] {
          fmt::print("{}", SettingsTable());
          return kExitOk;
        };
      });
}

}  // namespace impactlab::cli
