#include "synth/campaign.h"

#include "fit/effective_modulus.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "io/errors.h"
#include "io/units.h"
#include "model/power_law_contact.h"

namespace impactlab {
namespace {

// A number as a person writes it down: to `digits` significant digits.
double WrittenDown(double value, int digits) {
  return std::stod(fmt::format("{:.{}g}", value, digits));
}

double CampaignLogUniform(std::mt19937_64& rng, double low, double high) {
  return std::exp(std::uniform_real_distribution<double>(std::log(low), std::log(high))(rng));
}

// X0s spread log-uniformly from 0.1 in to 7 % of the pendulum's length (at
// most 1.5 in), written to 0.001 in and distinct (each is also its run's id).
std::vector<double> DrawInitialDisplacements(std::mt19937_64& rng, int runs, double length) {
  const double high = std::min(1.5, 0.07 * length);
  std::vector<double> x0s;
  for (int i = 0; i < runs; ++i)
    x0s.push_back(std::round(1e3 * CampaignLogUniform(rng, 0.1, high)) / 1e3);
  std::sort(x0s.begin(), x0s.end());
  for (std::size_t i = 1; i < x0s.size(); ++i) {
    if (x0s[i] <= x0s[i - 1]) x0s[i] = x0s[i - 1] + 1e-3;
  }
  return x0s;
}

// Which sessions disagree, and in what: a shuffled choice of
// round(fraction x sessions), chi then E* in turn.
std::vector<std::optional<CampaignDisagreement>> DrawDisagreements(std::mt19937_64& rng,
                                                                   const DrawnCampaignOptions& options) {
  std::vector<std::optional<CampaignDisagreement>> out(static_cast<std::size_t>(options.sessions));
  std::vector<std::size_t> order(out.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  const auto count = static_cast<std::size_t>(
      std::lround(options.disagreeing_fraction * static_cast<double>(options.sessions)));
  for (std::size_t i = 0; i < count; ++i) {
    out[order[i]] = CampaignDisagreement{i % 2 == 0 ? "damping_factor" : "effective_modulus",
                                         options.disagreement_factor};
  }
  return out;
}

DrawnCampaignSession DrawCampaignSession(std::mt19937_64& rng, const DrawnCampaignOptions& options, int index,
                                    const std::optional<CampaignDisagreement>& disagreement) {
  DrawnCampaignSession s;
  // Materials in turn, so every one is in a campaign of as many sessions.
  s.material = static_cast<std::size_t>(index) % options.materials.size();
  const CampaignMaterial& material = options.materials[s.material];
  const bool sphere = std::uniform_real_distribution<double>(0.0, 1.0)(rng) < 0.7;

  // The bars: a cylinder of the material with spherical ends of their own radius.
  s.specimen.material = material.name;
  s.specimen.end_shape = sphere ? "sphere" : "given_stiffness";
  s.specimen.bar_diameter =
      std::round(4.0 * std::uniform_real_distribution<double>(0.75, 1.5)(rng)) / 4.0;
  s.specimen.bar_length = std::round(std::uniform_real_distribution<double>(4.0, 10.0)(rng));
  s.specimen.modulus = material.modulus;
  s.specimen.poisson_ratio = material.poisson_ratio;
  s.sphere_radius = std::round(100.0 * CampaignLogUniform(rng, 0.5, 3.0)) / 100.0;
  s.gravity = StandardGravity(UnitSystem::kInLbfS);  // what the reader assumes
  s.weight =
      WrittenDown(material.weight_density * std::numbers::pi / 4.0 * *s.specimen.bar_diameter *
                      *s.specimen.bar_diameter * *s.specimen.bar_length,
                  4);
  s.pendulum_length =
      std::round(100.0 * std::uniform_real_distribution<double>(15.0, 40.0)(rng)) / 100.0;

  const double effective_modulus = EffectiveModulus(material.modulus, material.poisson_ratio);
  s.stiffness_of_material = HertzStiffnessOfSpheres(effective_modulus, s.sphere_radius);
  if (sphere) {
    s.specimen.sphere_radius = s.sphere_radius;
  } else {
    // Given as a person writes it down; that number is the truth's too.
    s.stiffness_of_material = WrittenDown(s.stiffness_of_material, 4);
    s.specimen.contact_stiffness = s.stiffness_of_material;
  }
  s.stiffness = s.stiffness_of_material;
  s.damping_factor = material.damping_factor;
  s.disagreement = disagreement;
  if (disagreement) {
    // k is proportional to E*: a shifted modulus shifts k by the same factor.
    (disagreement->parameter == "damping_factor" ? s.damping_factor : s.stiffness) *=
        disagreement->factor;
  }

  s.xmax_sigma = WrittenDown(CampaignLogUniform(rng, 2e-4, 8e-4), 2);
  s.contact_time_sigma = WrittenDown(CampaignLogUniform(rng, 1e-6, 4e-6), 2);
  LawSessionOptions draw;
  draw.initial_displacements = DrawInitialDisplacements(rng, options.runs, s.pendulum_length);
  draw.xmax_sigma = s.xmax_sigma;
  draw.contact_time_sigma = s.contact_time_sigma;
  draw.seed = rng();
  const HuntCrossley law{s.Mass(), s.stiffness, 1.5, s.damping_factor};
  s.runs =
      DrawLawSession(Pendulum{s.pendulum_length, s.gravity}, HuntCrossleyContactLaw(law), draw);
  for (LawSessionRun& run : s.runs) {
    for (double& x : run.xmax) x = WrittenDown(x, 6);
    run.contact_time = WrittenDown(run.contact_time, 6);
  }
  s.name = fmt::format("{:03d}-{}-{}", index + 1, material.name, sphere ? "sphere" : "given");
  return s;
}

nlohmann::json SpecimenJson(Specimen specimen) {
  nlohmann::json out = nlohmann::json::object();
  struct Insert {
    nlohmann::json& out;
    void operator()(const char* name, IfAnyField<std::string> text, Quantity, const char*) const {
      if (!text.field.empty()) out[name] = text.field;
    }
    void operator()(const char* name, const std::optional<double>& number, Quantity,
                    const char*) const {
      if (number) out[name] = *number;
    }
  };
  Specimen::VisitFields(specimen, Insert{out});
  return out;
}

}  // namespace

std::vector<CampaignMaterial> DefaultCampaignMaterials() {
  return {{"steel", 30.0e6, 0.29, 0.08, 0.284},
          {"aluminium", 10.0e6, 0.33, 0.20, 0.0975},
          {"brass", 15.0e6, 0.34, 0.12, 0.307}};
}

double EffectiveModulus(double modulus, double poisson_ratio) {
  return modulus / (2.0 * (1.0 - poisson_ratio * poisson_ratio));
}

DrawnCampaign DrawCampaign(const DrawnCampaignOptions& options) {
  if (options.materials.empty()) throw std::invalid_argument("a campaign needs a material");
  if (options.sessions < 1 || options.runs < 1) {
    throw std::invalid_argument("a campaign needs at least one session of one run");
  }
  if (!(options.disagreeing_fraction >= 0.0 && options.disagreeing_fraction <= 1.0)) {
    throw std::invalid_argument("the disagreeing fraction must be within [0, 1]");
  }
  if (!(options.disagreement_factor > 0.0)) {
    throw std::invalid_argument("the disagreement factor must be positive");
  }
  DrawnCampaign campaign{options, {}};
  // One stream: the disagreements first, then each session's draws in turn.
  std::mt19937_64 rng(options.seed);
  const auto disagreements = DrawDisagreements(rng, options);
  for (int i = 0; i < options.sessions; ++i) {
    campaign.sessions.push_back(
        DrawCampaignSession(rng, options, i, disagreements[static_cast<std::size_t>(i)]));
  }
  return campaign;
}

SessionManifest CampaignSessionManifest(const DrawnCampaignSession& session) {
  SessionManifest manifest;
  manifest.comment = {"A generated campaign's session (impactlab synth-campaign): typed-in maxima",
                      "and contact times drawn under Hunt-Crossley; truth in campaign.truth.json."};
  manifest.title = fmt::format("{}: {} bars, {} ends", session.name, session.specimen.material,
                               session.specimen.end_shape);
  manifest.apparatus = ManifestApparatus{session.pendulum_length, session.weight};
  manifest.specimen = session.specimen;
  for (const LawSessionRun& drawn : session.runs) {
    Run run;
    run.id = fmt::format("{:.3f}", drawn.initial_displacement);
    run.initial_displacement = drawn.initial_displacement;
    run.rebounds = drawn.xmax;
    run.rebound_uncertainty = session.xmax_sigma;
    run.contact_time = drawn.contact_time;
    run.contact_time_uncertainty = session.contact_time_sigma;
    manifest.runs.push_back(std::move(run));
  }
  return manifest;
}

nlohmann::json CampaignTruth(const DrawnCampaign& campaign) {
  const DrawnCampaignOptions& options = campaign.options;
  nlohmann::json truth{{"schema", "impactlab-campaign-truth"},
                       {"version", 1},
                       {"seed", options.seed},
                       {"units", "in-lbf-s"},
                       {"contact_law", "hunt-crossley"},
                       {"exponent", 1.5},
                       {"relations",
                        {{"effective_modulus", "1/E* = 2 (1 - nu^2)/E"},
                         {"effective_radius", "R_eff = R/2"},
                         {"hertz_stiffness", "k = (4/3) E* sqrt(R_eff)"}}},
                       {"options",
                        {{"sessions", options.sessions},
                         {"runs", options.runs},
                         {"disagreeing_fraction", options.disagreeing_fraction},
                         {"disagreement_factor", options.disagreement_factor}}}};
  nlohmann::json& materials = truth["materials"] = nlohmann::json::array();
  for (const CampaignMaterial& m : options.materials) {
    materials.push_back({{"name", m.name},
                         {"modulus", m.modulus},
                         {"poisson_ratio", m.poisson_ratio},
                         {"effective_modulus", EffectiveModulus(m.modulus, m.poisson_ratio)},
                         {"damping_factor", m.damping_factor},
                         {"weight_density", m.weight_density}});
  }
  nlohmann::json& sessions = truth["sessions"] = nlohmann::json::array();
  for (const DrawnCampaignSession& s : campaign.sessions) {
    const CampaignMaterial& m = options.materials[s.material];
    nlohmann::json entry{{"name", s.name},
                         {"material", m.name},
                         {"end_shape", s.specimen.end_shape},
                         {"specimen", SpecimenJson(s.specimen)},
                         {"pendulum_length", s.pendulum_length},
                         {"weight", s.weight},
                         {"gravity", s.gravity},
                         {"mass", s.Mass()},
                         {"sphere_radius", s.sphere_radius},
                         {"effective_radius", s.sphere_radius / 2.0},
                         {"stiffness_of_material", s.stiffness_of_material},
                         {"stiffness", s.stiffness},
                         {"damping_factor", s.damping_factor},
                         {"xmax_sigma", s.xmax_sigma},
                         {"contact_time_sigma", s.contact_time_sigma},
                         {"disagreement", nullptr}};
    if (s.disagreement) {
      const bool chi = s.disagreement->parameter == "damping_factor";
      const double shared = chi ? m.damping_factor : EffectiveModulus(m.modulus, m.poisson_ratio);
      entry["disagreement"] = {{"parameter", s.disagreement->parameter},
                               {"factor", s.disagreement->factor},
                               {"of_material", shared},
                               {"of_session", shared * s.disagreement->factor}};
    }
    nlohmann::json& runs = entry["runs"] = nlohmann::json::array();
    for (const LawSessionRun& r : s.runs) {
      runs.push_back({{"id", fmt::format("{:.3f}", r.initial_displacement)},
                      {"initial_displacement", r.initial_displacement},
                      {"xmax", r.true_xmax},
                      {"contact_time", r.true_contact_time},
                      {"contact_rebound", r.contact_rebound}});
    }
    sessions.push_back(std::move(entry));
  }
  return truth;
}

void WriteCampaign(const std::filesystem::path& dir, const DrawnCampaign& campaign) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir) && !fs::is_empty(dir, ec)) {
    throw InputError({dir, "", std::nullopt}, "the output folder exists and is not empty");
  }
  for (const DrawnCampaignSession& session : campaign.sessions) {
    fs::create_directories(dir / session.name, ec);
    if (ec) throw InputError({dir / session.name, "", std::nullopt}, "cannot create the folder");
    WriteManifest(dir / session.name / "session.toml", CampaignSessionManifest(session));
  }
  const fs::path truth = dir / "campaign.truth.json";
  std::ofstream out(truth);
  out << CampaignTruth(campaign).dump(1) << "\n";
  if (!out) throw InputError({truth, "", std::nullopt}, "cannot write the truth file");
}

}  // namespace impactlab
