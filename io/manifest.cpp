// Reading and validating a session manifest (format 1, docs/manifest.md).
//
// The manifest is the user's only way to tell the reducer about an experiment,
// so every mistake in it must be reported where the user can find it: the file,
// the key (as a readable dotted path such as `run "0.234".traces.right.volts_per_div`),
// the line, and what was expected next to what was found. All of that is done by
// TableReader below; the Read* functions only say which keys a table has and
// what each one must be.
//
// Key paths name an element of an array of tables by its id when it has one
// (`run "0.234"`), otherwise by its 1-based position (`prediction #2`); an
// element of a plain array by its 0-based index (`band_div[1]`, `rebounds[3]`,
// which is also the rebound's number).

#include "io/manifest.h"

#include "io/session_file.h"
#include "io/spelling.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <string_view>
#include <utility>

namespace impactlab {
namespace {

namespace fs = std::filesystem;

constexpr long long kMaxInt = std::numeric_limits<int>::max();
// A manifest is typed by hand: a few kB. Anything near this is not one.
constexpr std::uintmax_t kMaxManifestBytes = 16u << 20;

// ---------------------------------------------------------------------------
// Describing values and keys in messages.

// A string as the user would write it in TOML: "abc", with quotes and control
// characters escaped, cut short when long so a message stays one line.
std::string Quote(std::string_view text) {
  constexpr std::size_t kMaxShown = 80;
  std::string out = "\"";
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (i == kMaxShown) {
      out += "...";
      break;
    }
    const char c = text[i];
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += fmt::format("\\u{:04X}", static_cast<unsigned>(c));
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// A key as one segment of a dotted path: bare when TOML would allow it bare.
std::string KeySegment(std::string_view key) {
  const bool bare = !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
  return bare ? std::string(key) : Quote(key);
}

std::string JoinKey(std::string_view path, std::string_view key) {
  if (path.empty()) return KeySegment(key);
  return fmt::format("{}.{}", path, KeySegment(key));
}

// Shortest text that reads back as the same double: 0.2, 1e-06, nan, -inf.
std::string FormatNumber(double value) { return fmt::format("{}", value); }

// What a node holds, for "expected X, found Y" when the type is wrong.
std::string Describe(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return "string " + Quote(node.as_string()->get());
    case toml::node_type::integer:
      return fmt::format("integer {}", node.as_integer()->get());
    case toml::node_type::floating_point:
      return "floating-point " + FormatNumber(node.as_floating_point()->get());
    case toml::node_type::boolean:
      return fmt::format("boolean {}", node.as_boolean()->get());
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    default:
      return "nothing";
  }
}

std::string FormatList(const std::vector<double>& values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    out += (i ? ", " : "") + FormatNumber(values[i]);
  }
  return out + "]";
}

// toml++ numbers lines from 1 and uses 0 for "unknown" (e.g. implicit tables).
std::optional<long long> LineOf(const toml::node& node) {
  const auto line = node.source().begin.line;
  if (line == 0) return std::nullopt;
  return static_cast<long long>(line);
}

// "\"right\" or \"left\"", "\"exact\", \"thesis\" or \"x\"".
std::string ChoiceList(std::initializer_list<std::string_view> choices) {
  std::string out;
  std::size_t i = 0;
  for (std::string_view choice : choices) {
    if (i > 0) out += (i + 1 == choices.size()) ? " or " : ", ";
    out += Quote(choice);
    ++i;
  }
  return out;
}

// ---------------------------------------------------------------------------
// Paths inside the session folder.

// The folder as the operating system sees it (symbolic links resolved), to tell
// whether a manifest path leads outside it.
fs::path CanonicalFolder(const fs::path& folder) {
  std::error_code error;
  fs::path canonical = fs::canonical(folder, error);
  if (error) canonical = fs::weakly_canonical(fs::absolute(folder), error).lexically_normal();
  // A trailing separator would leave an empty last component that no file path shares.
  if (canonical.has_relative_path() && canonical.filename().empty()) {
    canonical = canonical.parent_path();
  }
  return canonical;
}

// ---------------------------------------------------------------------------
// TableReader: one TOML table, where it is, and typed access with good messages.

// What the whole manifest read shares: where it is, and where warnings go.
struct Context {
  fs::path manifest;
  fs::path folder;
  fs::path canonical_folder;
  std::vector<ManifestWarning>* warnings = nullptr;
};

enum class Sign { kAny, kPositive };

// What a number must be, and how to say so: {kPositive, "a positive number of V/div"}.
struct NumberRule {
  Sign sign;
  std::string_view what;
};

// What an integer must be: {1, kMaxInt, "an impact number >= 1"}.
struct IntegerRule {
  long long min;
  long long max;
  std::string_view what;
};

class TableReader {
 public:
  // `path` is the dotted key of the table ("" for the whole file); `line` is the
  // line reported for problems with the table as a whole (e.g. a missing key).
  TableReader(const Context& context, const toml::table& table, std::string path,
              std::optional<long long> line)
      : context_(&context), table_(&table), path_(std::move(path)), line_(line) {}

  const Context& context() const { return *context_; }
  const std::string& path() const { return path_; }
  std::optional<long long> line() const { return line_; }
  const toml::table& table() const { return *table_; }

  std::string KeyPath(std::string_view key) const { return JoinKey(path_, key); }
  const toml::node* Find(std::string_view key) const { return table_->get(key); }
  bool Has(std::string_view key) const { return Find(key) != nullptr; }

  // A problem with the table as a whole (keys that contradict each other, a
  // missing table entry): points at the table's header.
  [[noreturn]] void FailTable(const std::string& problem) const {
    throw InputError(InputLocation{context_->manifest, path_, line_}, problem);
  }

  // A problem with one key: points at its value, or at the table when missing.
  [[noreturn]] void Fail(std::string_view key, const std::string& problem) const {
    const toml::node* node = Find(key);
    std::optional<long long> line = node ? LineOf(*node) : std::nullopt;
    throw InputError(InputLocation{context_->manifest, KeyPath(key), line ? line : line_}, problem);
  }

  // A problem with a value below this table (an array element) with its own path.
  [[noreturn]] void FailAt(const toml::node& node, const std::string& key_path,
                           const std::string& problem) const {
    std::optional<long long> line = LineOf(node);
    throw InputError(InputLocation{context_->manifest, key_path, line ? line : line_}, problem);
  }

  [[noreturn]] void Missing(std::string_view key, std::string_view what) const {
    Fail(key, fmt::format("required key is missing; expected {}{}", what, NearMiss(key)));
  }

  // The table's unknown keys that look like a typo of `key`, said beside a
  // message about it: "; the table has `initial_displacment`: a typo?".
  std::string NearMiss(std::string_view key) const {
    std::vector<std::string> typos;
    for (const std::string& unknown : UnknownKeys()) {
      if (NearestWord(unknown, {std::string(key)})) typos.push_back("`" + unknown + "`");
    }
    if (typos.empty()) return {};
    return fmt::format("; the table has {}: a typo?", fmt::join(typos, " and "));
  }

  // The table's unknown keys, each with the known key it is nearest to:
  // "; `rebounds_` is not a key (did you mean \"rebounds\"?)". Said with a
  // problem of the table as a whole that a mistyped key may explain.
  std::string UnknownKeysNote() const {
    std::string note;
    for (const std::string& unknown : UnknownKeys()) {
      if (const std::string hint = DidYouMean(unknown, known_); !hint.empty()) {
        note += fmt::format("; `{}` is not a key{}", unknown, hint);
      }
    }
    return note;
  }

