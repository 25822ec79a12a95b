#include "pipeline/session_result.h"

#include <algorithm>
#include <stdexcept>

namespace impactlab {

int SessionResult::FailedRuns() const {
  // A log that cannot be analysed counts as a failed run: the exit status says so.
  return static_cast<int>(
      std::count_if(runs.begin(), runs.end(), [](const RunResult& r) { return !r.ok; }) +
      std::count_if(logs.begin(), logs.end(), [](const LogResult& l) { return !l.ok; }));
}

const RunResult* SessionResult::FindRun(const std::string& id) const {
  const auto it =
      std::find_if(runs.begin(), runs.end(), [&](const RunResult& r) { return r.id == id; });
  return it == runs.end() ? nullptr : &*it;
}

const ProductRecord* SessionResult::FindProduct(std::string_view name) const {
  const auto it = std::find_if(products.begin(), products.end(),
                               [&](const ProductRecord& p) { return p.name == name; });
  return it == products.end() ? nullptr : &*it;
}

const char* ConventionName(PendulumConvention convention) {
  return convention == PendulumConvention::kThesis ? "thesis" : "exact";
}

PendulumConvention ParseConvention(const std::string& name) {
  if (name == "exact") return PendulumConvention::kExact;
  if (name == "thesis") return PendulumConvention::kThesis;
  throw std::invalid_argument("convention must be \"exact\" or \"thesis\", got \"" + name + "\"");
}

}  // namespace impactlab
