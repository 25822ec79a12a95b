// A campaign of sessions drawn with known constants (synth/law_session.h):
// every session's bars are of one material (E*, chi) with spherical ends of
// its own radius and its own pendulum; two sessions are drawn with a shifted
// constant. Each is typed in, reduced and written like any results file;
// the campaign recovers the material's constants and names exactly the
// shifted sessions as pulling away (restitution's speed law: the one whose
// chi, so whose e, is shifted). Inputs it cannot read fail alone, and
// the file holds no NaN.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "campaign/campaign.h"
#include "fit/effective_modulus.h"
#include "io/hdf5_file.h"
#include "io/manifest.h"
#include "model/power_law_contact.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "synth/law_session.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

constexpr double kGravity = 385.644;
constexpr double kEffectiveModulus = 1.6e7;  // psi
constexpr double kChi = 1.5;                 // s/in

struct Drawn {
  std::string name;
  double sphere_radius = 1.0, weight = 2.23, modulus = kEffectiveModulus, chi = kChi;
  std::string material = "steel";
};

// A session typed in from runs drawn under Hunt-Crossley with k from E* and R.
std::string Manifest(const Drawn& d, std::uint64_t seed) {
  const Pendulum pendulum{22.0, kGravity};
  const double k = HertzStiffnessOfSpheres(d.modulus, d.sphere_radius);
  const HuntCrossley law{d.weight / kGravity, k, 1.5, d.chi};
  LawSessionOptions draw;
  draw.xmax_sigma = 2e-4;
  draw.seed = seed;
  std::string text = fmt::format(
      "format = 1\ntitle = \"{}\"\nunits = \"in-lbf-s\"\n\n[apparatus]\npendulum_length = 22.0\n"
      "weight = {}\ngravity = {}\n\n[products]\njoint_fits = false\nintervals = false\n"
      "leave_one_out = false\n[products.contact_laws]\nkelvin_voigt = false\n"
      "hunt_crossley_n = false\nhertz_damper = false\n",
      d.name, d.weight, kGravity);
  if (!d.material.empty()) {
    text += fmt::format(
        "\n[specimen]\nmaterial = \"{}\"\nend_shape = \"sphere\"\nsphere_radius = {}\n"
        "modulus = 29e6\npoisson_ratio = 0.29\n",
        d.material, d.sphere_radius);
  }
  text += LawSessionRunsToml(DrawLawSession(pendulum, HuntCrossleyContactLaw(law), draw));
  return text;
}

// The session reduced into dir/<name>.h5.
fs::path Reduced(const fs::path& dir, const Drawn& d, std::uint64_t seed) {
  fs::create_directories(dir / d.name);
  std::ofstream(dir / d.name / "session.toml") << Manifest(d, seed);
  const SessionResult result = ReduceSession(ReadManifest(dir / d.name).session, {});
  WriteResults(result, dir / (d.name + ".h5"));
  return dir / (d.name + ".h5");
}

const MaterialFit* FitOf(const Campaign& c, const std::string& material, const std::string& fit) {
  for (const MaterialFit& m : c.fits) {
    if (m.material == material && m.fit == fit) return &m;
  }
  return nullptr;
}

// Every number the file holds, dataset by dataset.
void CheckNoNan(const Hdf5File& f, const std::string& group) {
  for (const std::string& child : f.Children(group)) {
    const std::string path = group == "/" ? "/" + child : group + "/" + child;
    if (f.IsGroup(path)) {
      CheckNoNan(f, path);
    } else if (f.IsNumericDataset(path)) {
      for (double v : f.ReadVector(path)) {
        INFO(path);
        CHECK(std::isfinite(v));
      }
    }
  }
}