  void Warn(std::string_view key, const std::string& message) const {
    const toml::node* node = Find(key);
    std::optional<long long> line = node ? LineOf(*node) : std::nullopt;
    context_->warnings->push_back(ManifestWarning{
        InputLocation{context_->manifest, KeyPath(key), line ? line : line_}, message});
  }

  // Keys this table may have; any other key is most likely a typing mistake, so
  // the user hears about it, but a newer manifest still reads.
  void WarnUnknownKeys(std::initializer_list<std::string_view> known) const {
    known_.assign(known.begin(), known.end());
    for (const std::string& name : UnknownKeys()) {
      Warn(name, fmt::format("unknown key '{}' (ignored){}", name, DidYouMean(name, known_)));
    }
  }

  // The keys the table has that WarnUnknownKeys was not told of.
  std::vector<std::string> UnknownKeys() const {
    std::vector<std::string> unknown;
    if (known_.empty()) return unknown;
    for (const auto& [key, node] : *table_) {
      const std::string name(key.str());
      if (std::find(known_.begin(), known_.end(), name) == known_.end()) unknown.push_back(name);
    }
    return unknown;
  }

  std::optional<double> Number(std::string_view key, NumberRule rule) const {
    const toml::node* node = Find(key);
    if (!node) return std::nullopt;
    return NumberFrom(*node, KeyPath(key), rule);
  }

  double RequiredNumber(std::string_view key, NumberRule rule) const {
    if (!Has(key)) Missing(key, rule.what);
    return *Number(key, rule);
  }

  std::optional<long long> Integer(std::string_view key, IntegerRule rule) const {
    const toml::node* node = Find(key);
    if (!node) return std::nullopt;
    return IntegerFrom(*node, KeyPath(key), rule);
  }

  // A non-empty string.
  std::optional<std::string> String(std::string_view key, std::string_view what) const {
    const toml::node* node = Find(key);
    if (!node) return std::nullopt;
    const auto* text = node->as_string();
    if (!text) Fail(key, fmt::format("expected {}, found {}", what, Describe(*node)));
    if (text->get().empty()) Fail(key, fmt::format("expected {}, found an empty string", what));
    return text->get();
  }

  std::string RequiredString(std::string_view key, std::string_view what) const {
    if (!Has(key)) Missing(key, what);
    return *String(key, what);
  }

  // One of a few fixed words.
  std::optional<std::string> Choice(std::string_view key,
                                    std::initializer_list<std::string_view> choices) const {
    const std::string what = ChoiceList(choices);
    const toml::node* node = Find(key);
    if (!node) return std::nullopt;
    const auto* text = node->as_string();
    if (!text) Fail(key, fmt::format("expected {}, found {}", what, Describe(*node)));
    if (std::find(choices.begin(), choices.end(), text->get()) == choices.end()) {
      Fail(key, fmt::format("expected {}, found {}", what, Quote(text->get())));
    }
    return text->get();
  }

  // An array of numbers; `what` describes the whole array, `element` each number.
  // `count`, when given, is the exact length required.
  std::optional<std::vector<double>> Numbers(std::string_view key, std::string_view what,
                                             NumberRule element,
                                             std::optional<std::size_t> count) const {
    const toml::array* array = Array(key, what, count);
    if (!array) return std::nullopt;
    std::vector<double> values;
    for (std::size_t i = 0; i < array->size(); ++i) {
      values.push_back(NumberFrom(*array->get(i), fmt::format("{}[{}]", KeyPath(key), i), element));
    }
    return values;
  }

  std::optional<std::vector<long long>> Integers(std::string_view key, std::string_view what,
                                                 IntegerRule element,
                                                 std::optional<std::size_t> count) const {
    const toml::array* array = Array(key, what, count);
    if (!array) return std::nullopt;
    std::vector<long long> values;
    for (std::size_t i = 0; i < array->size(); ++i) {
      values.push_back(
          IntegerFrom(*array->get(i), fmt::format("{}[{}]", KeyPath(key), i), element));
    }
    return values;
  }

  // An array of photo pixels [[x, y], ...] (a manual hint), `min`..`max` of
  // them. Each coordinate is finite and not left of or above the photo's
  // first pixel; whether it lies inside the photo is checked where its size
  // is known (digitize/).
  std::optional<std::vector<std::array<double, 2>>> PixelPoints(std::string_view key,
                                                                std::string_view what,
                                                                std::size_t min,
                                                                std::size_t max) const {
    const toml::array* array = Array(key, what, std::nullopt);
    if (!array) return std::nullopt;
    if (array->size() < min || array->size() > max) {
      Fail(key, fmt::format("expected {}, found an array of {} values", what, array->size()));
    }
    constexpr NumberRule kCoordinate{Sign::kAny,
                                     "a pixel coordinate >= 0 (pixel centres are whole "
                                     "numbers)"};
    std::vector<std::array<double, 2>> points;
    for (std::size_t i = 0; i < array->size(); ++i) {
      const toml::node& element = *array->get(i);
      const std::string element_path = fmt::format("{}[{}]", KeyPath(key), i);
      const toml::array* pair = element.as_array();
      if (!pair || pair->size() != 2) {
        FailAt(element, element_path,
               fmt::format(
                   "expected a pixel [x, y], found {}",
                   pair ? fmt::format("an array of {} values", pair->size()) : Describe(element)));
      }
      std::array<double, 2> point{};
      for (std::size_t k = 0; k < 2; ++k) {
        const std::string coordinate_path = fmt::format("{}[{}]", element_path, k);
        point[k] = NumberFrom(*pair->get(k), coordinate_path, kCoordinate);
        // -0.5 is the first pixel's outer edge.
        if (point[k] < -0.5) {
          FailAt(*pair->get(k), coordinate_path,
                 fmt::format("expected {}, found {}", kCoordinate.what, FormatNumber(point[k])));
        }
      }
      points.push_back(point);
    }
    return points;
  }

  // A sub-table (a [header] table or an inline { } table).
  std::optional<TableReader> Table(std::string_view key) const {
    const toml::node* node = Find(key);
    if (!node) return std::nullopt;
    const toml::table* table = node->as_table();
    if (!table) Fail(key, fmt::format("expected a table, found {}", Describe(*node)));
    const std::optional<long long> line = LineOf(*node);
    return TableReader(*context_, *table, KeyPath(key), line ? line : line_);
  }

  // A sub-table, or an empty one standing in for it when absent (so its keys
  // can all come from defaults and missing ones are reported at this table).
  TableReader TableOrEmpty(std::string_view key) const {
    static const toml::table kEmpty;
    if (auto table = Table(key)) return *table;
    return TableReader(*context_, kEmpty, KeyPath(key), line_);
  }

