// A contact pulse whose edges settle as RC exponentials, as a real contact
// circuit's do (a time constant of a microsecond or two: a few hundredths of
// a division on a 50 us/div sweep), photographed at an angle (perspective,
// barrel distortion). The circuit leaves its level at once and approaches
// the other one, so the level it reaches begins 3-4 time constants after the
// one it leaves ends: the two levels' ends are no mirror images, and taking
// either's step for the edge put the rise and the fall up to 0.1 division
// apart (the width 0.4-0.6 % short, 12-19 standard errors, on external phone
// photos). The half-height crossings are RC ln 2 after the switching
// instants on both edges, so the width between them is the contact time.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <opencv2/core/utility.hpp>

#include "digitize/digitize.h"
#include "digitize/level_jump.h"
#include "render/oscillograph.h"
#include "tests/digitize/photo_scenes.h"

namespace impactlab {
namespace {

using testing::kContactStartS;
using testing::kContactTimePerDiv;

// A level's row along the sweep: a beam of Gaussian section whose level
// runs up to `end_px` (leaving) or from it (reaching), through a saturating
// tone curve.
std::vector<double> LevelRow(const std::vector<double>& offsets, double end_px, bool leaving) {
  std::vector<double> row;
  for (const double u : offsets) {
    const double beyond = leaving ? u - end_px : end_px - u;
    const double z = std::max(beyond, 0.0) / 1.5;
    row.push_back(1.0 - std::exp(-1.5 * (0.1 + std::exp(-0.5 * z * z))));
  }
  return row;
}

}  // namespace

TEST_CASE("level jump: each level's own end is found apart from the other's") {
  std::vector<double> offsets;
  for (double u = -30.0; u <= 30.0; u += 0.5) offsets.push_back(u);
  digitize::LevelJumpSearch search;
  search.centre_lo_px = -20.0;
  search.centre_hi_px = 20.0;
  search.half_window_px = 9.0;
  // Switched: the reaching level begins where the leaving one ends; each
  // row's half crossing lies beyond its level's end, so the reaching row's
  // comes first.
  const digitize::LevelJump switched = digitize::FitLevelJump(
      offsets, LevelRow(offsets, -3.0, true), LevelRow(offsets, -3.0, false), search);
  REQUIRE(std::isfinite(switched.leaving_end_px));
  REQUIRE(std::isfinite(switched.reaching_start_px));
  const double own = switched.leaving_end_px - (-3.0);  // the beam's end to its half crossing
  CHECK(own > 0.0);
  CHECK(switched.reaching_start_px == Approx(-3.0 - own).margin(0.05));
  // Settling slowly: the reaching level begins 12 px after the leaving one
  // ends.
  const digitize::LevelJump settling = digitize::FitLevelJump(
      offsets, LevelRow(offsets, -3.0, true), LevelRow(offsets, 9.0, false), search);
  CHECK(settling.leaving_end_px == Approx(switched.leaving_end_px).margin(0.05));
  CHECK(settling.reaching_start_px == Approx(9.0 - own).margin(0.05));
}

TEST_CASE("digitize: a pulse with RC edges on a phone photo is timed between like points") {
  cv::setNumThreads(1);
  struct Case {
    double rise_div, fall_div, rc_s;
    std::uint64_t seed;
  };
  // Edges clear of the grid lines, beside them and on them; time constants
  // of 1 and 2 us (0.02 and 0.04 division, 3-6 px at 1600 px).
  const std::vector<Case> cases = {
      {1.45, 8.53, 1.0e-6, 1},
      {1.45, 8.53, 2.0e-6, 2},
      {1.06, 8.07, 1.8e-6, 3},
      {2.35, 7.62, 1.5e-6, 4},
      {0.94, 8.03, 1.8e-6, 5},
      // Both half-height crossings on a grid line (the levels' ends only
      // bound them; the stroke's fit beside a line times them).
      {1.972, 8.972, 2.0e-6, 7},
  };
  for (const Case& c : cases) {
    const testing::RunScene run = testing::ContactRcScene(c.rise_div, c.fall_div, c.rc_s);
    RenderOptions options;
    options.style = PhotoStyle::kPhone;
    options.width_px = 1600;
    options.seed = c.seed;
    options.tilt_deg = 25.0;
    options.barrel_k1 = -0.05;
    const RenderedPhoto photo = RenderOscillograph(run.scene, options);
    const DigitizeResult result = DigitizePhoto({photo.image, "rc.png"}, {10, 8}, run.requests, {});
    INFO("edges at " << c.rise_div << " and " << c.fall_div << " div, RC " << c.rc_s * 1e6
                     << " us, seed " << c.seed);
    REQUIRE(result.pulses[2]);
    const ContactPulseFit& pulse = *result.pulses[2];
    const double truth_s = (c.fall_div - c.rise_div) * kContactTimePerDiv;
    const double error = pulse.pulse.width_s.value - truth_s;
    INFO("width " << pulse.pulse.width_s.value * 1e6 << " us, error " << 100.0 * error / truth_s
                  << " %, sigma " << 100.0 * pulse.pulse.width_s.sigma / truth_s << " %");
    CHECK(pulse.rise.from_image);
    CHECK(pulse.fall.from_image);
    CHECK(std::abs(error) < 1e-3 * truth_s);
    CHECK(std::abs(error) < 3.0 * pulse.pulse.width_s.sigma);
  }
}

}  // namespace impactlab
