// The constants a material's sessions share (docs/campaigns.md, "Joint fits").
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

#include "campaign/campaign_internal.h"
#include "campaign/shared_fit.h"

namespace impactlab {
namespace {

// How a fit's constants are held: as logarithms (positive constants) or as they are.
struct ConstantSpec {
  std::string name;
  std::string unit;
  bool logarithm = true;
};

// A statement the fit can weigh: finite, with positive variances (a session
// whose fit left a direction undetermined states nothing there).
bool Usable(const SessionStatement& s) {
  const std::size_t d = s.values.size();
  for (double v : s.values) {
    if (!std::isfinite(v)) return false;
  }
  for (double c : s.covariance) {
    if (!std::isfinite(c)) return false;
  }
  for (std::size_t i = 0; i < d; ++i) {
    if (!(s.covariance[i * d + i] > 0.0)) return false;
  }
  return true;
}

MaterialFit Summarise(const std::string& material, const std::string& fit_name,
                      const std::vector<ConstantSpec>& specs,
                      std::vector<SessionStatement> statements, double false_alarm) {
  std::erase_if(statements, [](const SessionStatement& s) { return !Usable(s); });
  MaterialFit out;
  out.material = material;
  out.fit = fit_name;
  for (const ConstantSpec& c : specs) {
    out.constants.push_back(c.name);
    out.units.push_back(c.unit);
    out.parameters.push_back(c.logarithm ? "log " + c.name : c.name);
  }
  for (const SessionStatement& s : statements) out.sessions.push_back(s.session);
  std::size_t stated = 0;
  for (const SessionStatement& s : statements) stated += s.values.size();
  out.pull_threshold = PullThreshold(stated, false_alarm);
  SharedFit fit;
  try {
    fit = FitSharedConstants(statements, static_cast<int>(specs.size()), out.pull_threshold);
  } catch (const std::invalid_argument& error) {
    fit.reason = error.what();
  }
  out.ok = fit.ok;
  out.reason = fit.reason;
  if (!fit.ok) return out;
  const double scale = std::max(1.0, fit.birge_ratio);
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const double value = specs[i].logarithm ? std::exp(fit.values[i]) : fit.values[i];
    const double sigma = specs[i].logarithm ? value * fit.sigma[i] : fit.sigma[i];
    out.values.push_back(value);
    out.sigma.push_back(sigma);
    out.sigma_scaled.push_back(sigma * scale);
  }
  out.covariance = fit.covariance;
  out.chi2 = fit.chi2;
  out.dof = fit.dof;
  out.birge_ratio = fit.birge_ratio;
  out.p_value = fit.p_value;
  // A pull names its session only where at least two others state the same
  // constant: measured against one other session alone, two that disagree
  // pull equally far apart, and which of them is off cannot be told.
  std::vector<int> stating(specs.size(), 0);
  for (const SessionStatement& s : statements) {
    for (int c : std::set<int>(s.constants.begin(), s.constants.end())) ++stating[c];
  }
  std::set<std::string> away(fit.set_aside.begin(), fit.set_aside.end());
  std::set<std::string> undecided;
  for (std::size_t i = 0; i < fit.pull.size(); ++i) {
    const auto constant = static_cast<std::size_t>(fit.pull_constant[i]);
    out.pull_session.push_back(fit.pull_session[i]);
    out.pull_constant.push_back(specs[constant].name);
    out.pull.push_back(fit.pull[i]);
    if (std::abs(fit.pull[i]) <= out.pull_threshold) continue;
    if (stating[constant] >= 3) {
      away.insert(fit.pull_session[i]);
    } else {
      undecided.insert(specs[constant].name);
    }
  }
  for (const std::string& s : out.sessions) {
    if (away.contains(s)) out.pulling_away.push_back(s);
  }
  out.disagreeing_pairs.assign(undecided.begin(), undecided.end());
  return out;
}

const SessionContactLaw* LawOf(const CampaignSession& s, const std::string& law) {
  const auto it = std::find_if(s.laws.begin(), s.laws.end(),
                               [&](const SessionContactLaw& l) { return l.law == law; });
  return it == s.laws.end() ? nullptr : &*it;
}

const SessionEstimate* EstimateOf(const CampaignSession& s, const std::string& source,
                                  const std::string& name) {
  const auto it =
      std::find_if(s.estimates.begin(), s.estimates.end(),
                   [&](const SessionEstimate& e) { return e.source == source && e.name == name; });
  return it == s.estimates.end() ? nullptr : &*it;
}

std::string EstimateUnit(const CampaignSession& s, const std::string& source,
                         const std::string& name) {
  const SessionEstimate* e = EstimateOf(s, source, name);
  return e ? e->unit : "";
}

// Hunt-Crossley: ln E* and ln chi, from every session's (ln k, ln chi) with
// their covariance; a session whose ends leave E* unidentifiable states chi
// alone. Where no session makes E* identifiable, chi is fitted alone.
std::optional<MaterialFit> FitHuntCrossley(const std::string& material,
                                           const std::vector<const CampaignSession*>& sessions,
                                           double false_alarm) {
  std::vector<const CampaignSession*> with;
  bool modulus = false;
  for (const CampaignSession* s : sessions) {
    if (const SessionContactLaw* law = LawOf(*s, "hunt-crossley")) {
      with.push_back(s);
      modulus = modulus || law->modulus_per_k > 0.0;
    }
  }
  if (with.empty()) return std::nullopt;
  std::vector<ConstantSpec> specs;
  if (modulus) {
    specs.push_back(
        {"effective_modulus", EstimateUnit(*with.front(), "hunt-crossley", "effective_modulus")});
  }
  specs.push_back(
      {"damping_factor", EstimateUnit(*with.front(), "hunt-crossley", "damping_factor")});
  for (const CampaignSession* s : with) {
    if (modulus && LawOf(*s, "hunt-crossley")->modulus_per_k > 0.0) {
      specs.front().unit = EstimateUnit(*s, "hunt-crossley", "effective_modulus");
      break;
    }
  }
  const int p = static_cast<int>(specs.size());
  std::vector<SessionStatement> statements;
  for (const CampaignSession* s : with) {
    const SessionContactLaw& law = *LawOf(*s, "hunt-crossley");
    const std::vector<double>& c = law.log_covariance;  // (ln k, ln chi)
    SessionStatement st;
    st.session = s->name;
    if (modulus && law.modulus_per_k > 0.0) {
      st.values = {std::log(law.modulus_per_k * law.hertz_stiffness), std::log(law.damping_factor)};
      st.covariance = c;
      st.design = {1, 0, 0, 1};
      st.constants = {0, 1};
    } else {
      st.values = {std::log(law.damping_factor)};
      st.covariance = {c.at(3)};
      st.design = p == 2 ? std::vector<double>{0, 1} : std::vector<double>{1};
      st.constants = {p - 1};
    }
    statements.push_back(std::move(st));
  }
  return Summarise(material, "hunt-crossley", specs, statements, false_alarm);
}

// Hertz: ln E* from the sessions whose ends make it identifiable.
std::optional<MaterialFit> FitHertz(const std::string& material,
                                    const std::vector<const CampaignSession*>& sessions,
                                    double false_alarm) {
  std::vector<SessionStatement> statements;
  std::string unit;
  for (const CampaignSession* s : sessions) {
    const SessionContactLaw* law = LawOf(*s, "hertz");
    if (law == nullptr || law->modulus_per_k <= 0.0) continue;
    statements.push_back({s->name,
                          {std::log(law->modulus_per_k * law->hertz_stiffness)},
                          {law->log_covariance.at(0)},
                          {1},
                          {0}});
    unit = EstimateUnit(*s, "hertz", "effective_modulus");
  }
  if (statements.empty()) return std::nullopt;
  return Summarise(material, "hertz", {{"effective_modulus", unit}}, statements, false_alarm);
}

// Restitution's speed law e(u) = E(chi u0 (u/u0)^beta) (campaign/
// restitution_law.h), from each session's own fit of it to its impacts: its
// ln eps at its own reference speed u_i states ln chi + ln u0 + beta ln(u_i/u0),
// and its beta states beta, with their covariance. u0 is the geometric mean
// of the sessions' u_i. The law holds across speeds, so sessions at different
// speeds state the same constants (a line in u, the sessions' linear-in-speed
// model, would not: its slope is the curve's local one).
std::optional<MaterialFit> FitRestitution(const std::string& material,
                                          const std::vector<const CampaignSession*>& sessions,
                                          double false_alarm) {
  std::vector<const CampaignSession*> with;
  double log_u0 = 0.0;
  for (const CampaignSession* s : sessions) {
    if (!s->restitution_law.ok) continue;
    with.push_back(s);
    log_u0 += std::log(s->restitution_law.reference_speed);
  }
  if (with.empty()) return std::nullopt;
  log_u0 /= static_cast<double>(with.size());
  std::vector<SessionStatement> statements;
  for (const CampaignSession* s : with) {
    const SessionRestitutionLaw& law = s->restitution_law;
    statements.push_back({s->name,
                          {law.log_eps - log_u0, law.exponent},
                          law.covariance,
                          {1.0, std::log(law.reference_speed) - log_u0, 0.0, 1.0},
                          {0, 1}});
  }
  const std::string chi_unit =
      EstimateUnit(*with.front(), "restitution speed law", "damping_factor");
  MaterialFit fit = Summarise(material, "restitution",
                              {{"damping_factor", chi_unit, true}, {"speed_exponent", "1", false}},
                              statements, false_alarm);
  fit.reference_speed = std::exp(log_u0);
  return fit;
}

}  // namespace

std::vector<MaterialFit> FitMaterials(const std::vector<CampaignSession>& sessions,
                                      double false_alarm) {
  std::map<std::string, std::vector<const CampaignSession*>> by_material;
  for (const CampaignSession& s : sessions) {
    if (s.material != kMaterialNotGiven) by_material[s.material].push_back(&s);
  }
  std::vector<MaterialFit> fits;
  for (const auto& [material, members] : by_material) {
    for (auto fit :
         {FitHuntCrossley(material, members, false_alarm), FitHertz(material, members, false_alarm),
          FitRestitution(material, members, false_alarm)}) {
      if (fit) fits.push_back(std::move(*fit));
    }
  }
  return fits;
}

}  // namespace impactlab