  // [[name]] tables. Each element's path names it by its `id` when it has a
  // string one, else by its 1-based position.
  std::vector<TableReader> ArrayOfTables(std::string_view key) const {
    const toml::node* node = Find(key);
    if (!node) return {};
    const toml::array* array = node->as_array();
    const bool all_tables =
        array && std::all_of(array->begin(), array->end(),
                             [](const toml::node& element) { return element.is_table(); });
    if (!all_tables) {
      const std::string found =
          node->is_table() ? fmt::format("a single [{}] table", key) : Describe(*node);
      Fail(key, fmt::format("expected [[{}]] tables (an array of tables), found {}", key, found));
    }
    std::vector<TableReader> tables;
    for (std::size_t i = 0; i < array->size(); ++i) {
      const toml::table& table = *array->get(i)->as_table();
      std::string label = fmt::format("{} #{}", KeySegment(key), i + 1);
      if (const auto* id = table.get("id");
          id && id->is_string() && !id->as_string()->get().empty()) {
        label = fmt::format("{} {}", KeySegment(key), Quote(id->as_string()->get()));
      }
      if (!path_.empty()) label = fmt::format("{}.{}", path_, label);
      const std::optional<long long> line = LineOf(table);
      tables.emplace_back(*context_, table, std::move(label), line ? line : line_);
    }
    return tables;
  }

  // A file named relative to the session folder: checked to stay inside it and
  // to exist, and returned resolved (folder / path).
  std::optional<fs::path> Path(std::string_view key) const {
    constexpr std::string_view kWhat = "a file path relative to the session folder";
    const std::optional<std::string> text = String(key, kWhat);
    if (!text) return std::nullopt;
    return ResolveInsideFolder(key, *text);
  }

  fs::path RequiredPath(std::string_view key) const {
    if (!Has(key)) Missing(key, "a file path relative to the session folder");
    return *Path(key);
  }

 private:
  double NumberFrom(const toml::node& node, const std::string& key_path, NumberRule rule) const {
    double value = 0.0;
    if (const auto* floating = node.as_floating_point()) {
      value = floating->get();
    } else if (const auto* integer = node.as_integer()) {
      value = static_cast<double>(integer->get());
    } else {
      FailAt(node, key_path, fmt::format("expected {}, found {}", rule.what, Describe(node)));
    }
    // nan and inf are valid TOML, but never a measurement.
    if (!std::isfinite(value)) {
      FailAt(node, key_path,
             fmt::format("expected {}, found {}, which is not a finite number", rule.what,
                         FormatNumber(value)));
    }
    const bool in_range = rule.sign == Sign::kAny || (rule.sign == Sign::kPositive && value > 0.0);
    if (!in_range) {
      FailAt(node, key_path, fmt::format("expected {}, found {}", rule.what, FormatNumber(value)));
    }
    return value;
  }

  long long IntegerFrom(const toml::node& node, const std::string& key_path,
                        IntegerRule rule) const {
    const auto* integer = node.as_integer();
    if (!integer) {
      FailAt(node, key_path, fmt::format("expected {}, found {}", rule.what, Describe(node)));
    }
    const long long value = integer->get();
    if (value < rule.min || value > rule.max) {
      FailAt(node, key_path, fmt::format("expected {}, found {}", rule.what, value));
    }
    return value;
  }

  const toml::array* Array(std::string_view key, std::string_view what,
                           std::optional<std::size_t> count) const {
    const toml::node* node = Find(key);
    if (!node) return nullptr;
    const toml::array* array = node->as_array();
    if (!array) Fail(key, fmt::format("expected {}, found {}", what, Describe(*node)));
    if (count && array->size() != *count) {
      Fail(key, fmt::format("expected {}, found an array of {} values", what, array->size()));
    }
    if (!count && array->empty()) Fail(key, fmt::format("expected {}, found an empty array", what));
    return array;
  }

  // The manifest must not make the reducer read files outside the session: an
  // absolute path, "..", or a symbolic link pointing out are all refused.
  fs::path ResolveInsideFolder(std::string_view key, const std::string& text) const {
    const fs::path relative(text);
    if (relative.has_root_directory() || relative.has_root_name()) {
      Fail(key, fmt::format("expected a path relative to the session folder, found the absolute "
                            "path {}",
                            Quote(text)));
    }
    for (const fs::path& part : relative) {
      if (part == "..") {
        Fail(key, fmt::format("expected a path inside the session folder, found {}, which "
                              "uses '..'",
                              Quote(text)));
      }
    }
    const fs::path resolved = (context_->folder / relative).lexically_normal();
    std::error_code error;
    // Made absolute first: of a relative path of which nothing exists,
    // weakly_canonical would return the path itself, still relative.
    const fs::path canonical = fs::weakly_canonical(fs::absolute(resolved), error);
    if (error) {
      Fail(key, fmt::format("expected a readable file, found {} ({}: {})", Quote(text),
                            resolved.string(), error.message()));
    }
    if (!IsInsideFolder(canonical, context_->canonical_folder)) {
      Fail(key, fmt::format("expected a path inside the session folder, found {}, which leads "
                            "outside it through a symbolic link (to {})",
                            Quote(text), canonical.string()));
    }
    const fs::file_status status = fs::status(resolved, error);
    if (!fs::exists(status)) {
      Fail(key, fmt::format("expected an existing file, found no file at {} (looked for {})",
                            Quote(text), resolved.string()));
    }
    if (fs::is_directory(status)) {
      Fail(key, fmt::format("expected a file, found a folder at {}", Quote(text)));
    }
    if (!fs::is_regular_file(status)) {
      // A named pipe would block the reducer in open(); a device never ends.
      Fail(key,
           fmt::format("expected a regular file, found {} at {}",
                       fs::is_fifo(status) ? "a named pipe" : "a special file (device or socket)",
                       Quote(text)));
    }
    return resolved;
  }

