// Campaigns with known truth (synth/campaign.h): the sessions follow from
// their materials' shared constants and their own geometry, the ones made to
// disagree are shifted as the truth records, and a written session reduces
// to the Hunt-Crossley k and chi of its truth.
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "synth/campaign.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

const NamedEstimate& LawParameter(const SessionResult& result, const std::string& name) {
  for (const ContactLawFit& fit : result.contact_laws) {
    if (fit.law != "hunt-crossley") continue;
    REQUIRE(fit.ok);
    for (const NamedEstimate& p : fit.parameters) {
      if (p.name == name) return p;
    }
  }
  FAIL("no hunt-crossley " << name);
  return result.contact_laws.front().parameters.front();
}

// The session reduced from the folder WriteCampaign wrote.
SessionResult ReduceWritten(const std::filesystem::path& dir, const DrawnCampaignSession& session) {
  const ManifestReadResult manifest = ReadManifest(dir / session.name);
  REQUIRE(manifest.session.runs.size() == session.runs.size());
  return ReduceSession(manifest.session, {});
}

}  // namespace

TEST_CASE("A campaign's sessions follow from their material and geometry", "[campaign]") {
  DrawnCampaignOptions options;
  options.sessions = 30;
  options.seed = 5;
  const DrawnCampaign campaign = DrawCampaign(options);
  REQUIRE(campaign.sessions.size() == 30);
  int disagreeing = 0, spheres = 0, given = 0;
  for (const DrawnCampaignSession& s : campaign.sessions) {
    INFO(s.name);
    const CampaignMaterial& m = options.materials[s.material];
    CHECK(s.specimen.material == m.name);
    // 1/E* = 2 (1 - nu^2)/E, R_eff = R/2, F = (4/3) E* sqrt(R_eff) (2x)^(3/2)
    // in one bar's compression x: k = (8/3) E* sqrt(R).
    const double e_star = m.modulus / (2.0 * (1.0 - m.poisson_ratio * m.poisson_ratio));
    const double k = 8.0 / 3.0 * e_star * std::sqrt(s.sphere_radius);
    CHECK(s.stiffness_of_material == Approx(k).epsilon(1e-3));  // given k: 4 digits
    if (s.specimen.end_shape == "sphere") {
      ++spheres;
      CHECK(*s.specimen.sphere_radius == s.sphere_radius);
      CHECK(s.stiffness_of_material == Approx(k).epsilon(1e-14));
    } else {
      ++given;
      CHECK(*s.specimen.contact_stiffness == s.stiffness_of_material);
    }
    const double chi_factor = s.damping_factor / m.damping_factor;
    const double k_factor = s.stiffness / s.stiffness_of_material;
    if (s.disagreement) {
      ++disagreeing;
      const bool chi = s.disagreement->parameter == "damping_factor";
      CHECK(chi_factor == Approx(chi ? 1.5 : 1.0));
      CHECK(k_factor == Approx(chi ? 1.0 : 1.5));
    } else {
      CHECK(chi_factor == 1.0);
      CHECK(k_factor == 1.0);
    }
    CHECK(s.runs.size() == 6);
  }
  CHECK(disagreeing == 3);  // 1 in 10 of 30
  CHECK(spheres > 0);
  CHECK(given > 0);

  // The same seed, the same campaign, truth and all.
  CHECK(CampaignTruth(DrawCampaign(options)) == CampaignTruth(campaign));
}

TEST_CASE("A written campaign has a session folder per session and its truth", "[campaign]") {
  DrawnCampaignOptions options;
  options.sessions = 4;
  options.seed = 2;
  const DrawnCampaign campaign = DrawCampaign(options);
  testing::TempDir dir;
  WriteCampaign(dir.path(), campaign);
  std::ifstream in(dir.path() / "campaign.truth.json");
  const nlohmann::json truth = nlohmann::json::parse(in);
  CHECK(truth["schema"] == "impactlab-campaign-truth");
  REQUIRE(truth["sessions"].size() == 4);
  CHECK(truth["materials"].size() == options.materials.size());
  for (const DrawnCampaignSession& s : campaign.sessions) {
    INFO(s.name);
    std::ifstream manifest(dir.path() / s.name / "session.toml");
    std::stringstream text;
    text << manifest.rdbuf();
    CHECK(text.str().find("[specimen]") != std::string::npos);
    CHECK(text.str().find("material = \"" + s.specimen.material + "\"") != std::string::npos);
    CHECK(text.str().find("end_shape = \"" + s.specimen.end_shape + "\"") != std::string::npos);
  }
  CHECK_THROWS_AS(WriteCampaign(dir.path(), campaign), InputError);  // not empty now
}

TEST_CASE("A campaign session reduces to its truth's Hunt-Crossley k and chi", "[campaign]") {
  DrawnCampaignOptions options;
  options.sessions = 6;
  options.seed = 11;
  options.disagreeing_fraction = 0.0;
  const DrawnCampaign campaign = DrawCampaign(options);
  testing::TempDir dir;
  WriteCampaign(dir.path(), campaign);
  for (const DrawnCampaignSession& s : campaign.sessions) {
    INFO(s.name);
    const SessionResult result = ReduceWritten(dir.path(), s);
    const NamedEstimate& chi = LawParameter(result, "damping_factor");
    const NamedEstimate& k = LawParameter(result, "hertz_stiffness");
    CHECK(std::abs(chi.estimate.value - s.damping_factor) < 4.0 * chi.estimate.sigma);
    CHECK(std::abs(k.estimate.value - s.stiffness) < 4.0 * k.estimate.sigma);
  }
}

TEST_CASE("A disagreeing session's fit is shifted from its material by the recorded factor",
          "[campaign]") {
  DrawnCampaignOptions options;
  options.sessions = 4;
  options.seed = 7;
  options.disagreeing_fraction = 0.5;  // chi in one session, E* in the other
  options.disagreement_factor = 1.6;
  const DrawnCampaign campaign = DrawCampaign(options);
  testing::TempDir dir;
  WriteCampaign(dir.path(), campaign);
  std::ifstream in(dir.path() / "campaign.truth.json");
  const nlohmann::json truth = nlohmann::json::parse(in);
  int checked = 0;
  for (std::size_t i = 0; i < campaign.sessions.size(); ++i) {
    const DrawnCampaignSession& s = campaign.sessions[i];
    if (!s.disagreement) continue;
    INFO(s.name);
    const nlohmann::json& recorded = truth["sessions"][i]["disagreement"];
    REQUIRE(recorded.is_object());
    CHECK(recorded["factor"] == 1.6);
    const CampaignMaterial& m = options.materials[s.material];
    const bool on_chi = recorded["parameter"] == "damping_factor";
    const SessionResult result = ReduceWritten(dir.path(), s);
    const NamedEstimate& fitted =
        LawParameter(result, on_chi ? "damping_factor" : "hertz_stiffness");
    const double of_material = on_chi ? m.damping_factor : s.stiffness_of_material;
    // The fit finds the shifted value, many sigma from the material's.
    CHECK(std::abs(fitted.estimate.value - 1.6 * of_material) < 4.0 * fitted.estimate.sigma);
    CHECK(std::abs(fitted.estimate.value - of_material) > 10.0 * fitted.estimate.sigma);
    ++checked;
  }
  CHECK(checked == 2);
}

}  // namespace impactlab
