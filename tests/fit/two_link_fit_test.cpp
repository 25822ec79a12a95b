// The two-link simulation fitted to logs simulated with hidden parameter
// changes (fit/two_link_fit.h): what the data determine comes back within
// its stated sigma.
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "fit/two_link_fit.h"
#include "multibody/two_link_simulation.h"

namespace impactlab {
namespace {

// The logger's view of a simulated record: whole encoder counts, noisy
// accelerometers (sigma 0.2 m/s^2).
TwoLinkMeasurement Logged(const TwoLinkParameters& p, const TwoLinkRecord& r) {
  TwoLinkMeasurement m;
  m.time_s = r.time_s;
  m.encoder_a_step_rad = 2.0 * M_PI / (p.sensors.counts_per_rev * p.drive_a.gear_ratio);
  m.encoder_b_step_rad = 2.0 * M_PI / (p.sensors.counts_per_rev * p.drive_b.gear_ratio);
  std::vector<double> q1, q4;
  for (std::size_t i = 0; i < r.time_s.size(); ++i) {
    q1.push_back(std::floor(r.gearbox_a_rad[i] / m.encoder_a_step_rad) * m.encoder_a_step_rad);
    q4.push_back(std::floor(r.gearbox_b_rad[i] / m.encoder_b_step_rad) * m.encoder_b_step_rad);
  }
  m.q1_rad = q1;
  m.q4_rad = q4;
  std::mt19937_64 engine(7);
  std::normal_distribution<double> noise(0.0, 0.2);
  for (int a = 0; a < 4; ++a) {
    std::vector<double> values = r.acceleration_m_s2[a];
    for (double& v : values) v += noise(engine);
    m.acceleration_m_s2[a] = values;
  }
  return m;
}

TEST_CASE("A hidden beam stiffness and start delay come back within their stated sigma",
          "[two_link_fit]") {
  TwoLinkParameters nominal = TwoLinkParameters::Nominal();
  nominal.cases[0].duration_s = 2.5;
  TwoLinkParameters hidden = nominal;
  hidden.beam1.flexural_rigidity_n_m2 = 3.0;  // -9.6 %
  hidden.cases[0].start_delay_s = 0.15;       // +50 ms
  const TwoLinkRecord record = SimulateTwoLink(TwoLinkModel(hidden), hidden.cases[0]);
  TwoLinkFitOptions options;
  options.free = {"beam1.flexural_rigidity_n_m2", "case1.start_delay_s"};
  const TwoLinkFitResult fit = FitTwoLinkSimulation(nominal, Logged(hidden, record), options);
  INFO(fit.Summary());
  REQUIRE(fit.parameters.size() == 2);
  const double truths[2] = {3.0, 0.15};
  for (int i = 0; i < 2; ++i) {
    const FittedParameter& p = fit.parameters[static_cast<std::size_t>(i)];
    CHECK(p.determined);
    REQUIRE(p.value.sigma > 0.0);
    WARN(p.name << ": " << p.value.value << " +- " << p.value.sigma << ", pull "
                << (p.value.value - truths[i]) / p.value.sigma);
    CHECK(std::abs(p.value.value - truths[i]) <= 4.0 * p.value.sigma);
  }
  CHECK(fit.birge_ratio < 1.5);
  CHECK(std::abs(fit.fitted_impact_s - record.FirstImpact()) < 1e-3);
}

TEST_CASE("The two-link fit refuses an unknown parameter, naming it", "[two_link_fit]") {
  TwoLinkMeasurement m;
  m.time_s = {0.0, 0.001, 0.002, 0.003, 0.004, 0.005, 0.006, 0.007, 0.008, 0.009, 0.010};
  TwoLinkFitOptions options;
  options.free = {"beam1.stiffness"};
  CHECK_THROWS_WITH(FitTwoLinkSimulation(TwoLinkParameters::Nominal(), m, options),
                    Catch::Contains("beam1.stiffness"));
}

}  // namespace
}  // namespace impactlab
