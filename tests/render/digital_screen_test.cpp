// Tests of the digital scope screen style against its own truth: the
// waveforms and the dotted graticule lie where the mapping says, in the
// channels' colours.
#include <cmath>
#include <numbers>
#include <vector>

#include <catch2/catch.hpp>
#include <opencv2/core.hpp>

#include "render/oscillograph.h"
#include "tests/render/sweep_settings.h"

namespace impactlab {
namespace {

// A decaying swing on channel 1 (yellow) and a slow ramp on channel 2 (cyan).
OscillographScene SwingScene() {
  OscillographScene scene;
  ScreenTrace right{"right", {}, {}, testing::SweepSettings(0.5, 0.2, 1.5)};
  ScreenTrace left{"left", {}, {}, testing::SweepSettings(0.5, 0.5, -2.5)};
  for (int i = 0; i <= 4000; ++i) {
    const double t = 5.0 * i / 4000;
    right.time_s.push_back(t);
    right.volts.push_back(0.4 * std::exp(-0.3 * t) * std::cos(2.0 * std::numbers::pi * t / 1.5));
    left.time_s.push_back(t);
    left.volts.push_back(0.1 * t);
  }
  scene.traces = {right, left};
  return scene;
}

cv::Vec3b PixelAt(const cv::Mat& image, cv::Point2d p) {
  return image.at<cv::Vec3b>(static_cast<int>(std::lround(p.y)),
                             static_cast<int>(std::lround(p.x)));
}

double LumaOf(const cv::Vec3b& bgr) { return 0.114 * bgr[0] + 0.587 * bgr[1] + 0.299 * bgr[2]; }

TEST_CASE("digital screen: each waveform lies where the truth says, in its channel's colour") {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    RenderOptions options;
    options.style = PhotoStyle::kDigital;
    options.seed = seed;
    options.width_px = 1800;
    const OscillographScene scene = SwingScene();
    const RenderedPhoto photo = RenderOscillograph(scene, options);
    REQUIRE(photo.image.type() == CV_8UC3);
    REQUIRE(photo.traces.size() == 2);
    int on_brighter = 0, yellow = 0, cyan = 0, checked = 0;
    for (std::size_t t = 0; t < 2; ++t) {
      const TraceTruth& truth = photo.traces[t];
      REQUIRE(truth.centre_px.size() > 100);
      for (std::size_t i = 0; i < truth.screen_div.size(); i += 97) {
        const cv::Point2d s = truth.screen_div[i];
        const cv::Vec3b on = PixelAt(photo.image, truth.centre_px[i]);
        // A third of a division off the waveform: the screen's dark ground
        // (or a dot of the graticule, far dimmer than a waveform).
        const cv::Vec3b off =
            PixelAt(photo.image, photo.ImageFromScreen(s + cv::Point2d(0.0, 0.33)));
        on_brighter += LumaOf(on) > LumaOf(off) + 40.0;
        if (t == 0) yellow += on[2] > on[0] + 30 && on[1] > on[0] + 30;  // red and green over blue
        if (t == 1) cyan += on[0] > on[2] + 30 && on[1] > on[2] + 30;    // blue and green over red
        ++checked;
      }
    }
    INFO("seed " << seed << ": " << on_brighter << ", " << yellow << " + " << cyan << " of "
                 << checked);
    CHECK(on_brighter >= 0.9 * checked);
    CHECK(yellow + cyan >= 0.8 * checked);
  }
}

TEST_CASE("digital screen: the graticule is dotted, a dot every fifth of a division") {
  // On a division line the dots stand out of the ground; between two dots
  // along the line (a tenth of a division from each) the ground shows.
  RenderOptions options;
  options.style = PhotoStyle::kDigital;
  options.seed = 3;
  options.width_px = 2400;
  options.tilt_deg = 0.0;
  options.blur_px = 0.5;
  const RenderedPhoto photo = RenderOscillograph(SwingScene(), options);
  int dots_brighter = 0, checked = 0;
  for (int x = 1; x <= 9; x += 2) {
    for (double y = -3.4; y <= -0.6; y += 0.2) {  // clear of the waveforms and the centre axis
      const double dot = LumaOf(PixelAt(photo.image, photo.ImageFromScreen({double(x), y})));
      const double gap = LumaOf(PixelAt(photo.image, photo.ImageFromScreen({double(x), y + 0.1})));
      dots_brighter += dot > gap + 10.0;
      ++checked;
    }
  }
  INFO(dots_brighter << " of " << checked);
  CHECK(dots_brighter >= 0.8 * checked);
}

TEST_CASE("digital screen: the same seed draws the same photo") {
  RenderOptions options;
  options.style = PhotoStyle::kDigital;
  options.seed = 7;
  options.width_px = 800;
  const RenderedPhoto a = RenderOscillograph(SwingScene(), options);
  const RenderedPhoto b = RenderOscillograph(SwingScene(), options);
  CHECK(cv::norm(a.image, b.image, cv::NORM_INF) == 0.0);
  CHECK(a.image.cols == 800);
}

}  // namespace
}  // namespace impactlab
