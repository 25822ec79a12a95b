// The stages' settings: every key of the options tree reads from a manifest's
// stage table into the field it names, the command line's override the
// manifest's, an entry's own apply to it alone, and a bad one is refused
// naming the file, the key and the line.
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <variant>

#include <fmt/format.h>
#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/stage_options.h"

namespace impactlab {
namespace {

// A value unlike the default, of the same kind: the next word of an enum,
// the other truth value, a number moved off its default.
template <typename Field>
SettingValue Changed(const Field& field) {
  if constexpr (std::is_same_v<Field, bool>) {
    return !field;
  } else if constexpr (EnumSetting<Field>) {
    const auto names = SettingNames(field);
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i].value == field) return std::string(names[(i + 1) % names.size()].name);
    }
    return std::string();
  } else if constexpr (std::is_integral_v<Field>) {
    return static_cast<long long>(field) + 3;
  } else {
    return field == 0.0 ? 0.125 : field * 1.25;
  }
}

std::string TomlValue(const SettingValue& value) {
  return std::visit(
      [](const auto& v) -> std::string {
        using V = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<V, std::string>) return fmt::format("\"{}\"", v);
        if constexpr (std::is_same_v<V, bool>) return v ? "true" : "false";
        if constexpr (std::is_same_v<V, double>) return fmt::format("{:.17g}", v);
        return fmt::format("{}", v);
      },
      value);
}

constexpr const char* kHeader = R"(format = 1
title = "settings"
)";

}  // namespace

TEST_CASE("stage_options: every setting reads from its manifest table into the field it names") {
  // Each key written as a dotted key of its stage table, with a value unlike
  // its default; read back, the options hold exactly those values.
  std::string manifest = kHeader;
  SettingValues expected;
  const StageOptions defaults;
  ForEachSetting(defaults, [&](const std::string& key, const auto& field, const char*) {
    const std::string stage = key.substr(0, key.find('.'));
    const SettingValue value = Changed(field);
    manifest += fmt::format("{} = {}\n", key, TomlValue(value));
    expected[key] = value;
  });
  const Session session = ParseManifest(manifest, "/tmp/s/session.toml").session;
  REQUIRE(session.settings.size() == expected.size());
  StageOptions options;
  for (const auto& [key, setting] : session.settings) {
    INFO(key);
    CHECK_FALSE(ApplySetting(options, key, setting.value).has_value());
  }
  const SettingValues read = SettingsOf(options);
  for (const auto& [key, value] : expected) {
    INFO(key << " = " << TomlValue(value));
    CHECK(read.at(key) == value);
  }
  CHECK(read.size() == expected.size());
}

TEST_CASE("stage_options: the defaults pass their check and every stage table is a manifest key") {
  std::string why;
  const StageOptions defaults;
  CHECK(defaults.Check(&why));
  std::vector<std::string> stages;
  StageOptions::VisitSettings(
      defaults, [&](const char* name, const auto&, const char*) { stages.push_back(name); });
  CHECK(stages == std::vector<std::string>(kStageTables.begin(), kStageTables.end()));
}

TEST_CASE(
    "stage_options: defaults that fail their check are a programming error, not a usage one") {
  // No setting of the user's is to blame: the CLI says "internal error"
  // (exit 5) for a logic_error, where an invalid_argument would read as a
  // bad command line (exit 2).
  StageOptions broken;
  broken.photocell.max_order = 0;
  CHECK_THROWS_AS(WithSettings(broken, {}), std::logic_error);
  bool usage = false;
  try {
    WithSettings(broken, {});
  } catch (const std::invalid_argument&) {
    usage = true;
  } catch (const std::logic_error&) {
  }
  CHECK_FALSE(usage);
}

