// Reducing the thesis's typed-in session reproduces its published tables.
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"

namespace impactlab {
namespace {

const std::filesystem::path kThesisSession =
    std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "thesis-1969";

SessionResult ReduceThesis(PendulumConvention convention = PendulumConvention::kExact) {
  ReduceOptions options;
  options.convention = convention;
  return ReduceSession(ReadManifest(kThesisSession).session, options);
}

// Table 2's "Theoretical X max" column (PENDUL's sampled peaks, 3 decimals).
const std::map<std::string, std::vector<double>> kTable2Theoretical = {
    {"0.115", {0.068, 0.052, 0.039, 0.030, 0.023}}, {"0.234", {0.176, 0.117, 0.078, 0.052, 0.035}},
    {"0.323", {0.259, 0.169, 0.110, 0.072, 0.047}}, {"0.405", {0.293, 0.195, 0.129, 0.085, 0.057}},
    {"0.478", {0.345, 0.273, 0.215, 0.170, 0.134}}, {"0.598", {0.416, 0.312, 0.235, 0.176, 0.133}},
    {"0.713", {0.510, 0.411, 0.331, 0.267, 0.215}}, {"1.519", {0.893, 0.679, 0.516, 0.392, 0.298}},
};

TEST_CASE("thesis: Table 2's theoretical column is reproduced within 0.0015 in") {
  for (auto convention : {PendulumConvention::kExact, PendulumConvention::kThesis}) {
    const SessionResult result = ReduceThesis(convention);
    REQUIRE(result.FailedRuns() == 0);
    for (const auto& [id, published] : kTable2Theoretical) {
      const RunResult* run = result.FindRun(id);
      REQUIRE(run != nullptr);
      for (std::size_t n = 0; n < published.size(); ++n) {
        INFO("run " << id << " rebound " << n << " convention " << ConventionName(convention));
        CHECK(std::abs(run->fits.kelvin_voigt->predicted_xmax[n].value - published[n]) <=
              /*max_error_in=*/0.0015);
      }
    }
  }
}

TEST_CASE("thesis: Table 4's predicted and calculated columns are reproduced within 0.0015 in") {
  const SessionResult result = ReduceThesis();
  REQUIRE(result.predictions.size() == 1);
  const RunPrediction& p = result.predictions.front();
  CHECK(p.source_run == "0.323");
  CHECK(p.target_run == "0.405");
  const std::vector<double> predicted = {0.293, 0.191, 0.124, 0.081, 0.053};
  const std::vector<double> calculated = {0.293, 0.195, 0.129, 0.085, 0.057};
  REQUIRE(p.predicted.size() == predicted.size());
  for (std::size_t n = 0; n < predicted.size(); ++n) {
    INFO("rebound " << n);
    CHECK(std::abs(p.predicted[n] - predicted[n]) <= /*max_error_in=*/0.0015);
    CHECK(std::abs(p.calculated[n] - calculated[n]) <= /*max_error_in=*/0.0015);
  }
}

TEST_CASE("thesis: Table 3's K and % variation with the average contact time of 353.35 us") {
  const SessionResult result = ReduceThesis();
  REQUIRE(result.kelvin_voigt.has_value());
  const SessionKelvinVoigt& s = *result.kelvin_voigt;
  // The contact time in the sample was chosen for a mean K of 462000 lbf/in.
  CHECK(s.spread.average == Approx(462000.0).epsilon(1e-4));
  // Table 3, ordered by sqrt(xi): K and % variation (its own K avg 462000).
  const std::vector<double> k_published = {465000, 464000, 464000, 460000,
                                           460000, 460000, 460000, 459000};
  const std::vector<double> pct_published = {0.6, 0.4, 0.4, 0.4, 0.4, 0.4, 0.4, 0.6};
  std::vector<std::size_t> order(s.run_ids.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](auto a, auto b) { return s.sqrt_restitution[a] < s.sqrt_restitution[b]; });
  REQUIRE(order.size() == k_published.size());
  for (std::size_t row = 0; row < order.size(); ++row) {
    const std::size_t i = order[row];
    INFO("row " << row << " run " << s.run_ids[i]);
    CHECK(std::abs(s.stiffness[i] / k_published[row] - 1.0) <= /*max_rel_error=*/0.0025);
    CHECK(std::abs(s.spread.pct_variation[i] - pct_published[row]) <= /*max_points=*/0.25);
  }
}

TEST_CASE("thesis: eq. 40's line C = a (1 - b sqrt(xi)) from each run's own K is within 2 %") {
  const SessionResult result = ReduceThesis();
  REQUIRE(result.kelvin_voigt->damping_line.has_value());
  const DampingLine& line = *result.kelvin_voigt->damping_line;
  CHECK(std::abs(line.a.value / 77.44 - 1.0) <= /*max_rel_error=*/0.02);
  CHECK(std::abs(line.b.value / 1.014 - 1.0) <= /*max_rel_error=*/0.02);
  CHECK(line.a.sigma > 0.0);
  CHECK(line.points == 8);
}

TEST_CASE("thesis: the average-K option gives every run C from the mean K, its own fit kept") {
  Session session = ReadManifest(kThesisSession).session;
  const SessionResult own = ReduceSession(session, {});
  session.reduction.average_stiffness = true;
  const SessionResult result = ReduceSession(session, {});
  REQUIRE(result.kelvin_voigt.has_value());
  const SessionKelvinVoigt& table = *result.kelvin_voigt;
  REQUIRE(table.average_stiffness.has_value());
  const double average = table.spread.average;
  CHECK(table.average_stiffness->value == Approx(average).epsilon(1e-15));
  REQUIRE(table.run_ids.size() == result.runs.size());
  for (std::size_t i = 0; i < result.runs.size(); ++i) {
    const KelvinVoigtTwoPointFit& fit = *result.runs[i].fits.kelvin_voigt;
    // The run's own fit is what it was without the option.
    CHECK(fit.stiffness->value == own.runs[i].fits.kelvin_voigt->stiffness->value);
    CHECK(table.stiffness[i] == fit.stiffness->value);
    const double zeta = fit.damping_ratio.value;
    CHECK(table.damping[i] ==
          Approx(2.0 * zeta * std::sqrt(average * session.apparatus->mass)).epsilon(1e-14));
    CHECK(table.damping_sigma[i] > 0.0);
  }
}

TEST_CASE("reduce: a run whose rebounds grow fails with a diagnostic while the others reduce") {
  Session session = ReadManifest(kThesisSession).session;
  session.runs[0].rebounds = {0.052, 0.068, 0.04};  // rebound 1 exceeds rebound 0
  const SessionResult result = ReduceSession(session, {});
  CHECK(result.FailedRuns() == 1);
  CHECK_FALSE(result.runs[0].ok);
  CHECK_THAT(result.runs[0].Status(),
             Catch::Contains("exceeds") && Catch::Contains("fit_rebounds"));
  for (std::size_t i = 1; i < result.runs.size(); ++i) CHECK(result.runs[i].ok);
}

TEST_CASE("reduce: model peak times follow the pendulum's quarter and half periods") {
  const SessionResult result = ReduceThesis();
  const RunResult& run = *result.FindRun("0.405");
  // first_rebound = 1: rebound 0 is PENDUL's rebound 1, which peaks after a
  // quarter swing, one contact and half a swing: about tau_r (0.751 s).
  const double tau_r = M_PI * std::sqrt(22.0 / 385.644);
  CHECK(run.PeakTimes()[0] == Approx(tau_r).epsilon(1e-3));
  for (std::size_t n = 1; n < run.PeakTimes().size(); ++n) {
    CHECK(run.PeakTimes()[n] - run.PeakTimes()[n - 1] == Approx(tau_r).epsilon(1e-3));
  }
}

}  // namespace
}  // namespace impactlab
