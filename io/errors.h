// Errors about bad input: every one names the file and, where known, the key and
// line it comes from, so a user can go straight to the problem.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace impactlab {

struct InputLocation {
  std::filesystem::path file;
  std::string key;                // dotted manifest key, e.g. "run[2].traces.right.volts_per_div"
  std::optional<long long> line;  // 1-based line in the file, when known
};

// Thrown for input the user can fix: a missing file, a wrong manifest key, a
// broken photo, NaN in a log. what() reads "FILE:LINE: KEY: problem".
class InputError : public std::runtime_error {
 public:
  InputError(InputLocation where, const std::string& problem);

  const InputLocation& where() const { return where_; }
  const std::string& problem() const { return problem_; }

 private:
  InputLocation where_;
  std::string problem_;
};

std::string FormatLocation(const InputLocation& where);

}  // namespace impactlab