  const Context* context_;
  const toml::table* table_;
  std::string path_;
  std::optional<long long> line_;
  // The keys it may have, once WarnUnknownKeys has been told them.
  mutable std::vector<std::string> known_;
};

// ---------------------------------------------------------------------------
// The manifest's tables.

// Screen settings a trace may give itself or take from [scope].
struct ScreenSettings {
  std::optional<double> time_per_div;
  std::optional<double> volts_per_div;
  std::optional<double> zero_div;
  std::optional<std::array<double, 2>> band_div;
  std::optional<double> t0_div;
  std::optional<int> impact;  // contact traces only
};

struct Scope {
  std::array<int, 2> divisions = {10, 8};
  ScreenSettings defaults;
};

enum class TraceKind { kCalibration, kDisplacement, kContact };

constexpr std::array<std::string_view, 5> kScreenKeys = {"time_per_div", "volts_per_div",
                                                         "zero_div", "band_div", "t0_div"};

std::optional<std::array<double, 2>> ReadBand(const TableReader& table) {
  constexpr std::string_view kWhat = "[lo, hi] in divisions from the graticule centre";
  auto band = table.Numbers("band_div", kWhat, {Sign::kAny, "a number of divisions"}, 2);
  if (!band) return std::nullopt;
  if (!((*band)[0] < (*band)[1])) {
    table.Fail("band_div",
               fmt::format("expected {} with lo < hi, found {}", kWhat, FormatList(*band)));
  }
  return std::array<double, 2>{(*band)[0], (*band)[1]};
}

// The same code reads [scope] and every trace table, so a bad value reads the
// same wherever it is.
ScreenSettings ReadScreenSettings(const TableReader& table, bool with_impact) {
  ScreenSettings settings;
  settings.time_per_div =
      table.Number("time_per_div", {Sign::kPositive, "a positive number of s/div"});
  settings.volts_per_div =
      table.Number("volts_per_div", {Sign::kPositive, "a positive number of V/div"});
  settings.zero_div = table.Number("zero_div", {Sign::kAny, "a number of divisions"});
  settings.band_div = ReadBand(table);
  settings.t0_div = table.Number("t0_div", {Sign::kAny, "a number of divisions"});
  if (with_impact) {
    if (auto impact = table.Integer("impact", {1, kMaxInt, "an impact number >= 1"})) {
      settings.impact = static_cast<int>(*impact);
    }
  }
  return settings;
}

Scope ReadScope(const TableReader& table) {
  std::vector<std::string_view> known(kScreenKeys.begin(), kScreenKeys.end());
  known.push_back("divisions");
  known.push_back("impact");
  for (const auto& [key, node] : table.table()) {
    const std::string_view name = key.str();
    if (name == "csv") {
      table.Warn(name,
                 "'csv' names one trace's file and cannot be a default for every trace "
                 "(ignored)");
    } else if (std::find(known.begin(), known.end(), name) == known.end()) {
      table.Warn(name, fmt::format("unknown key '{}' (ignored)", name));
    }
  }
  Scope scope;
  if (auto divisions = table.Integers("divisions", "[horizontal, vertical] graticule divisions",
                                      {1, 1000, "a positive whole number of divisions"}, 2)) {
    scope.divisions = {static_cast<int>((*divisions)[0]), static_cast<int>((*divisions)[1])};
  }
  scope.defaults = ReadScreenSettings(table, /*with_impact=*/true);
  return scope;
}

// Manual hint: photo pixels a trace passes through, for the tracking to
// follow where it alone strays (a scratch along the trace, a faint stretch).
constexpr std::size_t kMaxTracePoints = 1000;

void ReadTracePoints(const TableReader& table, TraceSettings& trace) {
  const std::string what =
      fmt::format("2 to {} photo pixels [[x, y], ...] the trace passes through", kMaxTracePoints);
  auto points = table.PixelPoints("points", what, 2, kMaxTracePoints);
  if (!points) return;
  if (trace.csv) {
    table.Warn("points", "'points' applies only to a trace read from the photo (ignored)");
    return;
  }
  for (std::size_t i = 0; i < points->size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if ((*points)[i] == (*points)[j]) {
        table.Fail("points", fmt::format("expected {}, found the pixel [{}, {}] twice ([{}] and "
                                         "[{}])",
                                         what, FormatNumber((*points)[i][0]),
                                         FormatNumber((*points)[i][1]), j, i));
      }
    }
  }
  trace.points_px = std::move(*points);
}

// One trace table. A trace is read either from the owner's photo or from its
// own `csv`; only a photo trace needs the screen scales.
TraceSettings ReadTrace(const TableReader& table, TraceKind kind, const Scope& scope,
                        bool owner_has_photo) {
  const bool contact = kind == TraceKind::kContact;
  for (const auto& [key, node] : table.table()) {
    const std::string_view name = key.str();
    const bool known = name == "csv" || name == "points" || (contact && name == "impact") ||
                       std::find(kScreenKeys.begin(), kScreenKeys.end(), name) != kScreenKeys.end();
    if (name == "impact" && !contact) {
      table.Warn(name, "'impact' applies only to contact traces (ignored)");
    } else if (!known) {
      table.Warn(name, fmt::format("unknown key '{}' (ignored)", name));
    }
  }

  const ScreenSettings own = ReadScreenSettings(table, contact);
  const ScreenSettings& defaults = scope.defaults;
  TraceSettings trace;
  trace.csv = table.Path("csv");
  if (!trace.csv && !owner_has_photo) {
    const std::string_view owner = kind == TraceKind::kCalibration ? "calibration" : "run";
    table.FailTable(
        fmt::format("expected `csv` in this trace or a `photo` in the {}, found neither (a trace "
                    "without a CSV file is read from the photo)",
                    owner));
  }

  // A photo trace cannot be read without its scales; a CSV trace already has
  // seconds and volts.
  const auto required = [&](std::string_view key, std::optional<double> value,
                            std::string_view what) {
    if (!value && !trace.csv) {
      table.Missing(key, fmt::format("{} (give it here or in [scope])", what));
    }
    return value.value_or(0.0);
  };
  trace.time_per_div =
      required("time_per_div", own.time_per_div ? own.time_per_div : defaults.time_per_div,
               "a positive number of s/div");
  trace.volts_per_div =
      required("volts_per_div", own.volts_per_div ? own.volts_per_div : defaults.volts_per_div,
               "a positive number of V/div");
  trace.zero_div = own.zero_div.value_or(defaults.zero_div.value_or(0.0));
  // Without a band the trace may be anywhere on the screen.
  const double half_height = scope.divisions[1] / 2.0;
  trace.band_div = own.band_div.value_or(
      defaults.band_div.value_or(std::array<double, 2>{-half_height, half_height}));
  trace.t0_div = own.t0_div.value_or(defaults.t0_div.value_or(0.0));
  if (contact) trace.impact = own.impact ? own.impact : defaults.impact;
  ReadTracePoints(table, trace);
  return trace;
}

// Plausible ranges of the apparatus. They catch a number in the wrong units
// (gravity 9.81 in an in-lbf-s session) or mistyped by orders of magnitude,
// which would otherwise reduce to absurd results without a word.
constexpr double kGravityTolerance = 0.05;  // gravity within 5 % of standard (Earth: +-0.3 %)
constexpr double kMinLengthMetres = 0.01, kMaxLengthMetres = 100.0;
constexpr double kMinReleaseFraction = 1e-6;  // X0 / L

double MetresPerLengthUnit(UnitSystem units) { return units == UnitSystem::kSI ? 1.0 : 0.0254; }

void CheckPlausible(const TableReader& table, const Apparatus& apparatus, UnitSystem units) {
  const UnitLabels labels = LabelsFor(units);
  const double standard = StandardGravity(units);
  if (std::abs(apparatus.gravity / standard - 1.0) > kGravityTolerance) {
    table.Fail("gravity",
               fmt::format("expected the acceleration of gravity in {}, within {:g} % of the "
                           "standard {} {}, found {}",
                           labels.acceleration, 100.0 * kGravityTolerance, FormatNumber(standard),
                           labels.acceleration, FormatNumber(apparatus.gravity)));
  }
  const double scale = MetresPerLengthUnit(units);
  const double metres = apparatus.pendulum_length * scale;
  if (!(metres >= kMinLengthMetres && metres <= kMaxLengthMetres)) {
    table.Fail("pendulum_length",
               fmt::format("expected a pendulum length between {:g} and {:g} {} (1 cm to 100 m), "
                           "found {}",
                           kMinLengthMetres / scale, kMaxLengthMetres / scale, labels.length,
                           FormatNumber(apparatus.pendulum_length)));
  }
}

