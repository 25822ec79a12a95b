// The halftone screen search (digitize/halftone.h) on figures printed on
// blank paper: dots only where the figure has ink (its grid lines and
// traces), the prints whose screen is faintest in the spectrum, and whose
// screen the search must find through its first look at two tiles alone.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>

#include "digitize/halftone.h"
#include "photo_scenes.h"
#include "render/oscillograph.h"

namespace impactlab {
namespace {

// `photo` printed on blank paper through a screen of `period_px` turned
// `angle_deg`: round dots whose area follows the photo's brightness (bright
// traces print dark), none where the photo is dark, then a scanner's blur.
cv::Mat1b PrintedOnBlankPaper(const cv::Mat& photo, double period_px, double angle_deg) {
  const double c = std::cos(angle_deg * std::numbers::pi / 180.0);
  const double s = std::sin(angle_deg * std::numbers::pi / 180.0);
  cv::Mat1f coverage;
  photo.convertTo(coverage, CV_32F, 1.0 / 255);
  cv::GaussianBlur(coverage, coverage, cv::Size(), 0.5 * period_px);
  cv::Mat1b printed(photo.size());
  for (int y = 0; y < printed.rows; ++y) {
    for (int x = 0; x < printed.cols; ++x) {
      const double a = (c * x + s * y) / period_px, b = (-s * x + c * y) / period_px;
      const double spot = 0.5 * (std::cos(2 * std::numbers::pi * a) +
                                 std::cos(2 * std::numbers::pi * b));  // -1 .. 1
      const double ink = std::clamp(1.6 * coverage(y, x) - 0.1, 0.0, 1.0);
      printed(y, x) = ink > 0.0 && spot > 1.0 - 2.0 * ink ? 40 : 225;
    }
  }
  cv::GaussianBlur(printed, printed, cv::Size(), 0.6);
  return printed;
}

TEST_CASE("halftone: a figure printed on blank paper has its screen found, at any period and angle",
          "[digitize][halftone]") {
  const testing::RunScene run = testing::StandardRunScene();
  const RenderedPhoto photo = RenderOscillograph(run.scene, testing::CleanOptions(2000, 9, true));
  REQUIRE_FALSE(digitize::FindHalftoneScreen(photo.image).has_value());
  for (const double period_px : {3.2, 4.6, 7.0}) {
    for (const double angle_deg : {0.0, 15.0, 45.0}) {
      CAPTURE(period_px, angle_deg);
      const auto screen =
          digitize::FindHalftoneScreen(PrintedOnBlankPaper(photo.image, period_px, angle_deg));
      REQUIRE(screen.has_value());
      // A coarser screen may be taken at one of its lattice's harmonics (the
      // 7 px one here at 7 / sqrt(2) and 7 / sqrt(5) px): still a screen, low-passed
      // away, but its period is read only for the finer ones.
      if (period_px < 6.0) CHECK(screen->period_px == Approx(period_px).epsilon(0.04));
    }
  }
}

}  // namespace
}  // namespace impactlab
