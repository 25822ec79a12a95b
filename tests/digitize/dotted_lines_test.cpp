// The dots of a ridge image (digitize/dotted_lines.h): a digital scope's
// dotted grid line kept, solid strokes of any direction (a menu box's edge, a
// trace, the frame) dropped.
#include <cmath>
#include <numbers>

#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>

#include "digitize/dotted_lines.h"

namespace impactlab::digitize {
namespace {

constexpr float kDot = 0.5f;

// A row of single lit pixels `spacing` apart at row `y`, from x0 to x1.
void DrawDottedRow(cv::Mat1f& ridge, int y, int x0, int x1, int spacing) {
  for (int x = x0; x <= x1; x += spacing) ridge(y, x) = kDot;
}

float MaxIn(const cv::Mat1f& image, const cv::Rect& area) {
  double max = 0.0;
  cv::minMaxLoc(image(area), nullptr, &max);
  return static_cast<float>(max);
}

TEST_CASE("dots of a dotted grid line are kept, straight strokes in any direction dropped") {
  cv::Mat1f ridge = cv::Mat1f::zeros(120, 200);
  DrawDottedRow(ridge, 20, 10, 190, 6);  // the grid's dots, six working pixels apart
  // Strokes, as a phone photo's working copy shows a display's line one or
  // two display pixels wide (two or three working pixels, antialiased): a
  // horizontal box edge, a vertical one, lines at 20 and 67 degrees. (A
  // stroke one pixel wide and between two of the eight directions leaves
  // some of its staircase's pixels.)
  cv::line(ridge, {10, 50}, {190, 50}, kDot, 2, cv::LINE_AA);
  cv::line(ridge, {100, 60}, {100, 115}, kDot, 2, cv::LINE_AA);
  for (const double degrees : {20.0, 67.0}) {
    const double a = degrees * std::numbers::pi / 180.0;
    const cv::Point from(30, 110);
    const cv::Point to(30 + static_cast<int>(std::lround(40 * std::cos(a))),
                       110 - static_cast<int>(std::lround(40 * std::sin(a))));
    cv::line(ridge, from, to, kDot, 2, cv::LINE_AA);
  }
  const cv::Mat1f dots = DotsOf(ridge, 0.1f);
  // Every dot of the dotted row is kept at its full height.
  int kept = 0, drawn = 0;
  for (int x = 10; x <= 190; x += 6, ++drawn) kept += dots(20, x) == kDot;
  CHECK(kept == drawn);
  // The strokes leave nothing above the floor, but for a pixel at their ends.
  CHECK(MaxIn(dots, {15, 49, 170, 3}) == 0.0f);  // the horizontal edge, ends aside
  CHECK(MaxIn(dots, {99, 65, 3, 45}) == 0.0f);   // the vertical one
  const int left_of_strokes = cv::countNonZero(dots(cv::Rect(0, 30, 200, 90)));
  INFO(left_of_strokes << " pixels left of the strokes");
  CHECK(left_of_strokes <= 8);  // two ends a stroke at most
}

TEST_CASE("dots below the floor are dropped") {
  cv::Mat1f ridge = cv::Mat1f::zeros(40, 80);
  DrawDottedRow(ridge, 20, 10, 70, 6);
  CHECK(cv::countNonZero(DotsOf(ridge, 0.6f)) == 0);
  CHECK(cv::countNonZero(DotsOf(ridge, 0.4f)) == 11);
}

}  // namespace
}  // namespace impactlab::digitize
