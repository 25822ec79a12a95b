#include "pipeline/session_result.h"

#include <algorithm>
#include <stdexcept>

namespace impactlab {

Curve ResidualCurve(const Curve& measured, const Curve& model) {
  Curve residual;
  const std::vector<double>& x = model.time_s;
  if (x.size() < 2) return residual;
  for (std::size_t k = 0; k < measured.time_s.size(); ++k) {
    const double t = measured.time_s[k];
    if (t < x.front() || t > x.back()) continue;
    const auto i = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), t) - x.begin());
    const double at = i >= x.size()
                          ? model.value.back()
                          : model.value[i - 1] + (t - x[i - 1]) / (x[i] - x[i - 1]) *
                                                     (model.value[i] - model.value[i - 1]);
    residual.time_s.push_back(t);
    residual.value.push_back(measured.value[k] - at);
  }
  return residual;
}

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
