// Tests of impact detection on signals whose impact instant is known exactly.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "signal/impact_detection.h"
#include "tests/signal/test_signals.h"

namespace impactlab {
namespace {

using testing::AddNoise;

constexpr double kRate = 1000.0;

// An accelerometer that integrates over each sample interval: quiet before
// `impact_s`, a spike carrying the velocity jump in the interval holding it, then
// a ring-down; a smaller start-up step at `start_s`.
std::vector<double> Accelerometer(double impact_s, double start_s, std::size_t n) {
  std::vector<double> a(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) {
    const double t0 = static_cast<double>(i - 1) / kRate, t1 = static_cast<double>(i) / kRate;
    if (t1 >= start_s) a[i] += 0.5;
    if (t0 < impact_s && impact_s <= t1) a[i] += 0.3 * kRate;  // 0.3 m/s in one sample
    if (t0 >= impact_s) {
      const double t = t0 - impact_s;
      a[i] += 5.0 * std::exp(-1.4 * t) * std::cos(2.0 * 3.14159265 * 11.5 * t);
    }
  }
  return a;
}

TEST_CASE("An impact's spike dates the impact to its sample interval", "[impact]") {
  const double impact_s = 1.2345;
  auto a = Accelerometer(impact_s, 0.2, 3000);
  AddNoise(a, 0.2, 1);
  const ImpactEstimate estimate =
      DetectImpact({{"a1", LogChannelKind::kAcceleration, a}}, 0.0, kRate, {});
  REQUIRE(estimate.found);
  CHECK(estimate.method == "accelerometer a1");
  CHECK(std::abs(estimate.time_s.value - impact_s) <= 0.5 / kRate);
  CHECK(estimate.time_s.sigma == Approx(1.0 / (kRate * std::sqrt(12.0))));
  CHECK(estimate.sample == 1235);
}

TEST_CASE("A ramped onset is dated to its start, not its peak", "[impact]") {
  // A sensor with a few samples' rise time.
  std::vector<double> a(2000, 0.0);
  const std::size_t onset = 800;
  for (std::size_t i = onset; i < a.size(); ++i) {
    const double k = static_cast<double>(i - onset);
    a[i] = 40.0 * std::min(1.0, (k + 1.0) / 4.0) * std::exp(-k / 300.0);
  }
  AddNoise(a, 0.1, 2);
  const ImpactEstimate estimate =
      DetectImpact({{"a1", LogChannelKind::kAcceleration, a}}, 10.0, kRate, {});
  REQUIRE(estimate.found);
  CHECK(std::abs(estimate.sample - static_cast<long long>(onset)) <= 1);
  CHECK(estimate.time_s.value == Approx(10.0 + (onset - 0.5) / kRate).margin(1.5 / kRate));
}

TEST_CASE("An encoder's velocity change dates the impact when no accelerometer does", "[impact]") {
  const double impact_s = 0.7777, before = 0.5, after = -0.05, quantum = 1e-4;
  std::vector<double> q(1500);
  for (std::size_t i = 0; i < q.size(); ++i) {
    const double t = static_cast<double>(i) / kRate;
    const double angle =
        t < impact_s ? 1.0 + before * t : 1.0 + before * impact_s + after * (t - impact_s);
    q[i] = quantum * std::floor(angle / quantum);
  }
  const ImpactEstimate estimate = DetectImpact({{"q1", LogChannelKind::kAngle, q}}, 0.0, kRate, {});
  REQUIRE(estimate.found);
  CHECK(estimate.method == "encoder q1");
  CHECK(estimate.time_s.value == Approx(impact_s).margin(1e-3));
  CHECK(std::abs(estimate.time_s.value - impact_s) < 4.0 * estimate.time_s.sigma + 1e-5);
  const ChannelImpact& channel = estimate.channels.at(0);
  CHECK(channel.velocity_before.value == Approx(before).margin(0.01));
  CHECK(channel.velocity_after.value == Approx(after).margin(0.01));
}

TEST_CASE("Noise alone holds no impact", "[impact]") {
  std::vector<double> a(3000, 0.0);
  AddNoise(a, 1.0, 4);
  const ImpactEstimate estimate =
      DetectImpact({{"a1", LogChannelKind::kAcceleration, a}}, 0.0, kRate, {});
  CHECK_FALSE(estimate.found);
  CHECK_FALSE(estimate.reason.empty());
  CHECK_FALSE(DetectImpact({}, 0.0, kRate, {}).found);
}

TEST_CASE("Impact options: the defaults pass Check and nonsense is refused", "[impact]") {
  std::string error;
  CHECK(ImpactDetectionOptions{}.Check(&error));
  CHECK_FALSE(ImpactDetectionOptions{.threshold_sigma = 0}.Check(&error));
  CHECK_THROWS_AS(DetectImpact({}, 0.0, 0.0, {}), std::invalid_argument);
}

}  // namespace
}  // namespace impactlab
