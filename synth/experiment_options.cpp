// Option checks, names, the one-line brief and the JSON form of the truth.
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "synth/experiment.h"

namespace impactlab {
namespace {

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

bool Positive(double v) { return v > 0.0 && std::isfinite(v); }

void CheckIntegration(const IntegrationOptions& i) {
  Require(Positive(i.relative_tolerance) && i.relative_tolerance < 1e-3,
          fmt::format("integration.relative_tolerance must be in (0, 1e-3), got {}",
                      i.relative_tolerance));
  Require(Positive(i.absolute_tolerance),
          fmt::format("integration.absolute_tolerance must be > 0, got {}", i.absolute_tolerance));
  Require(Positive(i.max_step_s),
          fmt::format("integration.max_step_s must be > 0, got {}", i.max_step_s));
  Require(Positive(i.max_contact_time_s),
          fmt::format("integration.max_contact_time_s must be > 0, got {}", i.max_contact_time_s));
}

}  // namespace

const char* ArrangementName(Arrangement a) { return a == Arrangement::kPair ? "pair" : "wall"; }

const char* ContactModelName(ContactModelKind k) {
  return k == ContactModelKind::kKelvinVoigt ? "kelvin-voigt" : "poynting-thomson";
}

void ExperimentOptions::Check() const {
  Require(Positive(pendulum_length),
          fmt::format("pendulum_length must be > 0, got {}", pendulum_length));
  Require(Positive(gravity), fmt::format("gravity must be > 0, got {}", gravity));
  Require(Positive(mass), fmt::format("mass must be > 0, got {}", mass));
  const bool pair = arrangement == Arrangement::kPair;
  Require(std::abs(left_length_excess) < 0.5 && std::abs(left_mass_excess) < 0.5,
          fmt::format("left_length_excess and left_mass_excess must be within +-0.5, got {}, {}",
                      left_length_excess, left_mass_excess));
  const double left_length = pendulum_length * (1.0 + left_length_excess);
  Require(Positive(release_x_right) && release_x_right < pendulum_length,
          fmt::format("release_x_right must be in (0, L = {}), got {}", pendulum_length,
                      release_x_right));
  if (pair) {
    Require(Positive(release_x_left) && release_x_left < left_length,
            fmt::format("release_x_left must be in (0, L_left = {}), got {}", left_length,
                        release_x_left));
    // Both bars must have left their magnets before they can meet.
    const double quarter_swing_s = 0.5 * std::numbers::pi * std::sqrt(pendulum_length / gravity);
    Require(std::abs(left_release_delay_s) < 0.5 * quarter_swing_s,
            fmt::format("|left_release_delay_s| must be < {} s (half a quarter swing), got {}",
                        0.5 * quarter_swing_s, left_release_delay_s));
  }
  if (contact_model == ContactModelKind::kKelvinVoigt) {
    const KelvinVoigtElement& kv = kelvin_voigt;
    Require(Positive(kv.stiffness) && kv.damping >= 0.0 && std::isfinite(kv.damping),
            fmt::format("kelvin_voigt needs K > 0 and C >= 0, got K = {}, C = {}", kv.stiffness,
                        kv.damping));
    // Damping ratio of the relative motion: the faces in series act as
    // (K/n, C/n) on delta, with the reduced mass of the bars.
    const double n = pair ? 2.0 : 1.0;
    const double ml = mass * (1.0 + left_mass_excess);
    const double reduced_mass = pair ? mass * ml / (mass + ml) : mass;
    const double zeta = (kv.damping / n) / (2.0 * std::sqrt(kv.stiffness / n * reduced_mass));
    if (separation == Separation::kKinematic && zeta >= 1.0) {
      throw NoSeparationError(fmt::format(
          "Kelvin-Voigt damping ratio zeta = {} >= 1 (K = {}, C = {}, M = {}): with kinematic "
          "separation the overlap never returns to 0, so the contact never ends; use force "
          "separation or C < 2 sqrt(K M)",
          zeta, kv.stiffness, kv.damping, mass));
    }
  } else {
    const PoyntingThomsonElement& pt = poynting_thomson;
    Require(
        Positive(pt.stiffness_1) && pt.stiffness_2 >= 0.0 && std::isfinite(pt.stiffness_2) &&
            Positive(pt.damping),
        fmt::format("poynting_thomson needs K1 > 0, K2 >= 0, C > 0, got K1 = {}, K2 = {}, C = {}",
                    pt.stiffness_1, pt.stiffness_2, pt.damping));
  }
  if (wires.enabled) {
    Require(wires.wires_per_bar >= 1,
            fmt::format("wires.wires_per_bar must be >= 1, got {}", wires.wires_per_bar));
    Require(Positive(wires.mass_per_length),
            fmt::format("wires.mass_per_length must be > 0, got {}", wires.mass_per_length));
    Require(wires.chord_length >= 0.0 && std::isfinite(wires.chord_length),
            fmt::format("wires.chord_length must be >= 0, got {}", wires.chord_length));
    Require(
        std::abs(wires.inclination_rad) < 1.5,
        fmt::format("wires.inclination_rad must be within +-1.5, got {}", wires.inclination_rad));
    Require(wires.decay_time_s > 0.0,
            fmt::format("wires.decay_time_s must be > 0, got {}", wires.decay_time_s));
  }
  Require(impact_count >= 1 && impact_count <= 1000,
          fmt::format("impact_count must be in 1..1000, got {}", impact_count));
  Require(Positive(sample_rate_hz) && sample_rate_hz <= 1e8,
          fmt::format("sample_rate_hz must be in (0, 1e8], got {}", sample_rate_hz));
  CheckIntegration(integration);
}

void FreeSwingOptions::Check() const {
  Require(Positive(pendulum_length) && Positive(gravity),
          fmt::format("free swing needs L > 0 and g > 0, got L = {}, g = {}", pendulum_length,
                      gravity));
  Require(Positive(release_x) && release_x < pendulum_length,
          fmt::format("release_x must be in (0, L = {}), got {}", pendulum_length, release_x));
  Require(Positive(duration_s), fmt::format("duration_s must be > 0, got {}", duration_s));
  Require(Positive(sample_rate_hz) && duration_s * sample_rate_hz < 1e8,
          fmt::format("sample_rate_hz must be > 0 and give < 1e8 samples, got {}", sample_rate_hz));
  CheckIntegration(integration);
}

std::string ExperimentResult::Brief() const {
  std::string text = fmt::format("{} {} ({}), {} impacts", ArrangementName(options.arrangement),
                                 ContactModelName(options.contact_model),
                                 SeparationName(options.separation), impacts.size());
  if (!impacts.empty()) {
    text += fmt::format(", e1 = {:.6f}, tau_c1 = {:.3f} us", impacts.front().restitution,
                        impacts.front().duration_s * 1e6);
  }
  const auto& maxima = rebounds_average.empty() ? rebounds_right : rebounds_average;
  text += ", xmax =";
  for (const ReboundTruth& r : maxima) text += fmt::format(" {:.4f}", r.xmax);
  return text;
}

void to_json(nlohmann::json& j, const ExperimentOptions& o) {
  j = {{"pendulum_length", o.pendulum_length},
       {"gravity", o.gravity},
       {"mass", o.mass},
       {"arrangement", ArrangementName(o.arrangement)},
       {"left_length_excess", o.left_length_excess},
       {"left_mass_excess", o.left_mass_excess},
       {"release_x_right", o.release_x_right},
       {"release_x_left", o.release_x_left},
       {"left_release_delay_s", o.left_release_delay_s},
       {"contact_model", ContactModelName(o.contact_model)},
       {"separation", SeparationName(o.separation)},
       {"impact_count", o.impact_count},
       {"sample_rate_hz", o.sample_rate_hz}};
  if (o.contact_model == ContactModelKind::kKelvinVoigt) {
    j["kelvin_voigt"] = {{"stiffness", o.kelvin_voigt.stiffness},
                         {"damping", o.kelvin_voigt.damping}};
  } else {
    j["poynting_thomson"] = {{"stiffness_1", o.poynting_thomson.stiffness_1},
                             {"stiffness_2", o.poynting_thomson.stiffness_2},
                             {"damping", o.poynting_thomson.damping}};
  }
  j["wires"] = {
      {"enabled", o.wires.enabled},
      {"wires_per_bar", o.wires.wires_per_bar},
      {"mass_per_length", o.wires.mass_per_length},
      {"chord_length", o.wires.chord_length},
      {"inclination_rad", o.wires.inclination_rad},
      // JSON has no infinity: null means undamped.
      {"decay_time_s", std::isfinite(o.wires.decay_time_s) ? nlohmann::json(o.wires.decay_time_s)
                                                           : nlohmann::json(nullptr)}};
  j["integration"] = {{"relative_tolerance", o.integration.relative_tolerance},
                      {"absolute_tolerance", o.integration.absolute_tolerance},
                      {"max_step_s", o.integration.max_step_s},
                      {"max_contact_time_s", o.integration.max_contact_time_s}};
}

void to_json(nlohmann::json& j, const ImpactTruth& i) {
  j = {{"impact", i.impact},
       {"start_time_s", i.start_time_s},
       {"end_time_s", i.end_time_s},
       {"duration_s", i.duration_s},
       {"approach_speed", i.approach_speed},
       {"separation_speed", i.separation_speed},
       {"restitution", i.restitution},
       {"right_impact_speed", i.right_impact_speed},
       {"right_exit_speed", i.right_exit_speed},
       {"left_impact_speed", i.left_impact_speed},
       {"left_exit_speed", i.left_exit_speed},
       {"peak_overlap", i.peak_overlap},
       {"peak_overlap_time_s", i.peak_overlap_time_s},
       {"energy_before", i.energy_before},
       {"energy_after", i.energy_after},
       {"dissipated_energy", i.dissipated_energy},
       {"residual_elastic", i.residual_elastic}};
}

void to_json(nlohmann::json& j, const ReboundTruth& r) {
  j = {{"rebound", r.rebound},
       {"start_time_s", r.start_time_s},
       {"end_time_s", r.end_time_s},
       {"duration_s", r.duration_s},
       {"xmax", r.xmax},
       {"peak_time_s", r.peak_time_s}};
}

nlohmann::json TruthJson(const ExperimentResult& r) {
  auto bar = [](const BarParameters& b) {
    return nlohmann::json{{"length", b.length},
                          {"mass", b.mass},
                          {"release_x", b.release_x},
                          {"release_time_s", b.release_time_s}};
  };
  nlohmann::json j = {{"options", r.options},
                      {"right", bar(r.right)},
                      {"impacts", r.impacts},
                      {"rebounds_right", r.rebounds_right},
                      {"end_time_s", r.end_time_s}};
  if (r.options.arrangement == Arrangement::kPair) {
    j["left"] = bar(r.left);
    j["rebounds_left"] = r.rebounds_left;
    j["rebounds_average"] = r.rebounds_average;
  }
  return j;
}

}  // namespace impactlab
