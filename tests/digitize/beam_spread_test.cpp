// The spread of a trace's exposure about its path (digitize/beam_spread.h)
// from profiles made in closed form: a Gaussian cross-section whose exposure
// falls as 1 / writing speed, through a saturating tone curve, with noise.
#include <cmath>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

#include "digitize/beam_spread.h"

namespace impactlab::digitize {
namespace {

constexpr double kSpreadPx2 = 1.7, kSpreadBackground = 0.05, kStepPx = 0.5;

// A film's shoulder and toe: (1 - exp(-3 E))^0.6.
double FilmTone(double exposure) { return std::pow(1.0 - std::exp(-3.0 * exposure), 0.6); }

// The profile across a trace written `speed` times faster than the sweep.
Profile Across(double speed, double noise, std::mt19937& random) {
  std::normal_distribution<double> normal(0.0, noise);
  Profile profile;
  profile.direction = {0.0, 1.0};
  profile.step_px = kStepPx;
  profile.start_px = -10.0;
  for (double u = -10.0; u <= 10.0 + 1e-9; u += kStepPx) {
    const double exposure = std::exp(-0.5 * u * u / kSpreadPx2) / speed;
    profile.values.push_back(
        static_cast<float>(kSpreadBackground + FilmTone(exposure) + normal(random)));
  }
  return profile;
}

LineCentre CentreOf(double speed) {
  LineCentre centre;
  centre.found = true;
  centre.offset_px = 0.0;
  centre.background = kSpreadBackground;
  centre.height = FilmTone(1.0 / speed);
  return centre;
}

std::vector<SpreadPoint> Points(double fastest, double noise, unsigned seed) {
  std::mt19937 random(seed);
  std::vector<SpreadPoint> points;
  const double typical = FilmTone(1.0);
  for (int i = 0; i < 200; ++i) {
    const double speed = std::pow(fastest, i / 199.0);
    points.push_back(
        {speed, MeasureLevelHalfWidths(Across(speed, noise, random), CentreOf(speed), typical)});
  }
  return points;
}

}  // namespace

TEST_CASE("beam spread: the width's fall with writing speed gives the spread, whatever the tone") {
  const SpreadEstimate estimate = EstimateSpread(Points(5.0, 0.0, 1));
  REQUIRE(estimate.found);
  // The saturated line is much wider than its spread would make it (level 6
  // is half its height)...
  std::mt19937 random(1);
  const double half_max_px =
      MeasureLevelHalfWidths(Across(1.0, 0.0, random), CentreOf(1.0), FilmTone(1.0))[6];
  CHECK(std::pow(2.0 * half_max_px / 2.3548, 2) > 1.5 * kSpreadPx2);
  // ...but the spread comes out to the reading's interpolation.
  CHECK(estimate.variance_px2 == Approx(kSpreadPx2).epsilon(0.02));
}

TEST_CASE("beam spread: with noise the spread lies within a few of its sigmas") {
  int within = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const SpreadEstimate estimate = EstimateSpread(Points(5.0, 0.02, seed));
    REQUIRE(estimate.found);
    CHECK(estimate.sigma_px2 < 0.2 * kSpreadPx2);
    within += std::abs(estimate.variance_px2 - kSpreadPx2) < 2.5 * estimate.sigma_px2;
  }
  CHECK(within >= 17);
}

TEST_CASE("beam spread: too narrow a range of writing speeds measures nothing") {
  CHECK_FALSE(EstimateSpread(Points(1.2, 0.01, 1)).found);
  CHECK_FALSE(EstimateSpread({}).found);
}

}  // namespace impactlab::digitize
