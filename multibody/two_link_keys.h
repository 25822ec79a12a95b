// The parameter file's keys (docs/two-link.md, "Parameters"): one list that
// the reader, the writer, the checks and the docs' test all walk.
#pragma once

#include <string>
#include <vector>

#include "multibody/two_link_parameters.h"

namespace impactlab {

enum class TwoLinkKeyRule { kPositive, kNonNegative, kAny };

// visit(section, key, value&, rule, description) for every key, in file order.
template <typename Parameters, typename Visit>
void VisitTwoLinkKeys(Parameters& p, Visit&& visit) {
  using R = TwoLinkKeyRule;
  auto beam = [&](const char* s, auto& b) {
    visit(s, "length_m", b.length_m, R::kPositive, "flexible length L, m");
    visit(s, "hub_radius_m", b.hub_radius_m, R::kNonNegative, "root's distance from the joint, m");
    visit(s, "mass_per_length_kg_per_m", b.mass_per_length_kg_per_m, R::kPositive, "rho A, kg/m");
    visit(s, "flexural_rigidity_n_m2", b.flexural_rigidity_n_m2, R::kPositive, "E I, N m^2");
    visit(s, "damping_n_s_per_m2", b.damping_n_s_per_m2, R::kNonNegative,
          "transverse damping per length, N s/m^2");
  };
  auto body = [&](const char* s, auto& b, bool with_mass) {
    if (with_mass) visit(s, "mass_kg", b.mass_kg, R::kNonNegative, "mass, kg");
    visit(s, "inertia_kg_m2", b.inertia_kg_m2, R::kNonNegative, "about its centre of mass, kg m^2");
  };
  auto drive = [&](const char* s, auto& d) {
    visit(s, "gear_ratio", d.gear_ratio, R::kPositive, "n, motor turns per output turn");
    visit(s, "torque_constant_n_m_per_a", d.torque_constant_n_m_per_a, R::kNonNegative, "K_t");
    visit(s, "back_emf_v_s_per_rad", d.back_emf_v_s_per_rad, R::kNonNegative, "K_b");
    visit(s, "armature_resistance_ohm", d.armature_resistance_ohm, R::kPositive, "R");
    visit(s, "equivalent_inertia_kg_m2", d.equivalent_inertia_kg_m2, R::kPositive,
          "J_eq at the output");
    visit(s, "equivalent_damping_n_m_s", d.equivalent_damping_n_m_s, R::kNonNegative,
          "C_eq at the output");
    visit(s, "backlash_rad", d.backlash_rad, R::kNonNegative, "total play at the output");
    visit(s, "mesh_stiffness_n_m_per_rad", d.mesh_stiffness_n_m_per_rad, R::kNonNegative,
          "k_g, engaged");
    visit(s, "mesh_damping_n_m_s", d.mesh_damping_n_m_s, R::kNonNegative, "c_g, engaged");
  };
  auto experiment = [&](const char* s, auto& c) {
    visit(s, "q1_rad", c.q1_rad, R::kAny, "link 1 from the x axis at the start");
    visit(s, "q4_rad", c.q4_rad, R::kAny, "link 2 from link 1 at the start");
    visit(s, "voltage_a_v", c.voltage_a_v, R::kAny, "motor A's armature voltage, V");
    visit(s, "voltage_b_v", c.voltage_b_v, R::kAny, "motor B's, V");
    visit(s, "start_delay_s", c.start_delay_s, R::kNonNegative, "motors start after the log, s");
    visit(s, "duration_s", c.duration_s, R::kPositive, "length of the log, s");
  };
  beam("beam1", p.beam1);
  beam("beam2", p.beam2);
  body("hub1", p.hub1, false);
  body("body2", p.body2, true);
  body("hub3", p.hub3, true);
  body("tool", p.tool.body, true);
  visit("tool", "centre_m", p.tool.centre_m, R::kAny, "centre of mass beyond beam 2's tip, m");
  visit("tool", "tip_x_m", p.tool.tip_x_m, R::kAny, "contact tip from the centre, along, m");
  visit("tool", "tip_y_m", p.tool.tip_y_m, R::kAny, "... and across, m");
  drive("drive_a", p.drive_a);
  drive("drive_b", p.drive_b);
  visit("surface", "distance_m", p.surface.distance_m, R::kAny, "the surface is x = -distance");
  visit("surface", "friction_coefficient", p.surface.friction_coefficient, R::kNonNegative,
        "kinetic mu");
  visit("surface", "slip_velocity_m_s", p.surface.slip_velocity_m_s, R::kPositive,
        "friction's regularisation speed, m/s");
  visit("surface", "restitution_coefficient", p.surface.restitution_coefficient, R::kNonNegative,
        "the impact's e, at most 1 (0: plastic)");
  visit("sensors", "counts_per_rev", p.sensors.counts_per_rev, R::kPositive,
        "encoder counts per motor turn");
  visit("sensors", "beam_sensitivity_v_per_g", p.sensors.beam_sensitivity_v_per_g, R::kPositive,
        "mid-beam accelerometers, V/g");
  visit("sensors", "body_sensitivity_v_per_g", p.sensors.body_sensitivity_v_per_g, R::kPositive,
        "RB2 and RB4 accelerometers, V/g");
  visit("sensors", "beam_noise_v", p.sensors.beam_noise_v, R::kNonNegative, "one sigma, V");
  visit("sensors", "body_noise_v", p.sensors.body_noise_v, R::kNonNegative, "one sigma, V");
  visit("sensors", "adc_lsb_v", p.sensors.adc_lsb_v, R::kNonNegative, "ADC step, V (0: none)");
  visit("sensors", "sample_rate_hz", p.sensors.sample_rate_hz, R::kPositive, "log rate, Hz");
  visit("sanding", "centre_y_m", p.sanding.centre_y_m, R::kAny, "tip's commanded mean y, m");
  visit("sanding", "amplitude_m", p.sanding.amplitude_m, R::kNonNegative, "and swing, m");
  visit("sanding", "period_s", p.sanding.period_s, R::kPositive, "of the swing, s");
  visit("sanding", "press_depth_m", p.sanding.press_depth_m, R::kAny,
        "commanded x this far into the surface, m");
  visit("sanding", "gain_v_per_rad", p.sanding.gain_v_per_rad, R::kNonNegative,
        "voltage per rad of joint error");
  visit("sanding", "max_voltage_v", p.sanding.max_voltage_v, R::kPositive, "clip, V");
  experiment("case1", p.cases[0]);
  experiment("case2", p.cases[1]);
  experiment("case3", p.cases[2]);
}

// The keys whose value is one of a few words:
// visit(section, key, value&, allowed words, description), in file order.
template <typename Parameters, typename Visit>
void VisitTwoLinkChoices(Parameters& p, Visit&& visit) {
  static const std::vector<std::string> restitution_laws = {"energetic", "newton", "poisson"};
  static const std::vector<std::string> impact_frictions = {"incremental", "paper"};
  visit("surface", "restitution_law", p.surface.restitution_law, restitution_laws,
        "how e ends the impulse: energetic (Stronge), newton or poisson");
  visit("surface", "impact_friction", p.surface.impact_friction, impact_frictions,
        "friction during the impulse: incremental (Coulomb at every instant) or paper");
}

}  // namespace impactlab
