#include "io/errors.h"

#include <fmt/format.h>

namespace impactlab {

std::string FormatLocation(const InputLocation& where) {
  std::string text = where.file.string();
  if (where.line) text += fmt::format(":{}", *where.line);
  if (!where.key.empty()) text += fmt::format(": {}", where.key);
  return text;
}

InputError::InputError(InputLocation where, const std::string& problem)
    : std::runtime_error(fmt::format("{}: {}", FormatLocation(where), problem)),
      where_(std::move(where)),
      problem_(problem) {}

}  // namespace impactlab