Apparatus ReadApparatus(const TableReader& table, UnitSystem units) {
  table.WarnUnknownKeys({"pendulum_length", "weight", "mass", "gravity", "arrangement"});
  const UnitLabels labels = LabelsFor(units);
  Apparatus apparatus;
  apparatus.pendulum_length = table.RequiredNumber(
      "pendulum_length", {Sign::kPositive, fmt::format("a positive length ({})", labels.length)});
  const std::string gravity_what = fmt::format("a positive acceleration ({})", labels.acceleration);
  apparatus.gravity =
      table.Number("gravity", {Sign::kPositive, gravity_what}).value_or(StandardGravity(units));

  const std::string weight_what = fmt::format("a positive weight ({})", labels.force);
  const std::string mass_what = fmt::format("a positive mass ({})", labels.mass);
  const std::optional<double> weight = table.Number("weight", {Sign::kPositive, weight_what});
  const std::optional<double> mass = table.Number("mass", {Sign::kPositive, mass_what});
  if (weight && mass) {
    table.Fail("mass", "expected either `weight` or `mass` of one pendulum, found both");
  }
  if (!weight && !mass) {
    table.FailTable(fmt::format(
        "required key is missing; expected `weight` ({}) or `mass` ({}) of one pendulum",
        labels.force, labels.mass));
  }
  apparatus.mass = mass ? *mass : *weight / apparatus.gravity;

  // The thesis's pendulum formulas are for two identical penduli meeting
  // half way; against a rigid stop the relative motion, the effective mass and
  // the calibration swing all differ, and nothing here models them yet.
  const std::string arrangement = table.Choice("arrangement", {"pair", "wall"}).value_or("pair");
  if (arrangement == "wall") {
    table.Fail("arrangement",
               "expected \"pair\" (two identical penduli), found \"wall\": one pendulum against a "
               "rigid stop is not supported yet, and reducing it as a pair would be wrong");
  }
  apparatus.arrangement = Arrangement::kPair;
  CheckPlausible(table, apparatus, units);
  return apparatus;
}

// A release displacement X0: positive, and shorter than the pendulum, since
// X = L sin(theta) (a longer one is no swing at all); not so small against
// L that the pendulum formulas lose their digits.
double ReadReleaseDisplacement(const TableReader& table, UnitSystem units,
                               const std::optional<Apparatus>& apparatus) {
  const std::string length = LabelsFor(units).length;
  const std::string_view key = "initial_displacement";
  const double x0 = table.RequiredNumber(
      key, {Sign::kPositive, fmt::format("a positive displacement X0 ({})", length)});
  if (!apparatus) return x0;
  const double l = apparatus->pendulum_length;
  if (!(x0 < l) || !(x0 >= kMinReleaseFraction * l)) {
    table.Fail(key, fmt::format("expected a displacement X0 between {} and {} {} (from {:g} times "
                                "the pendulum length L = {} {} up to L), found {}",
                                FormatNumber(kMinReleaseFraction * l), FormatNumber(l), length,
                                kMinReleaseFraction, FormatNumber(l), length, FormatNumber(x0)));
  }
  return x0;
}

// Ids name groups in the results file, rows of the report and arguments on the
// command line, so they keep to characters that are safe in all three: no
// '/', no "." or "..", no spaces, quotes or markup.
constexpr std::string_view kSafeIdRule =
    "1 to 64 letters, digits and '.', '_', '-', '+', beginning with a letter, a digit or '_'";

bool IsSafeId(std::string_view id) {
  const auto alphanumeric = [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
  };
  if (id.empty() || id.size() > 64 || !(alphanumeric(id.front()) || id.front() == '_')) {
    return false;
  }
  return std::all_of(id.begin(), id.end(), [&](char c) {
    return alphanumeric(c) || c == '.' || c == '_' || c == '-' || c == '+';
  });
}

// Remembers the ids of one kind of table and refuses a second use of one.
class IdRegistry {
 public:
  explicit IdRegistry(std::string_view kind) : kind_(kind) {}

  std::string Read(const TableReader& table) {
    const std::string what = fmt::format("a {} id (a string)", kind_);
    const std::string id = table.RequiredString("id", what);
    if (!IsSafeId(id)) {
      table.Fail("id", fmt::format("expected {} of {}, found {}", what, kSafeIdRule, Quote(id)));
    }
    const std::optional<long long> line = LineOf(*table.Find("id"));
    const auto [it, inserted] = first_line_.emplace(id, line);
    if (!inserted) {
      const std::string where = it->second ? fmt::format(" at line {}", *it->second) : "";
      table.Fail("id", fmt::format("expected an id no other {} has, found {}, already used by "
                                   "the {}{}",
                                   kind_, Quote(id), kind_, where));
    }
    return id;
  }

 private:
  std::string kind_;
  std::map<std::string, std::optional<long long>> first_line_;
};

// Manual hint: the graticule's outer corners in the photo, top-left,
// top-right, bottom-right, bottom-left as seen on the screen. In photo pixels
// (y down) that order goes clockwise round a convex quadrilateral; any other
// order, three corners in a line or a corner inside the others is a typing
// slip that would map the screen mirrored or folded.
constexpr double kMinCornerSidePx = 20.0;  // a graticule smaller than this cannot be read

std::optional<GraticuleCorners> ReadGraticuleCorners(const TableReader& table, bool has_photo) {
  constexpr std::string_view kKey = "graticule_corners";
  constexpr std::string_view kWhat =
      "the graticule's 4 corners in photo pixels [[x, y], ...] in the order top-left, top-right, "
      "bottom-right, bottom-left";
  const auto points = table.PixelPoints(kKey, kWhat, 4, 4);
  if (!points) return std::nullopt;
  if (!has_photo) {
    table.Warn(kKey, "'graticule_corners' applies to a photo, and there is none (ignored)");
    return std::nullopt;
  }
  GraticuleCorners corners{};
  std::copy(points->begin(), points->end(), corners.begin());
  const auto text = [&] {
    std::string out = "[";
    for (std::size_t i = 0; i < 4; ++i) {
      out += fmt::format("{}[{}, {}]", i ? ", " : "", FormatNumber(corners[i][0]),
                         FormatNumber(corners[i][1]));
    }
    return out + "]";
  };
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& a = corners[i];
    const auto& b = corners[(i + 1) % 4];
    const auto& c = corners[(i + 2) % 4];
    const double side = std::hypot(b[0] - a[0], b[1] - a[1]);
    const double next = std::hypot(c[0] - b[0], c[1] - b[1]);
    if (!(side >= kMinCornerSidePx)) {
      table.Fail(kKey, fmt::format("expected {}, each side at least {:g} px long, found {}, whose "
                                   "corners {} and {} are {:.1f} px apart",
                                   kWhat, kMinCornerSidePx, text(), i, (i + 1) % 4, side));
    }
    // Turning clockwise on the photo (y down) at every corner: the cross
    // product of consecutive sides is positive, and clearly so (not three
    // corners nearly in a line: the sine of the turn above about 0.1).
    const double cross = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]);
    if (!(cross > 0.1 * side * next)) {
      table.Fail(
          kKey,
          fmt::format("expected {}, going clockwise round a convex quadrilateral on the "
                      "photo, found {}, which {} at corner {}",
                      kWhat, text(), cross < 0.0 ? "turns the other way" : "is almost straight",
                      (i + 1) % 4));
    }
  }
  return corners;
}

// The settings of one stage table, nested tables as dotted keys below `key`.
void FlattenSettings(const TableReader& table, const std::string& key, StageSettings& settings) {
  for (const auto& [name, node] : table.table()) {
    const std::string below = key + "." + std::string(name.str());
    if (node.is_table()) {
      FlattenSettings(*table.Table(name.str()), below, settings);
      continue;
    }
    SettingValue value;
    if (const auto* flag = node.as_boolean()) {
      value = flag->get();
    } else if (const auto* integer = node.as_integer()) {
      value = static_cast<long long>(integer->get());
    } else if (const auto* number = node.as_floating_point()) {
      value = number->get();
    } else if (const auto* text = node.as_string()) {
      value = text->get();
    } else {
      table.Fail(name.str(), fmt::format("expected a setting (a number, true or false, or a "
                                         "word), found {}",
                                         Describe(node)));
    }
    const std::optional<long long> line = LineOf(node);
    settings[below] = StageSetting{
        std::move(value), InputLocation{table.context().manifest, table.KeyPath(name.str()),
                                        line ? line : table.line()}};
  }
}

