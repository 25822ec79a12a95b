// A contact trace whose pulse level runs along the centre axis of a small
// photo. The axis carries tick marks every 0.2 division, and a tick's light
// is taken to reach 1.5 grid-line widths either side of it: at about 30 px a
// division that covers every place between two ticks, and a profile across
// the trace there, lit by a tick at the trace's core, was skipped. The
// bright level was then read only beside the division lines, where no tick
// is drawn (randomised seed 1004's run 0.405: 26 samples in clumps a
// division apart, "the contact trace shows no step above its noise").
#include <cmath>
#include <vector>

#include <catch2/catch.hpp>
#include <opencv2/core/utility.hpp>

#include "digitize/digitize.h"
#include "render/oscillograph.h"
#include "tests/digitize/photo_scenes.h"

namespace impactlab {

TEST_CASE("digitize: a contact level along the centre axis of a small photo is read along it") {
  cv::setNumThreads(1);
  // Levels 0.05 and 2.45 V at 2 V/div: the pulse level 0.06 division above
  // the centre axis, the rest level 1.14 divisions below it.
  constexpr double kRiseDiv = 2.1, kFallDiv = 9.07, kZeroDiv = -1.165;
  testing::RunScene run = testing::ContactPulseScene(kRiseDiv, kFallDiv);
  ScreenTrace contact = run.scene.traces[2];
  contact.settings.zero_div = kZeroDiv;
  contact.settings.band_div = {-1.5, 0.5};
  run.scene.traces = {contact};
  run.requests = {{contact.name, contact.settings}};
  for (const int width_px : {400, 450}) {
    RenderOptions options = testing::CleanOptions(width_px, 4);
    const RenderedPhoto photo = RenderOscillograph(run.scene, options);
    const DigitizeResult result =
        DigitizePhoto({photo.image, "axis.png"}, {10, 8}, run.requests, {});
    INFO(width_px << " px wide, " << result.graticule.px_per_div
                  << " px a division: " << result.Failure());
    REQUIRE(result.ok);
    const DigitizedTrace& trace = result.traces[0];
    // The pulse level's samples cover its length, not a clump a division.
    int on_level = 0;
    for (const cv::Point2d& p : trace.screen_div) {
      if (p.x > kRiseDiv + 0.1 && p.x < kFallDiv - 0.1 && std::abs(p.y - 0.06) < 0.02) ++on_level;
    }
    const double step_div = 1.0 / result.graticule.px_per_div;
    CHECK(on_level * step_div > 0.8 * (kFallDiv - kRiseDiv - 0.2));
    // And its width is timed against the truth.
    REQUIRE(result.pulses[0]);
    const Estimate& width = result.pulses[0]->pulse.width_s;
    const double truth_s = (kFallDiv - kRiseDiv) * testing::kContactTimePerDiv;
    INFO("width " << width.value * 1e6 << " +- " << width.sigma * 1e6 << " us, truth "
                  << truth_s * 1e6);
    CHECK(std::abs(width.value - truth_s) < 0.01 * truth_s);
    CHECK(std::abs(width.value - truth_s) < 4.0 * width.sigma);
  }
}

}  // namespace impactlab
