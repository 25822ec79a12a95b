// End to end: a session typed in from runs drawn under a Hunt-Crossley
// contact (synth/law_session.h) is reduced like any other; the contact laws
// across its runs recover the law within their stated sigmas, and the model
// comparison prefers it to every linear law.
#include <cmath>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "model/power_law_contact.h"
#include "pipeline/reduce.h"
#include "synth/law_session.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

constexpr double kGravity = 385.644, kWeight = 2.23;

// session.toml with the drawn maxima and contact times typed in.
std::string Manifest(const std::vector<LawSessionRun>& runs) {
  std::string text = fmt::format(
      "format = 1\ntitle = \"Hunt-Crossley, drawn\"\nunits = \"in-lbf-s\"\n\n[apparatus]\n"
      "pendulum_length = 22.0\nweight = {}\ngravity = {}\narrangement = \"pair\"\n",
      kWeight, kGravity);
  text += LawSessionRunsToml(runs);
  return text;
}

const NamedEstimate& Parameter(const ContactLawFit& fit, const std::string& name) {
  for (const NamedEstimate& p : fit.parameters) {
    if (p.name == name) return p;
  }
  FAIL("no " << name << " in " << fit.law);
  return fit.parameters.front();
}

}  // namespace

TEST_CASE("A Hunt-Crossley session reduces to its law, preferred over the linear ones",
          "[contact_laws]") {
  const Pendulum pendulum{22.0, kGravity};
  const HuntCrossley truth{kWeight / kGravity, 4.7e7, 1.5, 1.5};
  LawSessionOptions draw;
  draw.xmax_sigma = 2e-4;
  draw.seed = 21;
  const auto runs = DrawLawSession(pendulum, HuntCrossleyContactLaw(truth), draw);
  testing::TempDir dir;
  std::ofstream(dir.path() / "session.toml") << Manifest(runs);

  const SessionResult result = ReduceSession(ReadManifest(dir.path()).session, {});
  REQUIRE(result.contact_laws.size() == 5);
  const ContactLawFit& hc = result.contact_laws[2];
  REQUIRE(hc.law == "hunt-crossley");
  REQUIRE(hc.ok);
  INFO(hc.identifiability);
  CHECK(hc.contact_times == 6);
  const NamedEstimate& chi = Parameter(hc, "damping_factor");
  const NamedEstimate& k = Parameter(hc, "hertz_stiffness");
  CHECK(std::abs(chi.estimate.value - truth.damping_factor) < 4.0 * chi.estimate.sigma);
  CHECK(std::abs(k.estimate.value - truth.stiffness) < 4.0 * k.estimate.sigma);
  CHECK_FALSE(hc.scatter.excess);

  REQUIRE(result.model_comparison);
  CHECK(result.model_comparison->best_by_bic == "hunt-crossley");
  for (const ComparedRestitutionModel& m : result.model_comparison->restitution_models) {
    if (m.fit.name == "common") CHECK(m.verdict.rfind("rejected", 0) == 0);
  }
}

}  // namespace impactlab
