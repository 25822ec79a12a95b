// "Did you mean …?": the known word a mistyped one was most likely meant to
// be, for messages about unknown keys, settings and commands.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace impactlab {

// The optimal string alignment distance: insertions, deletions,
// substitutions and swaps of two neighbouring letters each count one.
std::size_t EditDistance(std::string_view a, std::string_view b);

// The known word nearest `typed`, when it is near enough to be a typo: at
// most one edit for words of up to four letters, two up to twelve, three
// beyond (a missing or doubled underscore, a swapped pair, a dropped letter).
// Case is ignored. The first of equally near words wins.
std::optional<std::string> NearestWord(std::string_view typed,
                                       const std::vector<std::string>& known);

// " (did you mean \"word\"?)", or "" when no known word is near.
std::string DidYouMean(std::string_view typed, const std::vector<std::string>& known);

}  // namespace impactlab
