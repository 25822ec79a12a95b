// The two-link simulator on bad parameters (docs/two-link.md, "Parameters
// outside the model"): random parameter sets, each with one to three keys
// scaled by 10^k (k from -12 to 12) or set to an extreme, simulated as
// `simulate two-link --case 1` would. Every set must end within 10 s with a
// result or a refusal that names its cause, and no result may hold NaN.
//
//   bench_two_link_inputs [--sets 200] [--seed 1] [--list]
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "multibody/two_link_keys.h"
#include "multibody/two_link_simulation.h"

namespace {

using namespace impactlab;

// Every double the record holds is finite.
bool AllFinite(const TwoLinkRecord& r) {
  auto finite = [](const std::vector<double>& v) {
    for (double x : v) {
      if (!std::isfinite(x)) return false;
    }
    return true;
  };
  bool ok = finite(r.time_s) && finite(r.gearbox_a_rad) && finite(r.gearbox_b_rad) &&
            finite(r.normal_force_n) && finite(r.friction_force_n) && finite(r.tip_x_m) &&
            finite(r.tip_y_m);
  for (const auto& channel : r.acceleration_m_s2) ok = ok && finite(channel);
  for (const auto& q : r.position) ok = ok && q.allFinite();
  for (const auto& v : r.velocity) ok = ok && v.allFinite();
  return ok;
}

// The refusal's kind: its message up to the first number or colon.
std::string KindOf(const std::string& message) {
  std::string kind;
  for (char c : message) {
    if ((c >= '0' && c <= '9') || c == '=' || kind.size() > 60) break;
    kind += c;
  }
  return kind;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Two-link simulator: random bad parameter sets, each to a result or a refusal");
  int sets = 200;
  unsigned seed = 1;
  app.add_option("--sets", sets, "Parameter sets")->capture_default_str();
  app.add_option("--seed", seed, "Random seed")->capture_default_str();
  bool list = false;
  app.add_flag("--list", list, "Print each set and its outcome");
  CLI11_PARSE(app, argc, argv);

  std::vector<std::string> keys;
  TwoLinkParameters nominal = TwoLinkParameters::Nominal();
  VisitTwoLinkKeys(
      nominal, [&](const char* section, const char* key, double&, TwoLinkKeyRule, const char*) {
        if (std::string(section).rfind("case", 0) == 0 && std::string(section) != "case1") return;
        keys.push_back(fmt::format("{}.{}", section, key));
      });
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, keys.size() - 1);
  std::uniform_int_distribution<int> exponent(-12, 12), count(1, 3), extreme(0, 9);
  const double extremes[] = {0.0, -1.0, 1e300, -1e300, 1e-300, 1e308};

  int results = 0, refused_check = 0, refused_simulation = 0, over_10_s = 0, with_nan = 0;
  int warned = 0;
  double slowest = 0.0;
  std::string slowest_set;
  std::map<std::string, int> kinds;
  for (int s = 0; s < sets; ++s) {
    TwoLinkParameters p = nominal;
    std::string changed;
    for (int n = count(rng); n > 0; --n) {
      const std::string target = keys[pick(rng)];
      const int e = extreme(rng);
      VisitTwoLinkKeys(
          p, [&](const char* section, const char* key, double& value, TwoLinkKeyRule, const char*) {
            if (target != fmt::format("{}.{}", section, key)) return;
            value = e < 6 ? extremes[e] : value * std::pow(10.0, exponent(rng));
            changed += fmt::format("{} = {:g}; ", target, value);
          });
    }
    const auto start = std::chrono::steady_clock::now();
    std::string error, outcome;
    if (!p.Check(&error)) {
      ++refused_check;
      ++kinds["parameters: " + KindOf(error)];
      outcome = error;
    } else {
      try {
        const TwoLinkModel model(p);
        const TwoLinkRecord record = SimulateTwoLink(model, p.cases[0]);
        if (!AllFinite(record)) {
          ++with_nan;
          fmt::print("NaN in the record: {}\n", changed);
        }
        if (record.ok) {
          ++results;
          warned += !record.warnings.empty();
          outcome = "result";
        } else {
          ++refused_simulation;
          ++kinds["simulation: " + KindOf(record.reason)];
          outcome = record.reason;
        }
      } catch (const std::exception& e) {  // the model's own checks of its parameters
        ++refused_simulation;
        ++kinds["simulation: " + KindOf(e.what())];
        outcome = e.what();
      }
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (list) fmt::print("{:.2f} s: {}-> {}\n", seconds, changed, outcome);
    if (seconds > 10.0) {
      ++over_10_s;
      fmt::print("over 10 s ({:.1f} s): {} -> {}\n", seconds, changed, outcome);
    }
    if (seconds > slowest) {
      slowest = seconds;
      slowest_set = changed;
    }
  }
  fmt::print(
      "| sets | simulated | of them warned | refused by the parameter check | refused by the "
      "simulation | over 10 s | holding NaN | slowest |\n|---|---|---|---|---|---|---|---|\n");
  fmt::print("| {} | {} | {} | {} | {} | {} | {} | {:.2f} s ({}) |\n", sets, results, warned,
             refused_check, refused_simulation, over_10_s, with_nan, slowest, slowest_set);
  fmt::print("\n| refusal | sets |\n|---|---|\n");
  for (const auto& [kind, n] : kinds) fmt::print("| {} | {} |\n", kind, n);
  return over_10_s == 0 && with_nan == 0 ? 0 : 1;
}
