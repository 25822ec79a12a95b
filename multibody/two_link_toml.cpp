#include "multibody/two_link_toml.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include "io/errors.h"
#include "multibody/two_link_keys.h"

namespace impactlab {

TwoLinkParameters ParseTwoLinkParameters(std::string_view text, const std::filesystem::path& file) {
  return ParseTwoLinkParameters(text, file, TwoLinkParameters::Nominal());
}

TwoLinkParameters ParseTwoLinkParameters(std::string_view text, const std::filesystem::path& file,
                                         const TwoLinkParameters& base) {
  toml::table table;
  try {
    table = toml::parse(text, file.string());
  } catch (const toml::parse_error& e) {
    throw InputError({file, "", static_cast<long long>(e.source().begin.line)},
                     std::string(e.description()));
  }
  TwoLinkParameters p = base;
  std::map<std::string, std::set<std::string>> known;
  VisitTwoLinkKeys(p, [&](const char* section, const char* key, double& value, TwoLinkKeyRule rule,
                          const char*) {
    known[section].insert(key);
    const toml::node* node = table.at_path(fmt::format("{}.{}", section, key)).node();
    if (!node) return;
    const std::string where = fmt::format("{}.{}", section, key);
    const auto line = static_cast<long long>(node->source().begin.line);
    if (!node->is_number()) throw InputError({file, where, line}, "must be a number");
    value = node->value<double>().value();
    if (!std::isfinite(value)) throw InputError({file, where, line}, "must be finite");
    if (rule == TwoLinkKeyRule::kPositive && !(value > 0.0)) {
      throw InputError({file, where, line}, "must be positive");
    }
    if (rule == TwoLinkKeyRule::kNonNegative && !(value >= 0.0)) {
      throw InputError({file, where, line}, "must be >= 0");
    }
  });
  VisitTwoLinkChoices(p, [&](const char* section, const char* key, std::string& value,
                             const std::vector<std::string>& allowed, const char*) {
    known[section].insert(key);
    const toml::node* node = table.at_path(fmt::format("{}.{}", section, key)).node();
    if (!node) return;
    if (!node->is_string()) {
      throw InputError({file, fmt::format("{}.{}", section, key),
                        static_cast<long long>(node->source().begin.line)},
                       "must be a quoted word");
    }
    value = node->value<std::string>().value();
    if (std::find(allowed.begin(), allowed.end(), value) == allowed.end()) {
      throw InputError({file, fmt::format("{}.{}", section, key),
                        static_cast<long long>(node->source().begin.line)},
                       fmt::format("must be one of \"{}\"", fmt::join(allowed, "\", \"")));
    }
  });
  for (const auto& [section, node] : table) {
    const std::string name(section.str());
    const auto line = static_cast<long long>(node.source().begin.line);
    if (!known.count(name)) throw InputError({file, name, line}, "unknown table");
    if (!node.is_table()) throw InputError({file, name, line}, "must be a table");
    for (const auto& [key, value] : *node.as_table()) {
      if (!known[name].count(std::string(key.str()))) {
        throw InputError({file, fmt::format("{}.{}", name, key.str()),
                          static_cast<long long>(value.source().begin.line)},
                         "unknown key");
      }
    }
  }
  std::string error;
  if (!p.Check(&error)) throw InputError({file, "", std::nullopt}, error);
  return p;
}

std::string TwoLinkParametersText(const TwoLinkParameters& parameters) {
  std::ostringstream out;
  std::string current;
  // A section's words follow its numbers.
  auto choices_of = [&](const std::string& section) {
    VisitTwoLinkChoices(parameters,
                        [&](const char* choice_section, const char* key, const std::string& word,
                            const std::vector<std::string>&, const char* description) {
                          if (section == choice_section) {
                            out << fmt::format("{} = \"{}\"  # {}\n", key, word, description);
                          }
                        });
  };
  VisitTwoLinkKeys(parameters, [&](const char* section, const char* key, const double& value,
                                   TwoLinkKeyRule, const char* description) {
    if (current != section) {
      choices_of(current);
      out << (current.empty() ? "" : "\n") << "[" << section << "]\n";
      current = section;
    }
    out << fmt::format("{} = {}  # {}\n", key, value, description);
  });
  choices_of(current);
  return out.str();
}

}  // namespace impactlab
