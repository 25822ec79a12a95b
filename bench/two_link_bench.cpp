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
    TwoLinkRecord reference;
    try {
      reference = SimulateTwoLink(model, model.parameters().cases[c], reference_options);
    } catch (const std::exception& e) {
      fmt::print("| {} | 1e-12 | {} |\n", c + 1, e.what());
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
  return 0;
}
