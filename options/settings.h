// A stage's settings, listed once.
//
// Each options struct that users may set lists its settings in a static
// member template, in the order and with the names the manifest uses:
//
//   template <typename Self, typename Visit>
//   static void VisitSettings(Self& self, Visit&& visit) {
//     visit("max_order", self.max_order, "highest polynomial order tried");
//     visit("limits", self.limits, "");  // a nested options struct: its own list
//   }
//
// That one list drives everything a setting needs: the manifest's tables
// ([digitize], per-run overrides), the command line's flags, the run
// fingerprint (a changed setting re-measures the runs it touches) and the
// attributes written beside every result, which read back into options.
// Fields that are inputs rather than settings (a mass, a manual hint) are
// simply not listed.
#pragma once

#include <array>
#include <charconv>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>

namespace impactlab {

// A setting's value as a manifest, a command line or a results file gives it.
using SettingValue = std::variant<bool, long long, double, std::string>;

// Settings by dotted key relative to the options they apply to, e.g.
// "traces.method" for a DigitizeOptions.
using SettingValues = std::map<std::string, SettingValue>;

// The words of an enum setting: an options header declares, next to the enum,
//   constexpr std::array<SettingName<Polarity>, 3> SettingNames(Polarity) {...}
// found by argument-dependent lookup.
template <typename Enum>
struct SettingName {
  Enum value;
  std::string_view name;
};

namespace settings_detail {

struct AnyVisit {
  template <typename Field>
  void operator()(const char*, Field&, const char*) const {}
};

}  // namespace settings_detail

// An options struct with a list of its settings.
template <typename T>
concept HasSettings = requires(T& options) {
  std::remove_const_t<T>::VisitSettings(options, settings_detail::AnyVisit{});
};

template <typename T>
concept EnumSetting = std::is_enum_v<T> && requires(T value) {
  SettingNames(value);
};

// Calls leaf(key, field, help) for every setting of `options`, nested ones
// included, with the dotted key below `prefix`.
template <typename Options, typename Leaf>
requires HasSettings<Options>
void ForEachSetting(Options& options, Leaf&& leaf, const std::string& prefix = {}) {
  std::remove_const_t<Options>::VisitSettings(
      options, [&](const char* name, auto& field, const char* help) {
        const std::string key = prefix.empty() ? std::string(name) : prefix + "." + name;
        if constexpr (HasSettings<std::remove_reference_t<decltype(field)>>) {
          ForEachSetting(field, leaf, key);
        } else {
          leaf(key, field, help);
        }
      });
}

// The kind of value a setting takes, in words: for help texts and errors.
template <typename Field>
std::string SettingKind() {
  if constexpr (std::is_same_v<Field, bool>) {
    return "true or false";
  } else if constexpr (EnumSetting<Field>) {
    std::string words;
    for (const auto& [value, name] : SettingNames(Field{})) {
      words += (words.empty() ? "" : ", ") + std::string(name);
    }
    return "one of " + words;
  } else if constexpr (std::is_integral_v<Field> && std::is_unsigned_v<Field>) {
    return "a whole number >= 0";
  } else if constexpr (std::is_integral_v<Field>) {
    return "a whole number";
  } else {
    static_assert(std::is_floating_point_v<Field>, "a setting is a bool, number or enum");
    return "a number";
  }
}

// The value of a field as a setting (enums as their word).
template <typename Field>
SettingValue ToSettingValue(const Field& field) {
  if constexpr (std::is_same_v<Field, bool>) {
    return field;
  } else if constexpr (EnumSetting<Field>) {
    for (const auto& [value, name] : SettingNames(field)) {
      if (value == field) return std::string(name);
    }
    return std::string("?");
  } else if constexpr (std::is_integral_v<Field>) {
    return static_cast<long long>(field);
  } else {
    return static_cast<double>(field);
  }
}

// Sets `field` from `value`; false with `why` when the value is of the wrong
// kind or out of the field type's range. (Whether it is sensible is the
// options' Check.)
template <typename Field>
bool AssignSetting(Field& field, const SettingValue& value, std::string* why) {
  const auto wrong = [&] {
    *why = "expected " + SettingKind<Field>();
    return false;
  };
  if constexpr (std::is_same_v<Field, bool>) {
    if (!std::holds_alternative<bool>(value)) return wrong();
    field = std::get<bool>(value);
  } else if constexpr (EnumSetting<Field>) {
    if (!std::holds_alternative<std::string>(value)) return wrong();
    for (const auto& [option, name] : SettingNames(field)) {
      if (name == std::get<std::string>(value)) {
        field = option;
        return true;
      }
    }
    *why = "expected " + SettingKind<Field>() + ", found \"" + std::get<std::string>(value) + "\"";
    return false;
  } else if constexpr (std::is_integral_v<Field>) {
    long long whole = 0;
    if (const auto* integer = std::get_if<long long>(&value)) {
      whole = *integer;
    } else if (const auto* number = std::get_if<double>(&value);
               number != nullptr && std::isfinite(*number) && std::trunc(*number) == *number &&
               std::abs(*number) < 9e15) {
      whole = static_cast<long long>(*number);  // 2.0 from a file that stores numbers as reals
    } else {
      return wrong();
    }
    if (!std::in_range<Field>(whole)) return wrong();
    field = static_cast<Field>(whole);
  } else {
    if (const auto* integer = std::get_if<long long>(&value)) {
      field = static_cast<Field>(*integer);
    } else if (const auto* number = std::get_if<double>(&value)) {
      field = static_cast<Field>(*number);
    } else {
      return wrong();
    }
  }
  return true;
}

// A value as session.toml's bare form or the command line writes it:
// `gaussian`, `0.15` (the shortest text that reads back to the same double),
// `true`.
inline std::string SettingText(const SettingValue& value) {
  if (const auto* flag = std::get_if<bool>(&value)) return *flag ? "true" : "false";
  if (const auto* text = std::get_if<std::string>(&value)) return *text;
  if (const auto* integer = std::get_if<long long>(&value)) return std::to_string(*integer);
  const double number = std::get<double>(value);
  std::array<char, 32> buffer{};
  const auto end = std::to_chars(buffer.data(), buffer.data() + buffer.size(), number).ptr;
  std::string text(buffer.data(), end);
  // A whole double keeps a point, so that it reads back as a number of its kind.
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

// Every setting of `options` by dotted key.
template <typename Options>
requires HasSettings<Options> SettingValues SettingsOf(const Options& options) {
  SettingValues out;
  ForEachSetting(options, [&](const std::string& key, const auto& field, const char*) {
    out.emplace(key, ToSettingValue(field));
  });
  return out;
}

// A setting that could not be applied: its key and why.
struct SettingProblem {
  std::string key;
  std::string problem;
};

// Applies one setting by its dotted key; the problem when no setting has that
// key or the value does not fit it.
template <typename Options>
requires HasSettings<Options> std::optional<SettingProblem> ApplySetting(
    Options& options, const std::string& key, const SettingValue& value) {
  bool found = false;
  std::string why;
  ForEachSetting(options, [&](const std::string& name, auto& field, const char*) {
    if (name != key || found) return;
    found = true;
    if (!AssignSetting(field, value, &why) && why.empty()) why = "cannot be set";
  });
  if (!found) return SettingProblem{key, "no such setting"};
  if (!why.empty()) return SettingProblem{key, why};
  return std::nullopt;
}

// The dotted keys of every setting, for a "did you mean" list.
template <typename Options>
requires HasSettings<Options> std::string SettingKeys(const Options& options,
                                                      std::string_view below = {}) {
  std::string keys;
  ForEachSetting(options, [&](const std::string& key, const auto&, const char*) {
    if (!below.empty() && key.rfind(std::string(below) + ".", 0) != 0) return;
    keys += (keys.empty() ? "" : ", ") + key;
  });
  return keys;
}

}  // namespace impactlab