// The stage tables `stages` of `table`, by key below the stage tables.
StageSettings ReadSettings(const TableReader& table,
                           std::initializer_list<std::string_view> stages) {
  StageSettings settings;
  for (const std::string_view stage : stages) {
    if (const auto stage_table = table.Table(stage)) {
      FlattenSettings(*stage_table, std::string(stage), settings);
    }
  }
  return settings;
}

Calibration ReadCalibration(const TableReader& table, std::string id, UnitSystem units,
                            const std::optional<Apparatus>& apparatus, const Scope& scope) {
  table.WarnUnknownKeys({"id", "cell", "initial_displacement", "photo", "graticule_corners",
                         "trace", "digitize", "photocell"});
  Calibration calibration;
  calibration.id = std::move(id);
  calibration.settings = ReadSettings(table, {"digitize", "photocell"});
  if (!table.Has("cell")) table.Missing("cell", ChoiceList({"right", "left"}));
  calibration.cell = *table.Choice("cell", {"right", "left"});
  calibration.initial_displacement = ReadReleaseDisplacement(table, units, apparatus);
  calibration.photo = table.Path("photo");
  calibration.graticule_corners_px = ReadGraticuleCorners(table, calibration.photo.has_value());
  calibration.trace = ReadTrace(table.TableOrEmpty("trace"), TraceKind::kCalibration, scope,
                                calibration.photo.has_value());
  return calibration;
}

// calibration = { right = "R-0.234", left = "L-0.234" }: each must name a
// calibration of that very cell, or the displacements would be converted with
// the other photocell's curve.
std::map<std::string, std::string> ReadRunCalibrations(
    const TableReader& run, const std::vector<Calibration>& known,
    const std::map<std::string, std::string>& rejected) {
  std::map<std::string, std::string> result;
  const std::optional<TableReader> table = run.Table("calibration");
  if (!table) return result;
  table->WarnUnknownKeys({"right", "left"});
  for (const std::string_view cell : {"right", "left"}) {
    const std::string what = fmt::format("the id of a [[calibration]] for the {} cell", cell);
    const std::optional<std::string> id = table->String(cell, what);
    if (!id) continue;
    if (const auto bad = rejected.find(*id); bad != rejected.end()) {
      table->Fail(cell, fmt::format("expected {}, found {}, which cannot be used: {}", what,
                                    Quote(*id), bad->second));
    }
    const auto match =
        std::find_if(known.begin(), known.end(), [&](const Calibration& c) { return c.id == *id; });
    if (match == known.end()) {
      std::string ids;
      for (const Calibration& c : known) ids += (ids.empty() ? "" : ", ") + Quote(c.id);
      table->Fail(cell, fmt::format("expected {}, found {}, which no calibration has (known: {})",
                                    what, Quote(*id), ids.empty() ? "none" : ids));
    }
    if (match->cell != cell) {
      table->Fail(cell, fmt::format("expected {}, found {}, which calibrates the {} cell", what,
                                    Quote(*id), match->cell));
    }
    result.emplace(std::string(cell), *id);
  }
  return result;
}

std::map<std::string, TraceSettings> ReadRunTraces(const TableReader& run, const Scope& scope,
                                                   bool has_photo) {
  std::map<std::string, TraceSettings> traces;
  const std::optional<TableReader> table = run.Table("traces");
  if (!table) return traces;
  table->WarnUnknownKeys({"right", "left", "contact"});
  for (const std::string_view name : {"right", "left", "contact"}) {
    if (auto trace = table->Table(name)) {
      const TraceKind kind = name == "contact" ? TraceKind::kContact : TraceKind::kDisplacement;
      traces.emplace(std::string(name), ReadTrace(*trace, kind, scope, has_photo));
    }
  }
  return traces;
}

// Values typed in by hand instead of traces, and their reading uncertainties.
void ReadTypedIn(const TableReader& table, UnitSystem units, Run& run) {
  const std::string length = LabelsFor(units).length;
  if (auto rebounds =
          table.Numbers("rebounds", "an array of rebound amplitudes Xmax",
                        {Sign::kPositive, fmt::format("a positive rebound amplitude ({})", length)},
                        std::nullopt)) {
    run.rebounds = *rebounds;
  }
  run.contact_time = table.Number("contact_time", {Sign::kPositive, "a positive time (s)"});
  run.rebound_uncertainty = table.Number(
      "rebound_uncertainty", {Sign::kPositive, fmt::format("a positive length ({})", length)});
  run.contact_time_uncertainty =
      table.Number("contact_time_uncertainty", {Sign::kPositive, "a positive time (s)"});

  constexpr std::string_view kFitWhat = "two rebound numbers [a, b] with 0 <= a < b";
  const auto fit =
      table.Integers("fit_rebounds", kFitWhat, {0, kMaxInt, "a rebound number >= 0"}, 2);
  if (!fit) return;
  if (!((*fit)[0] < (*fit)[1])) {
    table.Fail("fit_rebounds",
               fmt::format("expected {}, found [{}, {}]", kFitWhat, (*fit)[0], (*fit)[1]));
  }
  const auto count = static_cast<long long>(run.rebounds.size());
  if (count > 0 && (*fit)[1] >= count) {
    table.Fail("fit_rebounds",
               fmt::format("expected {} < {} (the run has {} typed-in rebounds, numbered 0 to {}), "
                           "found [{}, {}]",
                           kFitWhat, count, count, count - 1, (*fit)[0], (*fit)[1]));
  }
  run.fit_rebounds = {static_cast<int>((*fit)[0]), static_cast<int>((*fit)[1])};
}

// [specimen] and [run.specimen] (io/specimen.h): what the bars are. Every
// key is optional (a run's table gives only what differs from the
// session's); a number is positive, Poisson's ratio within (-1, 1/2), the
// range in which the effective modulus E / (2 (1 - nu^2)) of an isotropic
// material is positive and finite.
Specimen ReadSpecimen(const TableReader& table) {
  table.WarnUnknownKeys({"material", "end_shape", "edge_radius", "sphere_radius",
                         "contact_stiffness", "bar_length", "bar_diameter", "modulus",
                         "poisson_ratio"});
  Specimen specimen;
  specimen.material = table.String("material", "the material's name (a string)").value_or("");
  specimen.end_shape =
      table.Choice("end_shape", {"plane", "sphere", "given_stiffness"}).value_or("");
  constexpr NumberRule kLength{Sign::kPositive, "a positive length"};
  specimen.edge_radius = table.Number("edge_radius", kLength);
  specimen.sphere_radius = table.Number("sphere_radius", kLength);
  specimen.contact_stiffness = table.Number(
      "contact_stiffness", {Sign::kPositive, "a positive Hertz stiffness k (force/length^1.5)"});
  specimen.bar_length = table.Number("bar_length", kLength);
  specimen.bar_diameter = table.Number("bar_diameter", kLength);
  specimen.modulus =
      table.Number("modulus", {Sign::kPositive, "a positive Young's modulus (force/length^2)"});
  constexpr std::string_view kPoisson = "a Poisson ratio greater than -1 and less than 0.5";
  specimen.poisson_ratio = table.Number("poisson_ratio", {Sign::kAny, kPoisson});
  if (specimen.poisson_ratio &&
      !(*specimen.poisson_ratio > -1.0 && *specimen.poisson_ratio < 0.5)) {
    table.Fail("poisson_ratio", fmt::format("expected {}, found {}", kPoisson,
                                            FormatNumber(*specimen.poisson_ratio)));
  }
  return specimen;
}

