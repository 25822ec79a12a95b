// The campaign file (docs/campaigns.md, "The campaign file").
#include <fmt/format.h>

#include "campaign/campaign.h"
#include "io/hdf5_extras.h"
#include "io/hdf5_file.h"
#include "io/result_fields_hdf5.h"

namespace impactlab {
namespace {

void WriteSession(Hdf5File& f, const Hdf5Extras& x, const std::string& g, const CampaignSession& s,
                  const UnitLabels& units) {
  f.CreateGroup(g);
  f.SetAttribute(g, "name", s.name);
  f.SetAttribute(g, "file", s.file);
  f.SetAttribute(g, "title", s.title);
  f.SetAttribute(g, "material", s.material);
  f.SetAttribute(g, "geometry", s.geometry);
  f.SetAttribute(g, "original_units", s.original_units);
  if (!s.specimen.empty()) WriteFields(f, x, g + "/specimen", s.specimen, units);

  std::vector<std::string> source, name, unit;
  std::vector<double> value, sigma;
  for (const SessionEstimate& e : s.estimates) {
    source.push_back(e.source), name.push_back(e.name), unit.push_back(e.unit);
    value.push_back(e.value), sigma.push_back(e.sigma);
  }
  f.CreateGroup(g + "/estimates");
  f.WriteStrings(g + "/estimates/source", source);
  f.WriteStrings(g + "/estimates/parameter", name);
  f.WriteVector(g + "/estimates/value", value, "");
  f.WriteVector(g + "/estimates/std_error", sigma, "");
  f.WriteStrings(g + "/estimates/unit", unit);

  std::vector<std::string> runs;
  std::vector<double> speed, e, e_sigma;
  for (const ImpactRestitution& r : s.restitution) {
    runs.push_back(r.run), speed.push_back(r.speed);
    e.push_back(r.restitution), e_sigma.push_back(r.restitution_sigma);
  }
  f.CreateGroup(g + "/restitution");
  f.WriteStrings(g + "/restitution/run", runs);
  f.WriteVector(g + "/restitution/impact_speed", speed, units.speed);
  f.WriteVector(g + "/restitution/restitution", e, "1");
  f.WriteVector(g + "/restitution/restitution_std_error", e_sigma, "1");

  runs.clear(), speed.clear();
  std::vector<double> tau, tau_sigma;
  for (const ContactTimeAtSpeed& c : s.contact_times) {
    runs.push_back(c.run), speed.push_back(c.speed);
    tau.push_back(c.contact_time), tau_sigma.push_back(c.contact_time_sigma);
  }
  f.CreateGroup(g + "/contact_times");
  f.WriteStrings(g + "/contact_times/run", runs);
  f.WriteVector(g + "/contact_times/impact_speed", speed, units.speed);
  f.WriteVector(g + "/contact_times/contact_time", tau, "s");
  f.WriteVector(g + "/contact_times/contact_time_std_error", tau_sigma, "s");
  // Its restitution speed law: the estimates hold chi and beta; here the
  // covariance the material's fit takes, and how well the law fits.
  const SessionRestitutionLaw& law = s.restitution_law;
  const std::string h = g + "/restitution_law";
  f.CreateGroup(h);
  f.SetAttribute(h, "status", law.ok ? std::string("ok") : "failed: " + law.reason);
  f.SetAttribute(h, "impacts", static_cast<long long>(law.impacts));
  if (law.ok) {
    f.WriteScalar(g + "/restitution_reference_speed", s.reference_speed, units.speed);
    x.WriteMatrix(h + "/covariance", 2, 2, law.covariance, "1");
    x.SetStringsAttribute(h + "/covariance", "parameter_names",
                          {"log damping_factor", "speed_exponent"});
    f.WriteScalar(h + "/chi2", law.chi2, "1");
    f.SetAttribute(h, "dof", static_cast<long long>(law.dof));
  }
}

void WriteFit(Hdf5File& f, const Hdf5Extras& x, const std::string& g, const MaterialFit& m,
              const UnitLabels& units) {
  f.CreateGroup(g);
  f.SetAttribute(g, "material", m.material);
  f.SetAttribute(g, "fit", m.fit);
  f.SetAttribute(g, "status", m.ok ? std::string("ok") : "failed: " + m.reason);
  f.WriteStrings(g + "/constants", m.constants);
  f.WriteStrings(g + "/units", m.units);
  f.WriteStrings(g + "/sessions", m.sessions);
  if (!m.ok) return;
  f.WriteVector(g + "/value", m.values, "");
  f.WriteVector(g + "/std_error", m.sigma, "");
  f.WriteVector(g + "/std_error_scaled", m.sigma_scaled, "");
  const std::size_t p = m.parameters.size();
  x.WriteMatrix(g + "/covariance", p, p, m.covariance, "1");
  x.SetStringsAttribute(g + "/covariance", "parameter_names", m.parameters);
  f.WriteScalar(g + "/chi2", m.chi2, "1");
  f.SetAttribute(g, "dof", static_cast<long long>(m.dof));
  f.WriteScalar(g + "/birge_ratio", m.birge_ratio, "1");
  f.WriteScalar(g + "/chi2_p_value", m.p_value, "1");
  f.WriteScalar(g + "/pull_threshold", m.pull_threshold, "1");
  if (m.fit == "restitution") f.WriteScalar(g + "/reference_speed", m.reference_speed, units.speed);
  f.CreateGroup(g + "/pulls");
  f.WriteStrings(g + "/pulls/session", m.pull_session);
  f.WriteStrings(g + "/pulls/constant", m.pull_constant);
  f.WriteVector(g + "/pulls/pull", m.pull, "1");
  f.WriteStrings(g + "/pulling_away", m.pulling_away);
  f.WriteStrings(g + "/disagreeing_pairs", m.disagreeing_pairs);
}

}  // namespace

void WriteCampaign(const Campaign& campaign, const std::filesystem::path& path) {
  WriteHdf5Atomically(path, [&](Hdf5File& f) {
    const Hdf5Extras x(f);
    const UnitLabels units = LabelsFor(campaign.units);
    f.SetAttribute("/", "kind", std::string("impactlab campaign"));
    f.SetAttribute("/", "campaign_layout", 1LL);
    f.SetAttribute("/", "units", std::string(UnitSystemName(campaign.units)));
    f.SetAttribute("/", "producer", campaign.producer);
    f.SetAttribute("/", "created", campaign.created);
    f.WriteStrings("/inputs", campaign.inputs);
    std::vector<std::string> input, reason;
    for (const CampaignFailure& failure : campaign.failures) {
      input.push_back(failure.input), reason.push_back(failure.reason);
    }
    f.CreateGroup("/failures");
    f.WriteStrings("/failures/input", input);
    f.WriteStrings("/failures/reason", reason);
    f.CreateGroup("/sessions");
    for (std::size_t i = 0; i < campaign.sessions.size(); ++i) {
      WriteSession(f, x, fmt::format("/sessions/{}", i), campaign.sessions[i], units);
    }
    f.CreateGroup("/materials");
    for (std::size_t i = 0; i < campaign.fits.size(); ++i) {
      WriteFit(f, x, fmt::format("/materials/{}", i), campaign.fits[i], units);
    }
  });
}

}  // namespace impactlab
