#include "pipeline/stage_options.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "io/errors.h"
#include "io/manifest.h"
#include "io/spelling.h"
#include "pipeline/setting_key_internal.h"

namespace impactlab {

bool StageOptions::Check(std::string* why) const {
  std::string inner;
  const auto in = [&](const char* stage, bool ok) {
    if (!ok) *why = fmt::format("{}: {}", stage, inner);
    return ok;
  };
  return in("digitize", digitize.Check(&inner)) && in("photocell", photocell.Check(&inner)) &&
         in("rebound_extraction", rebound_extraction.Check(&inner)) &&
         in("fit", fit.Check(&inner)) && in("log_analysis", log_analysis.Check(&inner)) &&
         in("products", products.Check(&inner));
}

StageOptions WithSettings(StageOptions options, const StageSettings& settings) {
  for (const auto& [key, setting] : settings) {
    if (const auto problem = ApplySetting(options, key, setting.value)) {
      const std::string known = SettingKeys(options, pipeline_internal::StageOf(key));
      std::vector<std::string> every;
      ForEachSetting(options,
                     [&](const std::string& k, const auto&, const char*) { every.push_back(k); });
      throw InputError(setting.where,
                       problem->problem == "no such setting"
                           ? fmt::format("no such setting{}; the {} settings are: {}",
                                         DidYouMean(key, every), pipeline_internal::StageOf(key),
                                         known.empty() ? "(none: no such stage)" : known)
                           : problem->problem);
    }
  }
  if (std::string why; !options.Check(&why)) {
    // Name the first setting given for the stage that fails, where the user wrote it.
    const std::string stage = why.substr(0, why.find(':'));
    const StageSetting* culprit = nullptr;
    for (const auto& [key, setting] : settings) {
      if (pipeline_internal::StageOf(key) != stage) continue;
      const std::string field = key.substr(key.rfind('.') + 1);
      if (culprit == nullptr || why.find(field) != std::string::npos) culprit = &setting;
      if (why.find(field) != std::string::npos) break;
    }
    if (culprit != nullptr) throw InputError(culprit->where, why);
    // The defaults themselves: a programming error (exit 5), not a bad command line.
    throw std::logic_error(why);
  }
  return options;
}

StageOptions SessionStageOptions(const StageOptions& defaults, const Session& session,
                                 const StageSettings& overrides) {
  return WithSettings(WithSettings(defaults, session.settings), overrides);
}

StageOptions EntryStageOptions(const StageOptions& session_options, const StageSettings& entry,
                               const StageSettings& overrides) {
  if (entry.empty()) return session_options;  // the command line's are in already
  return WithSettings(WithSettings(session_options, entry), overrides);
}

SettingValues SettingsOfStages(const StageOptions& options,
                               std::initializer_list<std::string_view> stages) {
  SettingValues all = SettingsOf(options);
  std::erase_if(all, [&](const auto& entry) {
    return std::find(stages.begin(), stages.end(), pipeline_internal::StageOf(entry.first)) ==
           stages.end();
  });
  return all;
}

std::string SettingsTable(const StageOptions& defaults) {
  std::string table =
      "| key | value | default | meaning |\n"
      "|---|---|---|---|\n";
  ForEachSetting(defaults, [&](const std::string& key, const auto& field, const char* help) {
    using Field = std::decay_t<decltype(field)>;
    const SettingValue value = ToSettingValue(field);
    const std::string text = std::holds_alternative<std::string>(value)
                                 ? "\"" + SettingText(value) + "\""
                                 : SettingText(value);
    table += fmt::format("| `{}` | {} | `{}` | {} |\n", key, SettingKind<Field>(), text, help);
  });
  return table;
}

StageSettings CommandLineSettings(
    const std::vector<std::pair<std::string, std::string>>& assignments) {
  StageSettings settings;
  for (const auto& [key, text] : assignments) {
    settings[key] =
        StageSetting{ParseSettingText(text), InputLocation{kCommandLine, "--" + key, {}}};
  }
  return settings;
}

}  // namespace impactlab