TEST_CASE("stage_options: a setting is refused naming the manifest, its key and line") {
  // The manifest read, then the session's options resolved: why either refuses.
  const auto refusal = [](const std::string& tables) {
    try {
      const Session session =
          ParseManifest(std::string(kHeader) + tables, "/tmp/s/session.toml").session;
      SessionStageOptions({}, session, {});
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  // A misspelt key: the stage's keys are listed.
  std::string why = refusal("[digitize.traces]\nmethd = \"gaussian\"\n");
  CHECK_THAT(why,
             Catch::Contains("session.toml:4") && Catch::Contains("digitize.traces.methd") &&
                 Catch::Contains("no such setting (did you mean \"digitize.traces.method\"?)") &&
                 Catch::Contains("traces.method"));
  // A word that is not one of the choices.
  why = refusal("[digitize]\ntraces.method = \"median\"\n");
  CHECK_THAT(why, Catch::Contains("session.toml:4") && Catch::Contains("centroid, gaussian"));
  // A number where a word is expected, and a fraction for a whole number.
  CHECK_THAT(refusal("[fit.kelvin_voigt.loss]\nkind = 2\n"), Catch::Contains("expected one of"));
  CHECK_THAT(refusal("[photocell]\nmax_order = 6.5\n"), Catch::Contains("a whole number"));
  // In range of its type but not of the stage: the options' check, at the key.
  why = refusal("[photocell]\nmax_order = 40\n");
  CHECK_THAT(why, Catch::Contains("session.toml:4") && Catch::Contains("photocell.max_order") &&
                      Catch::Contains("max_order must be 1..20"));
  // An array is no setting: the manifest is refused as it is read.
  CHECK_THAT(refusal("[rebound_extraction]\nthreshold_fraction = [0.1]\n"),
             Catch::Contains("session.toml:4") && Catch::Contains("expected a setting"));
  CHECK(refusal("[rebound_extraction]\nthreshold_fraction = 0.05\n") == "accepted");
}

TEST_CASE("stage_options: the command line overrides the manifest, an entry's own apply to it") {
  const Session session = ParseManifest(std::string(kHeader) + R"(
[digitize.traces]
method = "gaussian"
min_coverage = 0.1
[[log]]
id = "beam"
experiment = "log.csv"
[log.log_analysis]
fit_delay_s = 0.01
)",
                                        "/tmp/nonexistent/session.toml")
                              .session;
  // The log's file does not exist: the entry is rejected, its settings read all the same.
  REQUIRE(session.settings.size() == 2);
  const StageSettings command_line = CommandLineSettings(
      {{"digitize.traces.method", "parabola"}, {"fit.kelvin_voigt.loss.kind", "huber"}});
  const StageOptions options = SessionStageOptions({}, session, command_line);
  CHECK(options.digitize.traces.method == SubpixelMethod::kParabola);
  CHECK(options.digitize.traces.min_coverage == 0.1);
  CHECK(options.fit.kelvin_voigt.loss.kind == RobustLoss::kHuber);

  StageSettings entry;
  entry["log_analysis.fit_delay_s"] = {0.01, {"session.toml", "log \"beam\".log_analysis", 9}};
  entry["digitize.traces.method"] = {std::string("centroid"), {"session.toml", "run", 3}};
  const StageOptions own = EntryStageOptions(options, entry, command_line);
  CHECK(own.log_analysis.fit_delay_s == 0.01);
  CHECK(options.log_analysis.fit_delay_s == LogAnalysisOptions{}.fit_delay_s);
  // The command line has the last word, over an entry's own too.
  CHECK(own.digitize.traces.method == SubpixelMethod::kParabola);
}

TEST_CASE("stage_options: command-line values read as TOML, bare words as text") {
  CHECK(ParseSettingText("7") == SettingValue(7LL));
  CHECK(ParseSettingText("0.25") == SettingValue(0.25));
  CHECK(ParseSettingText("1e-9") == SettingValue(1e-9));
  CHECK(ParseSettingText("true") == SettingValue(true));
  CHECK(ParseSettingText("gaussian") == SettingValue(std::string("gaussian")));
  CHECK(ParseSettingText("\"auto\"") == SettingValue(std::string("auto")));
  const StageSettings bad = CommandLineSettings({{"digitize.graticule.polarity", "dark"}});
  try {
    SessionStageOptions({}, Session{}, bad);
    FAIL("accepted");
  } catch (const InputError& error) {
    CHECK_THAT(std::string(error.what()), Catch::Contains("--digitize.graticule.polarity") &&
                                              Catch::Contains("auto, bright_traces, dark_traces"));
  }
}

}  // namespace impactlab

namespace impactlab {

TEST_CASE("stage_options: docs/settings.md lists every setting as the program does") {
  std::ifstream file(std::string(IMPACTLAB_SOURCE_DIR) + "/docs/settings.md");
  REQUIRE(file);
  std::stringstream text;
  text << file.rdbuf();
  // Regenerate with: build/cli/impactlab settings (below the doc's introduction).
  CHECK_THAT(text.str(), Catch::EndsWith(SettingsTable()));
}

}  // namespace impactlab
