// A figure's file name for `report --figures DIR`: its number and its title's
// words, so that a folder of figures reads like the page's list of them.
#pragma once

#include <array>
#include <cctype>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

namespace impactlab {

// "02-c-against-sqrt-xi.svg" for figure 2, "C against √ξ"; "04-run-0.115-measured-minus-fitted.svg"
// for "Run 0.115: measured − fitted". Letters and digits in lower case, the symbols the titles
// use as words (√ξ, −), a point only between digits (a run id's), anything else one '-'.
inline std::string FigureFileName(std::size_t number, std::string_view title) {
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 7> kSymbols{{
      {"\u221a", "sqrt"},   // √
      {"\u2212", "minus"},  // −
      {"\u03be", "xi"},     // ξ
      {"\u03b6", "zeta"},   // ζ
      {"\u03c4", "tau"},    // τ
      {"\u03c7", "chi"},    // χ
      {"\u00b2", "2"},      // ²
  }};
  std::string words;
  const auto separate = [&] {
    if (!words.empty() && words.back() != '-') words += '-';
  };
  for (std::size_t i = 0; i < title.size();) {
    const auto c = static_cast<unsigned char>(title[i]);
    if (c < 0x80 && std::isalnum(c)) {
      words += static_cast<char>(std::tolower(c));
      ++i;
      continue;
    }
    if (c == '.' && !words.empty() && std::isdigit(static_cast<unsigned char>(words.back())) &&
        i + 1 < title.size() && std::isdigit(static_cast<unsigned char>(title[i + 1]))) {
      words += '.';
      ++i;
      continue;
    }
    separate();
    bool symbol = false;
    for (const auto& [text, word] : kSymbols) {
      if (title.substr(i).starts_with(text)) {
        words += word;
        separate();
        i += text.size();
        symbol = true;
        break;
      }
    }
    if (!symbol) ++i;
  }
  while (!words.empty() && words.back() == '-') words.pop_back();
  if (words.size() > 80) words.resize(80);  // a long log or channel name
  while (!words.empty() && words.back() == '-') words.pop_back();
  return fmt::format("{:02d}{}{}.svg", number, words.empty() ? "" : "-", words);
}

}  // namespace impactlab