TEST_CASE("campaign: a material's constants are recovered and the shifted sessions pull away") {
  testing::TempDir dir;
  std::vector<Drawn> drawn = {{"s1", 1.0},      {"s2", 2.0, 2.0}, {"s3", 4.0}, {"s4", 0.5},
                              {"s5", 1.5, 2.5}, {"s6", 3.0},      {"s7", 2.0}, {"s8", 1.0, 2.23}};
  drawn.push_back({"chi_off", 2.0, 2.23, kEffectiveModulus, 1.3 * kChi});
  drawn.push_back({"modulus_off", 1.0, 2.23, 1.4 * kEffectiveModulus, kChi});
  drawn.push_back({"unnamed", 1.0, 2.23, kEffectiveModulus, kChi, ""});
  std::vector<fs::path> inputs;
  for (std::size_t i = 0; i < drawn.size(); ++i)
    inputs.push_back(Reduced(dir.path(), drawn[i], 31 + i));

  const Campaign campaign = MakeCampaign(inputs, {});
  CHECK(campaign.failures.empty());
  REQUIRE(campaign.sessions.size() == drawn.size());
  CHECK(campaign.sessions.back().material == kMaterialNotGiven);  // grouped last
  CHECK(campaign.sessions.back().name == "unnamed");

  const MaterialFit* hc = FitOf(campaign, "steel", "hunt-crossley");
  REQUIRE(hc != nullptr);
  REQUIRE(hc->ok);
  REQUIRE(hc->constants == std::vector<std::string>{"effective_modulus", "damping_factor"});
  std::vector<std::string> away = hc->pulling_away;
  std::sort(away.begin(), away.end());
  CHECK(away == std::vector<std::string>{"chi_off", "modulus_off"});
  INFO("E* " << hc->values[0] << " +- " << hc->sigma[0] << ", chi " << hc->values[1] << " +- "
             << hc->sigma[1] << ", Birge " << hc->birge_ratio);
  CHECK(std::abs(hc->values[0] - kEffectiveModulus) < 4.0 * hc->sigma_scaled[0]);
  CHECK(std::abs(hc->values[1] - kChi) < 4.0 * hc->sigma_scaled[1]);
  CHECK(hc->birge_ratio < 2.0);
  // Each session's own E* is the one k = (8/3) E* sqrt(R) makes.
  for (const CampaignSession& s : campaign.sessions) {
    if (s.material != "steel") continue;
    for (const SessionEstimate& e : s.estimates) {
      if (e.source == "hunt-crossley" && e.name == "handbook_effective_modulus") {
        CHECK(e.value == Approx(29e6 / (2.0 * (1.0 - 0.29 * 0.29))));
      }
    }
  }

  // Restitution's speed law: Hunt-Crossley's e(chi u) (beta = 1) across the
  // sessions' speeds; only the session drawn with another chi restitutes
  // differently (E* leaves e alone).
  const MaterialFit* law = FitOf(campaign, "steel", "restitution");
  REQUIRE(law != nullptr);
  REQUIRE(law->ok);
  REQUIRE(law->constants == std::vector<std::string>{"damping_factor", "speed_exponent"});
  CHECK(law->pulling_away == std::vector<std::string>{"chi_off"});
  INFO("chi " << law->values[0] << " +- " << law->sigma[0] << ", beta " << law->values[1] << " +- "
              << law->sigma[1] << ", Birge " << law->birge_ratio);
  CHECK(std::abs(law->values[0] - kChi) < 4.0 * law->sigma_scaled[0]);
  CHECK(std::abs(law->values[1] - 1.0) < 4.0 * law->sigma_scaled[1]);
  CHECK(law->birge_ratio < 2.0);

  WriteCampaign(campaign, dir.path() / "campaign.h5");
  const Hdf5File f = Hdf5File::OpenReadOnly(dir.path() / "campaign.h5");
  CHECK(f.ReadStringAttribute("/", "kind") == "impactlab campaign");
  CheckNoNan(f, "/");
}

TEST_CASE("campaign: an input it cannot read fails alone, with its file and reason") {
  testing::TempDir dir;
  const fs::path good = Reduced(dir.path(), {"good", 2.0}, 7);
  const fs::path other = Reduced(dir.path(), {"other", 1.0}, 8);
  std::ofstream(dir.path() / "notes.h5") << "not an HDF5 file";
  const Campaign campaign =
      MakeCampaign({good, dir.path() / "notes.h5", dir.path() / "missing.h5", other}, {});
  REQUIRE(campaign.failures.size() == 2);
  CHECK(campaign.failures[0].input == (dir.path() / "notes.h5").string());
  CHECK_THAT(campaign.failures[0].reason, Catch::Matchers::Contains("notes.h5"));
  CHECK(campaign.failures[1].input == (dir.path() / "missing.h5").string());
  CHECK(campaign.sessions.size() == 2);
  CHECK(campaign.inputs.size() == 4);
}

TEST_CASE("campaign: a session folder is reduced first, and its unchanged results reused") {
  testing::TempDir dir;
  const Drawn d{"folder", 2.0};
  fs::create_directories(dir.path() / d.name);
  std::ofstream(dir.path() / d.name / "session.toml") << Manifest(d, 5);
  const fs::path other = Reduced(dir.path(), {"file", 1.0}, 6);
  CampaignOptions options;
  options.reduced_folder = dir.path() / "reduced";
  const Campaign campaign = MakeCampaign({dir.path() / d.name, other}, options);
  CHECK(campaign.failures.empty());
  REQUIRE(campaign.sessions.size() == 2);
  CHECK(fs::exists(dir.path() / "reduced" / "folder.h5"));
  CHECK(ReadResults(dir.path() / "reduced" / "folder.h5").specimen.sphere_radius == 2.0);
}

}  // namespace
}  // namespace impactlab
