// A campaign: many sessions' results read together (docs/campaigns.md).
//
// Every session's estimates are tabulated with their errors, grouped by
// material and end geometry (the manifest's [specimen]); the constants a
// material shares are fitted across its sessions by generalised least
// squares (campaign/shared_fit.h) with the Birge ratio and each session's
// pull. Numbers are in one unit system, the first session's; a session in
// the other is converted.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "io/specimen.h"
#include "io/units.h"

namespace impactlab {

inline constexpr const char* kMaterialNotGiven = "material not given";

// One estimate of a session: a contact law's or a restitution model's
// parameter, or a constant derived from one (E*).
struct SessionEstimate {
  std::string source;  // "hunt-crossley", "restitution linear-in-speed", ...
  std::string name;    // "effective_modulus", "damping_factor", "hertz_stiffness", "a", ...
  double value = 0.0;
  double sigma = 0.0;  // stated standard error
  std::string unit;    // in the campaign's units
};

// One impact of a run: the speed it met and the fraction of it kept.
struct ImpactRestitution {
  std::string run;
  int rebound = 0;  // n: the impact between the maxima X_n and X_{n+1}
  double speed = 0.0;
  double restitution = 0.0, restitution_sigma = 0.0;
  // The relative errors of v(X_n) and v(X_{n+1}); the second is the next
  // impact's first, which correlates the two.
  double speed_relative_sigma = 0.0, rebound_speed_relative_sigma = 0.0;
};

// A session's restitution speed law e(u) = E(eps_ref (u/u_ref)^beta), fitted
// to its impacts (campaign/restitution_law.h).
struct SessionRestitutionLaw {
  bool ok = false;
  std::string reason;              // why not, when !ok
  double reference_speed = 0.0;    // u_ref: the geometric mean of its impacts' speeds
  double log_eps = 0.0;            // ln eps_ref
  double exponent = 0.0;           // beta
  std::vector<double> covariance;  // of (ln eps_ref, beta), 2 x 2 row-major
  double chi2 = 0.0;
  int dof = 0;
  int impacts = 0;
};

// A run's own contact time, at the speed of its impact (the one after
// rebound 0, the manifest's default).
struct ContactTimeAtSpeed {
  std::string run;
  double speed = 0.0;
  double contact_time = 0.0, contact_time_sigma = 0.0;
};

// A session's fitted contact law, to draw its contact time against speed.
// Its k and chi are what the material fits take, with their logarithms'
// covariance.
struct SessionContactLaw {
  std::string law;  // "hunt-crossley" or "hertz"
  double mass = 0.0, hertz_stiffness = 0.0, damping_factor = 0.0;
  double modulus_per_k = 0.0;          // E* = this k, where the ends make E* identifiable (else 0)
  std::vector<double> log_covariance;  // of (ln k, ln chi), or ln k alone for Hertz; row-major
};

struct CampaignSession {
  std::string name;  // unique in the campaign: the results file's or folder's name
  std::string file;  // the results file read
  std::string title;
  std::string original_units;  // the session's own: "in-lbf-s" or "SI"
  Specimen specimen;           // in the campaign's units
  std::string material;        // the specimen's, or kMaterialNotGiven
  std::string geometry;        // "sphere R = 0.5 in", "plane", "given stiffness", "not given"
  std::vector<SessionEstimate> estimates;
  std::vector<ImpactRestitution> restitution;
  std::vector<ContactTimeAtSpeed> contact_times;
  std::vector<SessionContactLaw> laws;
  SessionRestitutionLaw restitution_law;
  double reference_speed = 0.0;  // u_ref of its restitution law (0: none fitted)
};

// The constants one material's sessions share, fitted together.
struct MaterialFit {
  std::string material;
  std::string fit;                     // "hunt-crossley", "hertz" or "restitution"
  std::vector<std::string> constants;  // "effective_modulus", "damping_factor", "speed_exponent"
  std::vector<std::string> units;
  bool ok = false;
  std::string reason;
  std::vector<double> values, sigma;    // the constants (fitted as logarithms where positive)
  std::vector<double> sigma_scaled;     // times the Birge ratio where it exceeds 1
  std::vector<double> covariance;       // of the fitted parameters (logs for the positive ones)
  std::vector<std::string> parameters;  // what the covariance is of: "log effective_modulus", ...
  double reference_speed = 0.0;         // restitution: u0 of e = E(chi u0 (u/u0)^beta)
  std::vector<std::string> sessions;    // the sessions fitted
  double chi2 = 0.0;
  int dof = 0;
  double birge_ratio = 1.0, p_value = 1.0;
  double pull_threshold = 3.0;
  std::vector<std::string> pull_session, pull_constant;
  std::vector<double> pull;
  std::vector<std::string> pulling_away;  // sessions with a |pull| beyond the threshold
  // Constants that only two sessions state and on which they disagree beyond
  // the threshold: neither is named, as which one is off cannot be told.
  std::vector<std::string> disagreeing_pairs;
};

struct CampaignFailure {
  std::string input;
  std::string reason;
};

struct Campaign {
  UnitSystem units = UnitSystem::kInLbfS;
  std::string producer, created;
  std::vector<std::string> inputs;
  std::vector<CampaignSession> sessions;  // grouped by material and geometry
  std::vector<MaterialFit> fits;
  std::vector<CampaignFailure> failures;  // inputs that could not be read, in input order
};

struct CampaignOptions {
  std::string producer = "impactlab";
  int jobs = 1;  // runs reduced in parallel, for a session folder
  // Where a session folder's results file is written (and reused from when
  // its runs are unchanged): <folder name>.h5 in it.
  std::filesystem::path reduced_folder;
  // The chance of naming any clean session as pulling away, per fit.
  double false_alarm = 0.01;
};

// Reads every input (a results file, or a session folder reduced first), in
// order. An input that cannot be read is a failure of its own; the rest are
// combined.
Campaign MakeCampaign(const std::vector<std::filesystem::path>& inputs,
                      const CampaignOptions& options);

// Writes the campaign file (docs/campaigns.md) atomically; throws InputError
// naming the file if it cannot.
void WriteCampaign(const Campaign& campaign, const std::filesystem::path& path);

}  // namespace impactlab
