#include "fit/kelvin_voigt_response.h"

#include <algorithm>
#include <cmath>

#include <catch2/catch.hpp>

#include "model/kelvin_voigt.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using testing::kBarMass;
using testing::kPendulum;

// A run simulated from known K, C and its two-point fit. Session rebound 0
// is PENDUL's rebound `first_rebound`.
struct FittedSimulation {
  ReboundSequence truth;
  std::vector<double> xmax;  // session numbering
  KelvinVoigtTwoPointFit fit;
};
FittedSimulation Simulated(double x0, int first_rebound) {
  const KelvinVoigt kv{kBarMass, 462000.0, 9.0};
  FittedSimulation s;
  s.truth = SimulateRebounds(kPendulum, KelvinVoigtContactLaw(kv, Separation::kKinematic), x0, 6);
  s.xmax.assign(s.truth.xmax.begin() + first_rebound, s.truth.xmax.end());
  ReboundMeasurements m;
  m.xmax = s.xmax;
  m.contact_time = s.truth.contact.contact_time;
  s.fit = FitKelvinVoigtTwoPoint(kPendulum, kBarMass, m, {{0, 1}, Separation::kKinematic});
  return s;
}

TEST_CASE("kelvin_voigt_response: the model's peak times are the simulated run's") {
  const double x0 = 0.405;
  for (int first_rebound : {0, 1, 2}) {
    INFO("first_rebound = " << first_rebound);
    const FittedSimulation s = Simulated(x0, first_rebound);
    REQUIRE(s.fit.ok);
    const std::vector<double> peaks = ModelPeakTimes(kPendulum, {s.xmax, x0, first_rebound}, s.fit);
    REQUIRE(peaks.size() == s.xmax.size());
    for (std::size_t n = 0; n < peaks.size(); ++n) {
      CHECK(peaks[n] == Approx(s.truth.peak_time[n + first_rebound]).epsilon(1e-9));
    }
  }
}

TEST_CASE("kelvin_voigt_response: the model's history peaks at the measured maxima") {
  const double x0 = 0.405;
  const FittedSimulation s = Simulated(x0, 1);
  REQUIRE(s.fit.ok);
  const SampledHistory h = ModelResponse(kPendulum, kBarMass, {s.xmax, x0, 1}, s.fit);
  REQUIRE(h.time.size() == h.displacement.size());
  CHECK(h.time.size() > 2900);
  // Released from the amplitude the fit extrapolates back to: X0 itself.
  CHECK(h.displacement.front() == Approx(x0).epsilon(1e-9));
  // Each rebound's largest sample lies within a sample step of its maximum.
  for (std::size_t n = 0; n < s.xmax.size(); ++n) {
    const int pendul = static_cast<int>(n) + 1;
    const double start = s.truth.start_time[pendul];
    const double end = start + s.truth.duration[pendul];
    double highest = 0.0;
    for (std::size_t i = 0; i < h.time.size(); ++i) {
      if (h.time[i] > start && h.time[i] < end) highest = std::max(highest, h.displacement[i]);
    }
    CHECK(highest == Approx(s.xmax[n]).epsilon(1e-4));
  }
}

}  // namespace
}  // namespace impactlab
