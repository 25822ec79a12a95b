// The hybrid simulation of the document's case 1 and the parameter file.
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "io/errors.h"
#include "multibody/two_link_keys.h"
#include "multibody/two_link_simulation.h"
#include "multibody/two_link_toml.h"
#include "tests/support/input_error.h"

namespace impactlab {
namespace {

bool Finite(const TwoLinkVector& x) { return x.allFinite(); }

TEST_CASE("two-link: case 1 strikes the surface and stays on it with the loop closed") {
  const TwoLinkParameters p = TwoLinkParameters::Nominal();
  const TwoLinkModel model(p);
  const TwoLinkCase& experiment = p.cases[0];
  const auto start = std::chrono::steady_clock::now();
  const TwoLinkRecord record = SimulateTwoLink(model, experiment);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  int impacts = 0, separations = 0;
  for (const TwoLinkEvent& e : record.events) (e.kind == "impact" ? impacts : separations)++;
  WARN("case 1: " << record.time_s.size() << " samples, " << impacts << " impacts, " << separations
                  << " separations, first impact at " << record.FirstImpact()
                  << " s, max loop closure " << record.max_loop_closure_m << " m, " << record.steps
                  << " steps, " << seconds << " s");

  // One sample per 1/rate from 0 to the case's duration.
  const double rate = p.sensors.sample_rate_hz;
  const std::size_t expected_samples =
      static_cast<std::size_t>(std::floor(experiment.duration_s * rate + 1e-9)) + 1;
  CHECK(record.time_s.size() == expected_samples);
  REQUIRE(record.position.size() == record.time_s.size());
  REQUIRE(record.in_contact.size() == record.time_s.size());

  CHECK(record.max_loop_closure_m <= 1e-9);
  CHECK(impacts >= 1);
  // The motors start after the delay, so the tip cannot arrive before it.
  CHECK(record.FirstImpact() > experiment.start_delay_s);
  CHECK(record.FirstImpact() < experiment.duration_s);

  const double surface = -p.surface.distance_m;
  int contact_samples = 0;
  bool all_finite = true;
  double worst_penetration = 0.0, worst_tension = 0.0, worst_contact_gap = 0.0;
  for (std::size_t k = 0; k < record.time_s.size(); ++k) {
    all_finite = all_finite && Finite(record.position[k]) && Finite(record.velocity[k]) &&
                 std::isfinite(record.normal_force_n[k]) &&
                 std::isfinite(record.friction_force_n[k]) && std::isfinite(record.tip_x_m[k]) &&
                 std::isfinite(record.tip_y_m[k]) && std::isfinite(record.gearbox_a_rad[k]) &&
                 std::isfinite(record.gearbox_b_rad[k]);
    for (const auto& channel : record.acceleration_m_s2) {
      all_finite = all_finite && std::isfinite(channel[k]);
    }
    // The recorded tip is the model's tip of the recorded state.
    const double gap = model.Gap(record.position[k]);
    CHECK(gap == Approx(record.tip_x_m[k] - surface).margin(1e-12));
    worst_penetration = std::max(worst_penetration, -gap);
    if (record.in_contact[k]) {
      ++contact_samples;
      worst_tension = std::max(worst_tension, -record.normal_force_n[k]);
      worst_contact_gap = std::max(worst_contact_gap, std::abs(gap));
      // Coulomb friction never exceeds mu N.
      CHECK(std::abs(record.friction_force_n[k]) <=
            p.surface.friction_coefficient * std::abs(record.normal_force_n[k]) * (1.0 + 1e-12) +
                1e-12);
    } else {
      CHECK(record.normal_force_n[k] == 0.0);
    }
  }
  INFO("worst penetration " << worst_penetration << " m, worst tension " << worst_tension
                            << " N, worst gap in contact " << worst_contact_gap << " m");
  CHECK(all_finite);
  CHECK(contact_samples > 0);
  CHECK(worst_tension <= 1e-9);
  CHECK(worst_contact_gap <= 1e-9);
  // Free flight never goes through the surface (the event tolerance is 1e-12 m).
  CHECK(worst_penetration <= 1e-9);
  // Motors off before the start delay: the arm is at rest there.
  for (std::size_t k = 0; k < record.time_s.size() && record.time_s[k] < experiment.start_delay_s;
       ++k) {
    CHECK(record.velocity[k].norm() == 0.0);
    CHECK(record.voltage_a_v[k] == 0.0);
  }
  for (const TwoLinkEvent& e : record.events) {
    if (e.kind != "impact") continue;
    CHECK(e.impact.momentum_residual <= 1e-12);
    CHECK(std::abs(e.impact.normal_velocity_after_m_s) <=
          1e-12 * std::abs(e.impact.normal_velocity_before_m_s) + 1e-15);
    CHECK(e.impact.normal_velocity_before_m_s <= 0.0);
  }
}

// ---------------------------------------------------------------------------
// The parameter file.

// Every key's value, in file order.
std::vector<double> Values(const TwoLinkParameters& p) {
  std::vector<double> out;
  VisitTwoLinkKeys(p, [&](const char*, const char*, const double& value, TwoLinkKeyRule,
                          const char*) { out.push_back(value); });
  return out;
}

// Every work that changes the energy is accounted for: what is left over is
// the integration's error, so it shrinks with the tolerance. At the default
// 1e-8 the three cases leave 2.4e-9, 1.2e-8 and 3.3e-8 of their peak kinetic
// energy; at 1e-10, 1.2e-10, 4.2e-10 and 3.9e-10.
TEST_CASE("two-link: the energy balances over cases 1-3 with every work accounted for") {
  const TwoLinkParameters p = TwoLinkParameters::Nominal();
  const TwoLinkModel model(p);
  for (const double tolerance : {1e-8, 1e-10}) {
    TwoLinkSimulationOptions options;
    options.relative_tolerance = tolerance;
    // At 1e-10 the steps' work is several times the default's: the step
    // budget still bounds it, and the wall-clock guard would make the test
    // depend on how busy the machine is.
    options.max_wall_seconds = std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < std::size(p.cases); ++c) {
      const TwoLinkRecord record = SimulateTwoLink(model, p.cases[c], options);
      const TwoLinkEnergy& e = record.energy;
      INFO("case " << c + 1 << ", tolerance " << tolerance << ": E " << e.initial_j << " -> "
                   << e.final_j << " J; drives and damping " << e.drives_and_damping_j
                   << ", surface " << e.surface_j << ", impacts " << e.impacts_j << ", projections "
                   << e.projections_j << "; peak kinetic " << e.peak_kinetic_j << " J; imbalance "
                   << e.Imbalance() << " J");
      REQUIRE(e.peak_kinetic_j > 0.0);
      CHECK(std::abs(e.Imbalance()) <= 10.0 * tolerance * e.peak_kinetic_j);
      CHECK(e.impacts_j < 0.0);                                     // plastic impacts lose energy
      CHECK(e.surface_j < 0.0);                                     // sliding friction too
      CHECK(e.drives_and_damping_j > 0.0);                          // the motors drive the arm
      CHECK(std::abs(e.projections_j) <= 1e-9 * e.peak_kinetic_j);  // only numerical
    }
  }
}

TEST_CASE("two-link: a simulation over its step budget stops with the budget and the time") {
  const TwoLinkParameters p = TwoLinkParameters::Nominal();
  TwoLinkSimulationOptions options;
  // Above the ~1500 steps stiffness alone needs for 5 s, below the ~18 000
  // that case 1 takes.
  options.max_steps = 2000;
  const TwoLinkRecord refused = SimulateTwoLink(TwoLinkModel(p), p.cases[0], options);
  CHECK_FALSE(refused.ok);
  CHECK_THAT(refused.reason, Catch::Contains("more than 2000 integration steps by t ="));
  // What was simulated before the refusal is kept, every channel sampled alike.
  REQUIRE(!refused.time_s.empty());
  CHECK(refused.time_s.size() < 5001);
  CHECK(refused.gearbox_a_rad.size() == refused.time_s.size());
  CHECK(refused.acceleration_m_s2[3].size() == refused.time_s.size());
  CHECK(refused.position.size() == refused.time_s.size());
  CHECK(refused.voltage_b_v.size() == refused.time_s.size());
  options.max_steps = 0;  // the default budget: 50 000 + 40 000 per simulated second
  options.duration_s = 2.0;
  CHECK(SimulateTwoLink(TwoLinkModel(p), p.cases[0], options).steps > 2000);
}

TEST_CASE("two-link: parameters beyond the model are refused with the key and the limit") {
  struct Bad {
    std::string toml, message;
  };
  const Bad cases[] = {
      {"[sensors]\nsample_rate_hz = 1e9\n", "give 5e+09 samples, over the limit of 2e+06"},
      {"[case1]\nduration_s = 1e9\n", "[case1] duration_s = 1e+09 give 1e+12 samples"},
      {"[beam1]\nlength_m = 1e308\n", "[beam1] length_m = 1e+308 is beyond the model's 100 m"},
      {"[hub3]\ninertia_kg_m2 = 1e300\n", "[hub3] inertia_kg_m2 = 1e+300 and"},
      {"[case1]\nvoltage_a_v = 1e6\n", "[case1] voltage_a_v = 1e+06 is beyond the drives' 1000 V"},
      {"[surface]\nrestitution_coefficient = 1.5\n", "must be at most 1"},
      {"[surface]\nrestitution_law = \"elastic\"\n", "must be one of"},
  };
  for (const Bad& bad : cases) {
    INFO(bad.toml);
    CHECK_THROWS_WITH(ParseTwoLinkParameters(bad.toml, "bad.toml"), Catch::Contains(bad.message));
  }
}

TEST_CASE("two-link: a motion beyond the model is refused with its cause, never NaN") {
  auto refusal = [](const char* toml) {
    const TwoLinkParameters p = ParseTwoLinkParameters(toml, "p.toml");
    const TwoLinkRecord record = SimulateTwoLink(TwoLinkModel(p), p.cases[0]);
    for (const std::vector<double>* channel :
         {&record.gearbox_a_rad, &record.gearbox_b_rad, &record.acceleration_m_s2[0]}) {
      for (const double x : *channel) CHECK(std::isfinite(x));
    }
    return record.ok ? std::string("no refusal") : record.reason;
  };
  // Stiff: refused before it starts, naming the key that makes it so.
  CHECK_THAT(refusal("[beam1]\nflexural_rigidity_n_m2 = 1e10\n"),
             Catch::Contains("too stiff") && Catch::Contains("[beam1] bending"));
  CHECK_THAT(refusal("[drive_a]\ngear_ratio = 1e5\n"),
             Catch::Contains("too stiff") && Catch::Contains("[drive_a] back-EMF braking"));
  CHECK_THAT(refusal("[beam1]\ndamping_n_s_per_m2 = 1e9\n"),
             Catch::Contains("too stiff") && Catch::Contains("[beam1] damping"));
  // Floppy: beyond the small-deflection model.
  CHECK_THAT(refusal("[beam1]\nflexural_rigidity_n_m2 = 1e-9\n"),
             Catch::Contains("[beam1]'s tip deflects") &&
                 Catch::Contains("beyond the small-deflection model"));
}

TEST_CASE("two-link: the written parameter file reads back to identical values") {
  const TwoLinkParameters nominal = TwoLinkParameters::Nominal();
  const TwoLinkParameters parsed =
      ParseTwoLinkParameters(TwoLinkParametersText(nominal), "nominal.toml");
  CHECK(Values(parsed) == Values(nominal));
  CHECK(Values(nominal).size() > 60);

  // Every value changed to one with all 17 digits: the text keeps them.
  TwoLinkParameters changed = nominal;
  int n = 0;
  VisitTwoLinkKeys(changed,
                   [&](const char*, const char*, double& value, TwoLinkKeyRule, const char*) {
                     value = (value == 0.0 ? 0.1 : value) * (1.0 + 0.1234567890123456789 / (++n));
                   });
  std::string error;
  REQUIRE(changed.Check(&error));
  const TwoLinkParameters reread =
      ParseTwoLinkParameters(TwoLinkParametersText(changed), "changed.toml");
  CHECK(Values(reread) == Values(changed));
  CHECK(Values(reread) != Values(nominal));
}

TEST_CASE("two-link: a parameter file may list only what differs from the nominal values") {
  const TwoLinkParameters p =
      ParseTwoLinkParameters("[beam2]\nlength_m = 0.45\n[case1]\nq1_rad = 1\n", "part.toml");
  CHECK(p.beam2.length_m == 0.45);
  CHECK(p.cases[0].q1_rad == 1.0);
  TwoLinkParameters expected = TwoLinkParameters::Nominal();
  expected.beam2.length_m = 0.45;
  expected.cases[0].q1_rad = 1.0;
  CHECK(Values(p) == Values(expected));
}

TEST_CASE("two-link: an experiment's file read over the simulation's keeps its other values") {
  // simulate two-link --experiment: EXP.toml lists how the experiment differs
  // from PARAMS.toml, not from the nominal set.
  TwoLinkParameters simulation = TwoLinkParameters::Nominal();
  simulation.beam1.flexural_rigidity_n_m2 = 5.0;
  simulation.cases[0].duration_s = 3.0;
  const TwoLinkParameters p =
      ParseTwoLinkParameters("[body2]\nmass_kg = 2.6\n", "experiment.toml", simulation);
  TwoLinkParameters expected = simulation;
  expected.body2.mass_kg = 2.6;
  CHECK(Values(p) == Values(expected));
}

TEST_CASE("two-link: a bad parameter file names the file and the key") {
  using testing::InputErrorOf;
  auto parse = [](const std::string& text) {
    return [text] { ParseTwoLinkParameters(text, "arm.toml"); };
  };
  const std::string unknown_key = InputErrorOf(parse("[beam1]\nlength_m = 0.7\nlenght_m = 0.7\n"));
  INFO(unknown_key);
  CHECK(unknown_key.find("arm.toml") != std::string::npos);
  CHECK(unknown_key.find("beam1.lenght_m") != std::string::npos);
  CHECK(unknown_key.find(":3") != std::string::npos);  // the line

  const std::string unknown_table = InputErrorOf(parse("[beam3]\nlength_m = 0.7\n"));
  INFO(unknown_table);
  CHECK(unknown_table.find("arm.toml") != std::string::npos);
  CHECK(unknown_table.find("beam3") != std::string::npos);

  const std::string string_value = InputErrorOf(parse("[beam1]\nlength_m = \"0.75\"\n"));
  INFO(string_value);
  CHECK(string_value.find("arm.toml") != std::string::npos);
  CHECK(string_value.find("beam1.length_m") != std::string::npos);
  CHECK(string_value.find(":2") != std::string::npos);

  const std::string negative = InputErrorOf(parse("[beam1]\nlength_m = -0.75\n"));
  INFO(negative);
  CHECK(negative.find("arm.toml") != std::string::npos);
  CHECK(negative.find("length_m") != std::string::npos);
  CHECK(negative.find("beam1") != std::string::npos);
  CHECK(negative.find("positive") != std::string::npos);
  CHECK(negative.find("beam1.length_m") != std::string::npos);
  CHECK(negative.find(":2") != std::string::npos);

  const std::string not_toml = InputErrorOf(parse("[beam1]\nlength_m = = 1\n"));
  INFO(not_toml);
  CHECK(not_toml.find("arm.toml:2") != std::string::npos);

  const std::string not_a_table = InputErrorOf(parse("beam1 = 3\n"));
  INFO(not_a_table);
  CHECK(not_a_table.find("arm.toml") != std::string::npos);
  CHECK(not_a_table.find("beam1") != std::string::npos);

  CHECK_THROWS_AS(ParseTwoLinkParameters("[drive_a]\nbacklash_rad = -1e-3\n", "arm.toml"),
                  InputError);
  CHECK_THROWS_AS(ParseTwoLinkParameters("[surface]\nslip_velocity_m_s = 0\n", "arm.toml"),
                  InputError);
}

}  // namespace
}  // namespace impactlab
