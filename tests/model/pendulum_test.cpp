#include "model/pendulum.h"

#include <cmath>
#include <numbers>

#include <catch2/catch.hpp>

#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using std::numbers::pi;
using testing::kG;

TEST_CASE("pendulum: small amplitudes approach the small-angle model") {
  const Pendulum exact{22.0, kG, PendulumConvention::kExact};
  const double w0 = std::sqrt(kG / 22.0);
  CHECK(HalfPeriod(exact, 1e-6) == Approx(pi / w0).epsilon(1e-14));
  CHECK(SpeedFromAmplitude(exact, 1e-6) == Approx(1e-6 * w0).epsilon(1e-12));
}

TEST_CASE("pendulum: exact half period grows with amplitude as K(sin(theta/2))") {
  const Pendulum exact{1.0, 9.80665, PendulumConvention::kExact};
  CHECK(HalfPeriod(exact, 0.5) > HalfPeriod(exact, 0.1));
  // X = L/2: theta_m = 30 deg, K(sin 15 deg) = 1.598142002112540 (mpmath, 30 digits).
  CHECK(HalfPeriod(exact, 0.5) ==
        Approx(2.0 * 1.598142002112540 / std::sqrt(9.80665)).epsilon(1e-14));
}

TEST_CASE("pendulum: amplitude and speed are inverse in both conventions") {
  for (auto convention : {PendulumConvention::kExact, PendulumConvention::kThesis}) {
    const Pendulum p{22.0, kG, convention};
    for (double x : {1e-9, 1e-3, 0.115, 1.519, 15.0}) {
      CHECK(AmplitudeFromSpeed(p, SpeedFromAmplitude(p, x)) == Approx(x).epsilon(1e-14));
    }
  }
}

TEST_CASE("pendulum: energy speed uses 2 sin^2(theta/2), exact for tiny angles") {
  const Pendulum thesis{22.0, kG, PendulumConvention::kThesis};
  // 1 - cos(X/L) would lose every digit here; 2 sin^2 keeps them.
  const double x = 1e-7;
  CHECK(SpeedFromPeakEnergy(thesis, x) == Approx(x * std::sqrt(kG / 22.0)).epsilon(1e-14));
}

TEST_CASE("pendulum: release swing starts at X0 and reaches equilibrium after a quarter period") {
  const Pendulum p{22.0, kG, PendulumConvention::kExact};
  const double x0 = 5.0;
  CHECK(ReleaseSwingDisplacement(p, x0, 0.0) == Approx(x0).epsilon(1e-14));
  CHECK(ReleaseSwingDisplacement(p, x0, 0.5 * HalfPeriod(p, x0)) == Approx(0.0).margin(1e-13));
  // A rebound through equilibrium at the release swing's speed peaks at X0.
  const double v = SpeedFromAmplitude(p, x0);
  CHECK(ReboundDisplacement(p, v, 0.5 * HalfPeriod(p, x0)) == Approx(x0).epsilon(1e-13));
}

TEST_CASE("pendulum: a rebound's state is its displacement and that displacement's rate") {
  for (auto convention : {PendulumConvention::kExact, PendulumConvention::kThesis}) {
    const Pendulum p{22.0, kG, convention};
    for (double x : {0.115, 1.519, 15.0}) {
      const double v = SpeedFromAmplitude(p, x), half = HalfPeriod(p, x);
      CHECK(ReboundState(p, v, 0.0).velocity == Approx(v).epsilon(1e-13));
      CHECK(ReboundState(p, v, 0.5 * half).velocity == Approx(0.0).margin(1e-9 * v));
      for (double f : {0.1, 0.3, 0.49, 0.51, 0.8, 0.97}) {
        const double t = f * half, h = 1e-6 * half;
        const SwingState state = ReboundState(p, v, t);
        CHECK(state.displacement == Approx(ReboundDisplacement(p, v, t)).epsilon(1e-15));
        const double rate =
            (ReboundDisplacement(p, v, t + h) - ReboundDisplacement(p, v, t - h)) / (2.0 * h);
        CHECK(state.velocity == Approx(rate).margin(1e-7 * v));
      }
    }
  }
}

TEST_CASE("pendulum: amplitude beyond the horizontal is a domain error") {
  const Pendulum p{1.0, 9.81, PendulumConvention::kExact};
  CHECK_THROWS_AS(SwingAngle(p, 1.0), std::domain_error);
  CHECK_THROWS_AS(AmplitudeFromSpeed(p, 2.0 * std::sqrt(9.81)), std::domain_error);
}

TEST_CASE("pendulum: a maximum or a speed no swing has is said as a value, in the throw's words") {
  const Pendulum exact{1.0, 9.81, PendulumConvention::kExact};
  const Pendulum thesis{1.0, 9.81, PendulumConvention::kThesis};
  // X = L/2: K(sin 15 deg) = 1.598142002112540, as above.
  CHECK(*HalfPeriodIfSwings(exact, 0.5) ==
        Approx(2.0 * 1.598142002112540 / std::sqrt(9.81)).epsilon(1e-14));
  for (const double x : {1.0, 1.5, -0.1, std::nan("")}) {
    CHECK_FALSE(HalfPeriodIfSwings(exact, x).has_value());
    CHECK_FALSE(SwingAmplitudeProblem(exact, x).empty());
  }
  // The thesis's half period is pi sqrt(L/g) whatever the amplitude, as HalfPeriod's.
  CHECK(*HalfPeriodIfSwings(thesis, 1.5) == Approx(pi / std::sqrt(9.81)).epsilon(1e-15));
  CHECK(SwingAmplitudeProblem(exact, 0.999).empty());
  try {
    SwingAngle(exact, 1.0);
    FAIL("SwingAngle took X = L");
  } catch (const std::domain_error& e) {
    CHECK(SwingAmplitudeProblem(exact, 1.0) == e.what());
  }
  // Exact: the horizontal is reached at v = 2 sqrt(gL) sin 45 deg = sqrt(2 g L).
  const double horizontal = std::sqrt(2.0 * 9.81);
  CHECK(SwingSpeedProblem(exact, 0.999 * horizontal).empty());
  CHECK_THAT(SwingSpeedProblem(exact, 1.001 * horizontal),
             Catch::Contains("would pass the horizontal"));
  CHECK_THAT(SwingSpeedProblem(thesis, std::sqrt(9.81)), Catch::Contains(">= L = 1"));
  CHECK_THAT(SwingSpeedProblem(exact, -1.0), Catch::Contains("must be >= 0"));
  try {
    AmplitudeFromSpeed(exact, 1.001 * horizontal);
    FAIL("AmplitudeFromSpeed passed the horizontal");
  } catch (const std::domain_error& e) {
    CHECK(SwingSpeedProblem(exact, 1.001 * horizontal) == e.what());
  }
}

}  // namespace
}  // namespace impactlab
