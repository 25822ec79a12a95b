// Benchmark of the two-link manipulator's simulator (docs/two-link.md,
// "Benchmarks"): run time against accuracy for the document's three cases,
// and the modes about the state after the first impact.
//
//   bench_two_link [--repeats 5] [--tolerance 1e-9]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "multibody/two_link_modes.h"
#include "multibody/two_link_simulation.h"

namespace {

using namespace impactlab;
using Clock = std::chrono::steady_clock;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Largest difference of the encoder angles (rad) and the mid-beam
// accelerometer (m/s^2) against a reference record on the same samples.
std::pair<double, double> Differences(const TwoLinkRecord& a, const TwoLinkRecord& b) {
  double angle = 0.0, acceleration = 0.0;
  const std::size_t n = std::min(a.time_s.size(), b.time_s.size());
  for (std::size_t i = 0; i < n; ++i) {
    angle = std::max(angle, std::abs(a.gearbox_a_rad[i] - b.gearbox_a_rad[i]));
    acceleration =
        std::max(acceleration, std::abs(a.acceleration_m_s2[0][i] - b.acceleration_m_s2[0][i]));
  }
  return {angle, acceleration};
}

// The impact law's effect on each case (docs/two-link.md, "The impact law"):
// the incremental Coulomb law against the paper's, impact by impact.
void PrintImpactLaws() {
  fmt::print(
      "\n| case | impact law | impacts | slip reversed | stuck | friction work > 0 | largest "
      "friction work J | first impact: P_n, P_t N s | its loss J |\n"
      "|---|---|---|---|---|---|---|---|---|\n");
  for (int c = 0; c < 3; ++c) {
    for (const char* law : {"incremental", "paper"}) {
      TwoLinkParameters p = TwoLinkParameters::Nominal();
      p.surface.impact_friction = law;
      const TwoLinkModel model(p);
      TwoLinkSimulationOptions options;
      options.keep_state = false;
      const TwoLinkRecord record = SimulateTwoLink(model, p.cases[c], options);
      int impacts = 0, reversed = 0, stuck = 0, positive = 0;
      double largest = -1e300;
      const ImpactOutcome* first = nullptr;
      for (const TwoLinkEvent& e : record.events) {
        if (e.kind != "impact") continue;
        ++impacts;
        reversed +=
            e.impact.slip_reversed ||
            e.impact.tangential_velocity_before_m_s * e.impact.tangential_velocity_after_m_s < 0.0;
        stuck += e.impact.sticks;
        positive += e.impact.friction_work_j > 0.0;
        largest = std::max(largest, e.impact.friction_work_j);
        if (!first) first = &e.impact;
      }
      if (!first) continue;
      fmt::print("| {} | {} | {} | {} | {} | {} | {:.3g} | {:.4f}, {:+.4f} | {:.4f} |\n", c + 1,
                 law, impacts, reversed, stuck, positive, largest, first->normal_impulse_n_s,
                 first->tangential_impulse_n_s, -(first->normal_work_j + first->friction_work_j));
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Two-link manipulator: simulation time against accuracy");
  int repeats = 5;
  app.add_option("--repeats", repeats, "Timed runs per case and tolerance")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const TwoLinkModel model(TwoLinkParameters::Nominal());
  fmt::print(
      "| case | tolerance | median s | steps | RHS calls | events | first impact s | "
      "max |dq1| rad | max |da1| m/s^2 |\n|---|---|---|---|---|---|---|---|---|\n");
  for (int c = 0; c < 3; ++c) {
    TwoLinkSimulationOptions reference_options;
    reference_options.relative_tolerance = 1e-12;
    reference_options.absolute_tolerance = 1e-15;
    reference_options.keep_state = false;
    const TwoLinkRecord reference =
        SimulateTwoLink(model, model.parameters().cases[c], reference_options);
    if (!reference.ok) {
      fmt::print("| {} | 1e-12 | {} |\n", c + 1, reference.reason);
      continue;
    }
    for (double tolerance : {1e-6, 1e-7, 1e-8, 1e-9, 1e-10}) {
      TwoLinkSimulationOptions options;
      options.relative_tolerance = tolerance;
      options.absolute_tolerance = tolerance * 1e-3;
      options.keep_state = false;
      std::vector<double> seconds;
      TwoLinkRecord record;
      for (int r = 0; r < repeats; ++r) {
        const auto start = Clock::now();
        record = SimulateTwoLink(model, model.parameters().cases[c], options);
        seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
      }
      if (!record.ok) {
        fmt::print("| {} | {:.0e} | {} |\n", c + 1, tolerance, record.reason);
        continue;
      }
      const auto [angle, acceleration] = Differences(record, reference);
      fmt::print("| {} | {:.0e} | {:.3f} | {} | {} | {} | {:.5f} | {:.2e} | {:.2e} |\n", c + 1,
                 tolerance, Median(seconds), record.steps, record.rhs_evaluations,
                 record.events.size(), record.FirstImpact(), angle, acceleration);
    }
    // The modes after the first impact settles: the state 1 s after it.
    TwoLinkSimulationOptions options;
    const TwoLinkRecord record = SimulateTwoLink(model, model.parameters().cases[c], options);
    const double impact = record.FirstImpact();
    if (impact < 0.0) continue;
    const std::size_t k =
        std::min(record.time_s.size() - 1, static_cast<std::size_t>((impact + 1.0) * 1000.0));
    const TwoLinkVector& q = record.position[k];
    const TwoLinkVector& v = record.velocity[k];
    const DriveVoltages voltages{record.voltage_a_v[k], record.voltage_b_v[k]};
    const auto modes = LinearisedModes(model, q, v, voltages, record.in_contact[k] != 0);
    std::string list;
    for (const VibrationMode& m : modes) {
      if (m.frequency_hz > 0.0)
        list += fmt::format(" {:.2f} Hz (zeta {:.3f});", m.frequency_hz, m.damping_ratio);
    }
    fmt::print("\ncase {} at t = {:.3f} s ({}):{}\n\n", c + 1, record.time_s[k],
               record.in_contact[k] ? "on the surface" : "free", list);
  }
  PrintImpactLaws();
  return 0;
}
