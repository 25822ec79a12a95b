// Checks of numeric options that say what was wrong in words (CLI11's own
// print the bound: "not in range 0.000000 to 1797693134862315708...").
#pragma once

#include <cmath>
#include <string>

#include <CLI/CLI.hpp>

namespace impactlab::cli {

// A number `test` accepts; otherwise "must be <what>, got <text>".
template <typename Test>
CLI::Validator NumberThat(Test test, const std::string& what, const std::string& name) {
  return CLI::Validator(
      [test, what](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value)) {
          return "expected a number, got \"" + text + "\"";
        }
        return test(value) ? std::string() : "must be " + what + ", got " + text;
      },
      name);
}

inline const CLI::Validator kPositive =
    NumberThat([](double v) { return v > 0.0; }, "positive", "POSITIVE");
inline const CLI::Validator kNonNegative =
    NumberThat([](double v) { return v >= 0.0; }, "zero or more", "NONNEGATIVE");

}  // namespace impactlab::cli
