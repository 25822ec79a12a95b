// Which sessions a material's fit names as pulling away: only those that the
// other sessions, at least two of them, outvote. Sessions made by hand, their
// restitution speed laws stated directly.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "campaign/campaign.h"
#include "campaign/campaign_internal.h"

namespace impactlab {
namespace {

// A session of `material` whose restitution law states chi (beta = 1 exactly
// at the reference speed 100) with a relative error of 1e-3 and beta to 0.01.
CampaignSession WithRestitution(const std::string& name, double chi) {
  CampaignSession s;
  s.name = name;
  s.material = "steel";
  SessionRestitutionLaw& law = s.restitution_law;
  law.ok = true;
  law.reference_speed = 100.0;
  law.log_eps = std::log(chi * law.reference_speed);
  law.exponent = 1.0;
  law.covariance = {1e-6, 0.0, 0.0, 1e-4};
  s.estimates.push_back({"restitution speed law", "damping_factor", chi, chi * 1e-3, "s/in"});
  return s;
}

const MaterialFit& RestitutionFit(const std::vector<MaterialFit>& fits) {
  const auto m = std::find_if(fits.begin(), fits.end(),
                              [](const MaterialFit& f) { return f.fit == "restitution"; });
  REQUIRE(m != fits.end());
  return *m;
}

TEST_CASE("material fits: of two sessions that disagree neither is named, and the pair is said") {
  const std::vector<MaterialFit> fits =
      FitMaterials({WithRestitution("a", 0.1), WithRestitution("b", 0.15)}, 0.01);
  const MaterialFit& m = RestitutionFit(fits);
  REQUIRE(m.ok);
  CHECK(m.birge_ratio > 100.0);
  CHECK(m.pulling_away.empty());
  CHECK(m.disagreeing_pairs == std::vector<std::string>{"damping_factor"});
}

TEST_CASE("material fits: with three sessions the one that disagrees is named, alone") {
  const std::vector<MaterialFit> fits = FitMaterials(
      {WithRestitution("a", 0.1), WithRestitution("b", 0.15), WithRestitution("c", 0.1)}, 0.01);
  const MaterialFit& m = RestitutionFit(fits);
  REQUIRE(m.ok);
  CHECK(m.pulling_away == std::vector<std::string>{"b"});
  CHECK(m.disagreeing_pairs.empty());
  CHECK(m.values[0] == Approx(0.1).epsilon(1e-9));
}

}  // namespace
}  // namespace impactlab
