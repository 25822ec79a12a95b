#include "multibody/two_link_parameters.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "multibody/two_link_keys.h"

namespace impactlab {

TwoLinkParameters TwoLinkParameters::Nominal() {
  TwoLinkParameters p;
  // Aluminium strips 45 x 2.5 mm bending in the table's plane:
  // rho A = 2700 x 45e-3 x 2.5e-3, E I = 69 GPa x 45e-3 x 2.5e-3^3 / 12.
  // With the masses below, a1's ring-down after case 1's first impact shows
  // 11.6 Hz, as the paper's simulation does (11.53-11.59 Hz).
  p.beam1 = {0.75, 0.05, 0.30375, 4.043, 0.05};
  p.beam2 = {0.50, 0.04, 0.30375, 4.043, 0.05};
  p.hub1 = {0.4, 2.0e-3};
  p.body2 = {2.5, 6.0e-3};  // motor-gearbox B, its bracket and an air bearing
  p.hub3 = {0.15, 2.0e-4};
  p.tool = {{0.75, 8.0e-4}, 0.02, 0.03, 0.0};  // tool and its air bearing
  // Permanent-magnet DC motors with 50:1 planetary gearheads.
  p.drive_a = {50.0, 0.0525, 0.0525, 2.0, 0.030, 0.05, 0.003, 2.0e4, 5.0};
  p.drive_b = {50.0, 0.0302, 0.0302, 4.0, 0.010, 0.02, 0.003, 1.0e4, 2.0};
  p.surface = {0.025, 0.2, 1e-3};
  const double deg = std::numbers::pi / 180.0;
  p.cases[0] = {55.0 * deg, 0.0, 1.5, 1.5, 0.1, 5.0, false};
  p.cases[1] = {87.0 * deg, 0.0, 0.0, 1.5, 0.1, 5.0, false};
  p.cases[2] = {70.0 * deg, 40.0 * deg, 0.0, 0.0, 0.1, 8.0, true};
  p.sanding = {0.95, 0.12, 4.0, 0.05, 40.0, 6.0};
  return p;
}

bool TwoLinkParameters::Check(std::string* error) const {
  bool ok = true;
  VisitTwoLinkKeys(*this, [&](const char* section, const char* key, const double& value,
                              const TwoLinkKeyRule& rule, const char*) {
    if (!ok) return;
    const bool finite = std::isfinite(value);
    const bool in_range = finite && (rule == TwoLinkKeyRule::kAny ||
                                     (rule == TwoLinkKeyRule::kPositive && value > 0.0) ||
                                     (rule == TwoLinkKeyRule::kNonNegative && value >= 0.0));
    if (!in_range) {
      ok = false;
      if (error) {
        *error = fmt::format("[{}] {} = {} must be {}", section, key, value,
                             rule == TwoLinkKeyRule::kPositive      ? "positive"
                             : rule == TwoLinkKeyRule::kNonNegative ? "finite and >= 0"
                                                                    : "finite");
      }
    }
  });
  VisitTwoLinkChoices(*this, [&](const char* section, const char* key, const std::string& value,
                                 const std::vector<std::string>& allowed, const char*) {
    if (!ok || std::find(allowed.begin(), allowed.end(), value) != allowed.end()) return;
    ok = false;
    if (error) {
      *error = fmt::format("[{}] {} = \"{}\" must be one of \"{}\"", section, key, value,
                           fmt::join(allowed, "\", \""));
    }
  });
  // The model is a table-top arm's: its geometry is held to 100 m, far
  // beyond any such arm and far inside what its trigonometry resolves.
  VisitTwoLinkKeys(*this, [&](const char* section, const char* key, const double& value,
                              const TwoLinkKeyRule&, const char*) {
    const std::string_view name(key);
    const bool length = name.size() > 2 && name.substr(name.size() - 2) == "_m" &&
                        std::string_view(section) != "sanding";
    if (ok && length && !(std::abs(value) <= 100.0)) {
      ok = false;
      if (error) {
        *error = fmt::format("[{}] {} = {:g} is beyond the model's 100 m", section, key, value);
      }
    }
  });
  // Masses and inertias that span more than 1e12 leave the mass matrix
  // singular to double precision.
  std::pair<double, std::string> lightest{INFINITY, ""}, heaviest{0.0, ""};
  VisitTwoLinkKeys(*this, [&](const char* section, const char* key, const double& value,
                              const TwoLinkKeyRule&, const char*) {
    const std::string_view name(key);
    const bool inertial = name == "mass_kg" || name == "inertia_kg_m2" ||
                          name == "mass_per_length_kg_per_m" || name == "equivalent_inertia_kg_m2";
    if (!inertial || !(value > 0.0)) return;
    const std::string where = fmt::format("[{}] {} = {:g}", section, key, value);
    if (value < lightest.first) lightest = {value, where};
    if (value > heaviest.first) heaviest = {value, where};
  });
  if (ok && heaviest.first > 1e12 * lightest.first) {
    ok = false;
    if (error) {
      *error = fmt::format("{} and {} span more than the 1e12 the mass matrix resolves",
                           heaviest.second, lightest.second);
    }
  }
  // The drives are DC motors on a table-top arm, without saturation.
  constexpr double kMostVolts = 1000.0;
  for (int c = 0; c < 3 && ok; ++c) {
    for (const auto& [key, volts] : {std::pair{"voltage_a_v", cases[c].voltage_a_v},
                                     std::pair{"voltage_b_v", cases[c].voltage_b_v}}) {
      if (ok && !(std::abs(volts) <= kMostVolts)) {
        ok = false;
        if (error) {
          *error = fmt::format("[case{}] {} = {:g} is beyond the drives' {:g} V", c + 1, key, volts,
                               kMostVolts);
        }
      }
    }
  }
  if (ok && !(sanding.max_voltage_v <= kMostVolts)) {
    ok = false;
    if (error) {
      *error = fmt::format("[sanding] max_voltage_v = {:g} is beyond the drives' {:g} V",
                           sanding.max_voltage_v, kMostVolts);
    }
  }
  for (int c = 0; c < 3 && ok; ++c) {
    const double samples = sensors.sample_rate_hz * cases[c].duration_s;
    if (!(samples <= kTwoLinkMaxSamples)) {
      ok = false;
      if (error) {
        *error = fmt::format(
            "[sensors] sample_rate_hz = {:g} and [case{}] duration_s = {:g} give {:.3g} samples, "
            "over the limit of {:g} per case",
            sensors.sample_rate_hz, c + 1, cases[c].duration_s, samples, kTwoLinkMaxSamples);
      }
    }
  }
  if (ok && surface.restitution_coefficient > 1.0) {
    ok = false;
    if (error) {
      *error = fmt::format("[surface] restitution_coefficient = {} must be at most 1",
                           surface.restitution_coefficient);
    }
  }
  if (ok && surface.impact_friction == "paper" && surface.restitution_coefficient != 0.0) {
    ok = false;
    if (error) {
      *error = fmt::format(
          "[surface] impact_friction = \"paper\" is the paper's plastic impact: "
          "restitution_coefficient = {} must be 0 with it",
          surface.restitution_coefficient);
    }
  }
  return ok;
}

}  // namespace impactlab
