// Helpers of the numerical-stability suites: long-double references, relative
// errors and a record of the worst error per quantity.
// Set IMPACTLAB_STABILITY_REPORT=1 to print the worst errors at exit.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

namespace impactlab::testing {

using LD = long double;
static_assert(std::numeric_limits<LD>::digits >= 64,
              "the references need an extended-precision long double");

inline constexpr double kEps = std::numeric_limits<double>::epsilon();  // 2.2e-16
inline constexpr LD kPiL = std::numbers::pi_v<LD>;

// n points from lo to hi, evenly spaced in log, ends exact.
inline std::vector<double> LogSpace(double lo, double hi, int n) {
  std::vector<double> out;
  for (int i = 0; i < n; ++i) {
    const LD f = static_cast<LD>(i) / (n - 1);
    out.push_back(static_cast<double>(expl(logl(lo) + f * (logl(hi) - logl(lo)))));
  }
  out.front() = lo;
  out.back() = hi;
  return out;
}

inline double RelErr(double got, LD ref) {
  if (ref == 0.0L) return got == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  return static_cast<double>(fabsl(static_cast<LD>(got) - ref) / fabsl(ref));
}

struct Worst {
  double err = 0.0, tol = 0.0, input = 0.0;
  double ratio = 0.0;  // largest err / tol
};

class WorstErrors {
 public:
  ~WorstErrors() {
    if (std::getenv("IMPACTLAB_STABILITY_REPORT") == nullptr) return;
    std::printf("%-58s %10s %10s %7s %12s\n", "quantity", "worst err", "its tol", "err/tol",
                "at input");
    for (const auto& [name, w] : worst_) {
      std::printf("%-58s %10.3g %10.3g %7.3f %12.6g\n", name.c_str(), w.err, w.tol, w.ratio,
                  w.input);
    }
  }
  void Record(const std::string& quantity, double err, double tol, double input) {
    Worst& w = worst_[quantity];
    if (err >= w.err) {
      w.err = err;
      w.tol = tol;
      w.input = input;
    }
    w.ratio = std::max(w.ratio, err / tol);
  }

 private:
  std::map<std::string, Worst> worst_;
};

inline WorstErrors& Worsts() {
  static WorstErrors registry;
  return registry;
}

// `got` is finite and within max_rel_error of `ref`; records the error.
// `input_name` says what `input` is in the failure message.
inline void CheckRel(const std::string& quantity, double got, LD ref, double max_rel_error,
                     double input, const char* input_name = "input") {
  const double err = RelErr(got, ref);
  Worsts().Record(quantity, err, max_rel_error, input);
  char msg[320];
  std::snprintf(msg, sizeof msg,
                "%s at %s = %.17g: got %.17g, reference %.20Lg, rel err %.3g, max %.3g",
                quantity.c_str(), input_name, input, got, ref, err, max_rel_error);
  INFO(msg);
  CHECK(std::isfinite(got));
  CHECK(err <= max_rel_error);
}

}  // namespace impactlab::testing
