// Rebound anomalies against a history whose durations and maxima are exact
// (the rebound history of a Kelvin-Voigt contact): none there; a raised
// maximum and a stretched swing are marked with their distance in sigmas.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "model/kelvin_voigt.h"
#include "model/rebound_history.h"
#include "rebounds/rebound_anomalies.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using testing::kPendulum;

struct Exact {
  std::vector<double> xmax, xmax_sigma, duration, duration_sigma;
};

Exact ExactRebounds() {
  const double mass = 2.23 / 385.644;
  const KelvinVoigtContactLaw law(KelvinVoigtFromRates(mass, {8900.0, 0.1}),
                                  Separation::kKinematic);
  const ReboundSequence seq = SimulateRebounds(kPendulum, law, 0.4, 6);
  Exact e;
  for (std::size_t n = 1; n < seq.xmax.size(); ++n) {  // session rebound 0 = thesis rebound 1
    e.xmax.push_back(seq.xmax[n]);
    e.xmax_sigma.push_back(5e-4);
    e.duration.push_back(seq.duration[n]);
    e.duration_sigma.push_back(1e-3);
  }
  return e;
}

}  // namespace

TEST_CASE("A free pendulum's rebounds show no anomaly", "[anomalies]") {
  const Exact e = ExactRebounds();
  CHECK(
      FindReboundAnomalies(kPendulum, e.xmax, e.xmax_sigma, e.duration, e.duration_sigma).empty());
}

TEST_CASE("A maximum above its predecessor by more than 3 sigma is marked", "[anomalies]") {
  Exact e = ExactRebounds();
  e.xmax[3] = e.xmax[2] + 0.0025;  // 3.5 combined sigma above rebound 2
  const auto found =
      FindReboundAnomalies(kPendulum, e.xmax, e.xmax_sigma, e.duration, e.duration_sigma);
  REQUIRE(found.size() >= 1);
  CHECK(found.front().rebound == 3);
  CHECK(found.front().why.find("exceeds rebound 2") != std::string::npos);
  CHECK(found.front().why.find("by 3.5 sigma") != std::string::npos);
  // Within the uncertainty: not marked.
  e.xmax[3] = e.xmax[2] + 0.0015;
  for (const auto& a : FindReboundAnomalies(kPendulum, e.xmax, e.xmax_sigma, {}, {})) {
    CHECK(a.rebound != 3);
  }
  // Typed-in maxima without sigmas: any rise is marked.
  CHECK(FindReboundAnomalies(kPendulum, {0.3, 0.2, 0.21}, {}, {}, {}).size() == 1);
}

TEST_CASE("A rebound lasting longer than the pendulum's half period allows is marked",
          "[anomalies]") {
  Exact e = ExactRebounds();
  e.duration[1] += 0.005;  // 5 sigma of the duration
  const auto found =
      FindReboundAnomalies(kPendulum, e.xmax, e.xmax_sigma, e.duration, e.duration_sigma);
  REQUIRE(found.size() == 1);
  CHECK(found.front().rebound == 1);
  CHECK(found.front().why.find("sigma longer") != std::string::npos);
  // Unknown duration sigma: not checked.
  e.duration_sigma.assign(e.duration.size(), 0.0);
  CHECK(
      FindReboundAnomalies(kPendulum, e.xmax, e.xmax_sigma, e.duration, e.duration_sigma).empty());
}

TEST_CASE("The anomaly threshold keeps a session's false alarms at the stated rate",
          "[anomalies]") {
  CHECK(AnomalyThreshold(0.01, 24) == Approx(3.529).margin(1e-3));
  CHECK(AnomalyThreshold(0.01, 60) == Approx(3.765).margin(1e-3));
  // Sessions of 24 tests with honest (standard normal) errors: about 1 % of
  // them raise any alarm.
  std::mt19937 rng(11);
  std::normal_distribution<double> z(0.0, 1.0);
  const double threshold = AnomalyThreshold(0.01, 24);
  int alarms = 0;
  const int sessions = 40000;
  for (int s = 0; s < sessions; ++s) {
    bool any = false;
    for (int k = 0; k < 24; ++k) any = std::abs(z(rng)) > threshold || any;
    alarms += any;
  }
  CHECK(alarms / static_cast<double>(sessions) == Approx(0.01).margin(0.0015));
  // The tests counted: each maximum after the first, each duration with a sigma.
  CHECK(CountReboundTests({0.3, 0.2, 0.1}, {0.7, 0.7, 0.7}, {1e-3, 0.0, 1e-3}) == 4);
}

}  // namespace impactlab
