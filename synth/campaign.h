// Campaigns with known truth (`impactlab synth-campaign`, docs/synth.md):
// many sessions of several materials and end geometries, drawn from shared
// material constants, each session with its own nuisance (pendulum, bars,
// X0s, reading sigmas, noise). Every session is a folder of typed-in maxima
// and contact times drawn under Hunt-Crossley (synth/law_session.h), with
// its [specimen] in the manifest, so `impactlab reduce` reduces it.
//
// The material fixes the effective modulus of two identical bars,
// 1/E* = 2 (1 - nu^2)/E, and Hunt-Crossley's chi; the session's geometry
// fixes the effective radius of two identical spheres touching, R/2, and
// so the law's k = (4/3) E* sqrt(R/2). A few sessions are made to disagree:
// their chi or E* is multiplied by a stated factor, recorded in the truth.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "io/specimen.h"
#include "synth/law_session.h"
#include "synth/manifest_writer.h"

namespace impactlab {

// A material's handbook constants, in in-lbf-s units.
struct CampaignMaterial {
  std::string name;             // also the folder names' middle part: no spaces
  double modulus = 0.0;         // E, psi
  double poisson_ratio = 0.0;   // nu
  double damping_factor = 0.0;  // Hunt-Crossley chi, s/in
  double weight_density = 0.0;  // lbf/in^3: a bar's weight from its size
};

// Steel, aluminium and brass (moduli and densities from handbooks; chi
// chosen so that e falls from about 0.97 to 0.7 over the runs' speeds).
std::vector<CampaignMaterial> DefaultCampaignMaterials();

// 1/E* = 2 (1 - nu^2)/E: two bars of the same material.
double EffectiveModulus(double modulus, double poisson_ratio);

struct DrawnCampaignOptions {
  int sessions = 12;
  int runs = 6;  // per session, X0s spread over the pendulum's range
  std::uint64_t seed = 1;
  // Sessions made to disagree: round(fraction x sessions) of them, the
  // first with its chi multiplied by `disagreement_factor`, the next with its
  // E* (so its k), alternately.
  double disagreeing_fraction = 0.1;
  double disagreement_factor = 1.5;
  std::vector<CampaignMaterial> materials = DefaultCampaignMaterials();
};

// What a disagreeing session's truth departs from its material by.
struct CampaignDisagreement {
  std::string parameter;  // "damping_factor" or "effective_modulus"
  double factor = 1.0;
};

struct DrawnCampaignSession {
  std::string name;          // its folder: "007-brass-sphere"
  std::size_t material = 0;  // index into DrawnCampaignOptions::materials
  Specimen specimen;         // what its manifest says (geometry, handbook E and nu)
  double pendulum_length = 0.0, weight = 0.0, gravity = 0.0;  // in, lbf, in/s^2
  // The spheres' radius; for given_stiffness ends, the radius behind the
  // written k (the manifest gives only k).
  double sphere_radius = 0.0;
  double stiffness_of_material = 0.0;                 // k from the material and the geometry
  double stiffness = 0.0, damping_factor = 0.0;       // the law drawn from (after any shift)
  double xmax_sigma = 0.0, contact_time_sigma = 0.0;  // as written in the manifest
  std::optional<CampaignDisagreement> disagreement;
  std::vector<LawSessionRun> runs;  // exact values, and the readings with their errors
  double Mass() const { return weight / gravity; }
};

struct DrawnCampaign {
  DrawnCampaignOptions options;
  std::vector<DrawnCampaignSession> sessions;
};

// Draws every session. Throws std::invalid_argument for options out of range
// (no material, sessions or runs < 1, fraction outside [0, 1], factor <= 0).
DrawnCampaign DrawCampaign(const DrawnCampaignOptions& options);

// A session's manifest: [apparatus], [specimen], a [[run]] per X0 with its
// maxima and contact time typed in (6 significant digits) and their sigmas.
SessionManifest CampaignSessionManifest(const DrawnCampaignSession& session);

// The truth (schema "impactlab-campaign-truth", docs/synth.md).
nlohmann::json CampaignTruth(const DrawnCampaign& campaign);

// Writes DIR/<session>/session.toml for every session and
// DIR/campaign.truth.json. DIR must not exist or be empty; throws
// InputError otherwise or when a file cannot be written.
void WriteCampaign(const std::filesystem::path& dir, const DrawnCampaign& campaign);

}  // namespace impactlab
