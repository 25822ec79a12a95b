#include "multibody/two_link_parameters.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

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
  return ok;
}

}  // namespace impactlab