Run ReadRun(const TableReader& table, std::string id, UnitSystem units,
            const std::optional<Apparatus>& apparatus, const Scope& scope,
            const std::vector<Calibration>& calibrations,
            const std::map<std::string, std::string>& rejected_calibrations) {
  table.WarnUnknownKeys({"id", "initial_displacement", "photo", "graticule_corners", "calibration",
                         "first_rebound", "traces", "rebounds", "contact_time", "fit_rebounds",
                         "rebound_uncertainty", "contact_time_uncertainty", "digitize",
                         "rebound_extraction", "specimen"});
  Run run;
  run.id = std::move(id);
  run.settings = ReadSettings(table, {"digitize", "rebound_extraction"});
  run.initial_displacement = ReadReleaseDisplacement(table, units, apparatus);
  run.photo = table.Path("photo");
  run.graticule_corners_px = ReadGraticuleCorners(table, run.photo.has_value());
  run.calibration = ReadRunCalibrations(table, calibrations, rejected_calibrations);
  run.first_rebound = static_cast<int>(
      table.Integer("first_rebound", {0, kMaxInt, "a rebound number >= 0"}).value_or(1));
  run.traces = ReadRunTraces(table, scope, run.photo.has_value());
  ReadTypedIn(table, units, run);
  if (auto specimen = table.Table("specimen")) run.specimen = ReadSpecimen(*specimen);

  const bool has_csv = std::any_of(run.traces.begin(), run.traces.end(),
                                   [](const auto& trace) { return trace.second.csv.has_value(); });
  if (!run.photo && !has_csv && !run.HasTypedRebounds()) {
    table.FailTable(
        "the run has nothing to reduce; expected a `photo`, traces with `csv` files, "
        "or typed-in `rebounds`" +
        table.UnknownKeysNote());
  }
  if (run.photo && run.traces.empty() && !run.HasTypedRebounds()) {
    table.Warn("photo",
               "the photo is not used: the run has no [run.traces.*] tables saying what "
               "it shows");
  }
  return run;
}

LogChannel ReadChannel(const TableReader& table, std::string name) {
  table.WarnUnknownKeys({"column", "counts_per_rev", "gear_ratio", "sensitivity"});
  LogChannel channel;
  // Most logs name their columns after the channels, so the column may be left out.
  channel.column = table.String("column", "a CSV column name").value_or(name);
  channel.name = std::move(name);
  channel.counts_per_rev =
      table.Number("counts_per_rev", {Sign::kPositive, "a positive number of counts per turn"});
  channel.gear_ratio =
      table.Number("gear_ratio", {Sign::kPositive, "a positive gear ratio"}).value_or(1.0);
  channel.sensitivity =
      table.Number("sensitivity", {Sign::kPositive, "a positive sensitivity (V per g)"});
  if (channel.counts_per_rev && channel.sensitivity) {
    table.Fail("sensitivity",
               "expected `counts_per_rev` (an encoder) or `sensitivity` (an "
               "accelerometer), found both");
  }
  if (table.Has("gear_ratio") && !channel.counts_per_rev) {
    table.Warn("gear_ratio",
               "'gear_ratio' applies only to encoder channels (with "
               "`counts_per_rev`) (ignored)");
  }
  return channel;
}

Log ReadLog(const TableReader& table, std::string id) {
  table.WarnUnknownKeys(
      {"id", "experiment", "simulation", "time_column", "channels", "log_analysis"});
  Log log;
  log.id = std::move(id);
  log.settings = ReadSettings(table, {"log_analysis"});
  log.folder = table.context().folder;
  log.experiment = table.RequiredPath("experiment");
  log.simulation = table.Path("simulation");
  log.time_column = table.String("time_column", "a CSV column name").value_or("t");
  if (const std::optional<TableReader> channels = table.Table("channels")) {
    // toml++ keeps keys sorted; list the channels in the order the user wrote them.
    std::vector<std::pair<toml::source_position, std::string>> names;
    for (const auto& [key, node] : channels->table()) {
      names.emplace_back(node.source().begin, std::string(key.str()));
    }
    std::stable_sort(names.begin(), names.end(), [](const auto& a, const auto& b) {
      return std::pair(a.first.line, a.first.column) < std::pair(b.first.line, b.first.column);
    });
    for (const auto& [position, name] : names) {
      // A channel names a group in the results file, as an id does.
      if (!IsSafeId(name)) {
        channels->Fail(
            name, fmt::format("expected a channel name of {}, found {}", kSafeIdRule, Quote(name)));
      }
      log.channels.push_back(ReadChannel(*channels->Table(name), name));
    }
  }
  return log;
}

ReductionSettings ReadReduction(const TableReader& table) {
  table.WarnUnknownKeys({"contact_time", "stiffness", "convention", "separation"});
  ReductionSettings reduction;
  reduction.contact_time = table.Number("contact_time", {Sign::kPositive, "a positive time (s)"});
  reduction.average_stiffness =
      table.Choice("stiffness", {"per-run", "average"}).value_or("per-run") == "average";
  reduction.convention = table.Choice("convention", {"exact", "thesis"}).value_or("exact");
  reduction.separation = table.Choice("separation", {"kinematic", "force"}).value_or("kinematic");
  return reduction;
}

// A run has rebounds to fit or to compare with when they are typed in or will
// be read from a displacement trace.
bool HasRebounds(const Run& run) {
  return run.HasTypedRebounds() || run.traces.count("right") || run.traces.count("left");
}

Prediction ReadPrediction(const TableReader& table, const std::vector<Run>& runs,
                          const std::vector<RejectedEntry>& rejected) {
  table.WarnUnknownKeys({"source_run", "target_run", "start_rebound"});
  const auto run_key = [&](std::string_view key) -> const Run& {
    constexpr std::string_view kWhat = "the id of a [[run]] with rebounds";
    const std::string id = table.RequiredString(key, kWhat);
    const auto run =
        std::find_if(runs.begin(), runs.end(), [&](const Run& r) { return r.id == id; });
    if (run == runs.end()) {
      const auto bad = std::find_if(rejected.begin(), rejected.end(), [&](const RejectedEntry& e) {
        return e.table == "run" && e.id == id;
      });
      table.Fail(
          key,
          bad != rejected.end()
              ? fmt::format("expected {}, found {}, a run that cannot be reduced", kWhat, Quote(id))
              : fmt::format("expected {}, found {}, which no run has", kWhat, Quote(id)));
    }
    if (!HasRebounds(*run)) {
      table.Fail(key, fmt::format("expected {}, found {}, which has neither typed-in `rebounds` "
                                  "nor a right or left trace",
                                  kWhat, Quote(id)));
    }
    return *run;
  };
  Prediction prediction;
  prediction.source_run = run_key("source_run").id;
  const Run& target = run_key("target_run");
  prediction.target_run = target.id;
  prediction.start_rebound = static_cast<int>(
      table.Integer("start_rebound", {0, kMaxInt, "a rebound number >= 0"}).value_or(0));
  const auto count = static_cast<int>(target.rebounds.size());
  if (count > 0 && prediction.start_rebound >= count) {
    table.Fail("start_rebound",
               fmt::format("expected a rebound number below {} (run {} has {} typed-in rebounds), "
                           "found {}",
                           count, Quote(target.id), count, prediction.start_rebound));
  }
  return prediction;
}

