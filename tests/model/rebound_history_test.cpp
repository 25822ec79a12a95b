#include "model/rebound_history.h"

#include <cmath>
#include <numbers>

#include <catch2/catch.hpp>

#include "model/kelvin_voigt.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using testing::kBarMass;
using testing::kG;

TEST_CASE("rebound_history: thesis convention gives A_N = X0 e^N and PENDUL's timing") {
  const Pendulum p{22.0, kG, PendulumConvention::kThesis};
  const KelvinVoigtContactLaw law({kBarMass, 462000.0, 10.0}, Separation::kKinematic);
  const ReboundSequence seq = SimulateRebounds(p, law, 0.5, 5);
  const double e = seq.contact.restitution;
  const double tau_r = std::numbers::pi * std::sqrt(22.0 / kG);
  const double tau_c = seq.contact.contact_time;
  for (int n = 0; n <= 5; ++n) {
    CHECK(seq.xmax[n] == Approx(0.5 * std::pow(e, n)).epsilon(1e-14));
  }
  for (int n = 1; n <= 5; ++n) {
    // Impact n starts at (n - 1/2) tau_r + (n - 1) tau_c (physics.md).
    CHECK(seq.impact_time[n - 1] == Approx((n - 0.5) * tau_r + (n - 1) * tau_c).epsilon(1e-14));
    CHECK(seq.peak_time[n] == Approx(n * tau_r + n * tau_c).epsilon(1e-14));
  }
}

TEST_CASE("rebound_history: sampled history peaks at the analytic maxima and is continuous") {
  const Pendulum p{22.0, kG, PendulumConvention::kExact};
  const KelvinVoigtContactLaw law({kBarMass, 462000.0, 10.0}, Separation::kKinematic);
  const ReboundSequence seq = SimulateRebounds(p, law, 1.519, 4);
  for (int n = 1; n <= 4; ++n) {
    CHECK(HistoryDisplacement(seq, p, law, seq.peak_time[n]) == Approx(seq.xmax[n]).epsilon(1e-12));
    // Just inside the contact the displacement is a tiny compression (negative).
    const double during = HistoryDisplacement(seq, p, law, seq.impact_time[n - 1] + 1e-5);
    CHECK(during < 0.0);
    CHECK(during > -1e-3);
  }
  const SampledHistory h = SampleHistory(seq, p, law, 1e-3);
  double sampled_max = 0.0;
  for (std::size_t i = 0; i < h.time.size(); ++i) {
    if (h.time[i] > seq.start_time[2] && h.time[i] < seq.start_time[2] + seq.duration[2]) {
      sampled_max = std::max(sampled_max, h.displacement[i]);
    }
  }
  // PENDUL printed sampled maxima, which read low; the analytic peak bounds them.
  CHECK(sampled_max <= seq.xmax[2]);
  CHECK(sampled_max > seq.xmax[2] * (1.0 - 1e-4));
}

TEST_CASE("rebound_history: exact rebounds of decreasing amplitude get shorter") {
  const Pendulum p{22.0, kG, PendulumConvention::kExact};
  const KelvinVoigtContactLaw law({kBarMass, 462000.0, 10.0}, Separation::kKinematic);
  const ReboundSequence seq = SimulateRebounds(p, law, 15.0, 3);
  CHECK(seq.duration[1] > seq.duration[2]);
  CHECK(seq.duration[2] > seq.duration[3]);
}

}  // namespace
}  // namespace impactlab