// ---------------------------------------------------------------------------
// The whole file.

toml::table ParseToml(const std::string& text, const fs::path& manifest) {
  try {
    return toml::parse(text, manifest.string());
  } catch (const toml::parse_error& error) {
    const auto line = error.source().begin.line;
    throw InputError(
        InputLocation{manifest, "", line ? std::optional<long long>(line) : std::nullopt},
        fmt::format("TOML syntax error: {}", error.description()));
  }
}

// Reads each [[kind]] table with `read(table, id)`. An entry whose id cannot
// be used (missing, unsafe, or already taken) or whose reading throws an
// InputError is rejected alone, with the reason, under its id or "#N".
void ReadEntries(const TableReader& root, std::string_view kind,
                 std::vector<RejectedEntry>& rejected,
                 const std::function<void(const TableReader&, std::string)>& read) {
  IdRegistry ids(kind);
  const std::vector<TableReader> tables = root.ArrayOfTables(kind);
  for (std::size_t i = 0; i < tables.size(); ++i) {
    std::string label = fmt::format("#{}", i + 1);
    try {
      std::string id = ids.Read(tables[i]);
      label = id;
      read(tables[i], std::move(id));
    } catch (const InputError& error) {
      rejected.push_back({std::string(kind), label, i, error.where(), error.problem()});
    }
  }
}

Session ReadSession(const TableReader& root) {
  const Context& context = root.context();
  Session session;
  session.folder = context.folder;
  session.manifest = context.manifest;

  // The format decides what every other key means, so it is checked first.
  constexpr std::string_view kFormatWhat = "the manifest format 1";
  if (!root.Has("format")) root.Missing("format", kFormatWhat);
  session.format = static_cast<int>(*root.Integer("format", {1, 1, kFormatWhat}));

  root.WarnUnknownKeys({"format", "title", "units", "apparatus", "scope", "calibration", "run",
                        "log", "reduction", "prediction", "specimen", kStageTables[0],
                        kStageTables[1], kStageTables[2], kStageTables[3], kStageTables[4],
                        kStageTables[5]});
  session.settings = ReadSettings(root, {kStageTables[0], kStageTables[1], kStageTables[2],
                                         kStageTables[3], kStageTables[4], kStageTables[5]});
  session.title = root.String("title", "a title (a string)").value_or("");
  if (auto units = root.Choice("units", {"in-lbf-s", "SI"})) {
    session.units = *ParseUnitSystem(*units);
  }
  if (auto apparatus = root.Table("apparatus")) {
    session.apparatus = ReadApparatus(*apparatus, session.units);
  }
  const Scope scope = ReadScope(root.TableOrEmpty("scope"));
  session.divisions = scope.divisions;

  // Calibrations first: runs refer to them wherever they stand in the file.
  // Each entry is read on its own: a mistake in one fails that entry alone.
  std::map<std::string, std::string> rejected_calibrations;  // id -> why
  ReadEntries(root, "calibration", session.rejected, [&](const TableReader& table, std::string id) {
    const std::string key = id;
    try {
      session.calibrations.push_back(
          ReadCalibration(table, std::move(id), session.units, session.apparatus, scope));
    } catch (const InputError& error) {
      rejected_calibrations.emplace(key, FormatLocation(error.where()) + ": " + error.problem());
      throw;
    }
  });
  const std::vector<TableReader> run_tables = root.ArrayOfTables("run");
  ReadEntries(root, "run", session.rejected, [&](const TableReader& table, std::string id) {
    session.runs.push_back(ReadRun(table, std::move(id), session.units, session.apparatus, scope,
                                   session.calibrations, rejected_calibrations));
  });
  if (!run_tables.empty() && !session.apparatus) {
    const TableReader& first = run_tables.front();
    const std::string where = first.line() ? fmt::format(" at line {}", *first.line()) : "";
    root.Missing("apparatus",
                 fmt::format("an [apparatus] table, which a session with runs needs (the first "
                             "run is {}{})",
                             first.path(), where));
  }
  ReadEntries(root, "log", session.rejected, [&](const TableReader& table, std::string id) {
    session.logs.push_back(ReadLog(table, std::move(id)));
  });
  if (auto reduction = root.Table("reduction")) session.reduction = ReadReduction(*reduction);
  if (auto specimen = root.Table("specimen")) session.specimen = ReadSpecimen(*specimen);
  const std::vector<TableReader> predictions = root.ArrayOfTables("prediction");
  for (std::size_t i = 0; i < predictions.size(); ++i) {
    try {
      session.predictions.push_back(ReadPrediction(predictions[i], session.runs, session.rejected));
    } catch (const InputError& error) {
      session.rejected.push_back(
          {"prediction", fmt::format("#{}", i + 1), i, error.where(), error.problem()});
    }
  }
  return session;
}

}  // namespace

ManifestReadResult ParseManifest(const std::string& toml_text,
                                 const std::filesystem::path& manifest_path) {
  ManifestReadResult result;
  Context context;
  context.manifest = manifest_path;
  context.folder = manifest_path.has_parent_path() ? manifest_path.parent_path() : fs::path(".");
  context.canonical_folder = CanonicalFolder(context.folder);
  context.warnings = &result.warnings;

  const toml::table document = ParseToml(toml_text, manifest_path);
  result.session = ReadSession(TableReader(context, document, "", std::nullopt));
  return result;
}

SettingValue ParseSettingText(const std::string& text) {
  try {
    const toml::table parsed = toml::parse("value = " + text);
    const toml::node& node = *parsed.get("value");
    if (const auto* flag = node.as_boolean()) return flag->get();
    if (const auto* integer = node.as_integer()) return static_cast<long long>(integer->get());
    if (const auto* number = node.as_floating_point()) return number->get();
    if (const auto* quoted = node.as_string()) return quoted->get();
  } catch (const toml::parse_error&) {
    // Not a TOML value: a bare word such as gaussian.
  }
  return text;
}

std::filesystem::path SessionFolderOf(const std::filesystem::path& session) {
  std::error_code error;
  if (session.filename() != "session.toml" || !fs::is_regular_file(session, error)) return session;
  return session.has_parent_path() ? session.parent_path() : fs::path(".");
}

ManifestReadResult ReadManifest(const std::filesystem::path& session) {
  std::error_code error;
  const fs::path session_folder = SessionFolderOf(session);
  const fs::path manifest = session_folder / "session.toml";
  if (!fs::is_directory(session_folder, error)) {
    throw InputError(InputLocation{session_folder, "", std::nullopt},
                     "expected a session folder, found no folder there");
  }
  if (!fs::exists(fs::symlink_status(manifest, error))) {
    throw InputError(InputLocation{manifest, "", std::nullopt},
                     "expected the session manifest session.toml in the session folder, found "
                     "no such file");
  }
  // Opened like every file the manifest names: a manifest that is a link out
  // of the folder, or a named pipe, is refused, not read.
  const std::vector<unsigned char> bytes =
      ReadSessionFile(session_folder, manifest, kMaxManifestBytes);
  return ParseManifest(std::string(bytes.begin(), bytes.end()), manifest);
}

}  // namespace impactlab
