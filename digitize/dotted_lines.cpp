#include "digitize/dotted_lines.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace impactlab::digitize {

namespace {

// A straight segment of `length` pixels through the kernel's centre at
// `angle_rad`, one pixel per step along its longer axis.
cv::Mat Segment(int length, double angle_rad) {
  cv::Mat1b kernel = cv::Mat1b::zeros(length, length);
  const double half = 0.5 * (length - 1);
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  const double step = 1.0 / std::max(std::abs(c), std::abs(s));
  for (double r = -half * step; r <= half * step + 1e-9; r += step) {
    const int x = static_cast<int>(std::lround(half + r * c));
    const int y = static_cast<int>(std::lround(half + r * s));
    if (x >= 0 && y >= 0 && x < length && y < length) kernel(y, x) = 1;
  }
  return kernel;
}

}  // namespace

cv::Mat1f DotsOf(const cv::Mat1f& ridge, float floor) {
  // Eight directions, 22.5 degrees apart: a stroke between two of them still
  // holds a segment within half a pixel of its course over five pixels.
  constexpr int kDirections = 8;
  cv::Mat1f strokes = cv::Mat1f::zeros(ridge.size());
  cv::Mat1f opened;
  for (int k = 0; k < kDirections; ++k) {
    const double angle = k * std::numbers::pi / kDirections;
    cv::morphologyEx(ridge, opened, cv::MORPH_OPEN, Segment(kDotStrokePx, angle));
    strokes = cv::max(strokes, opened);
  }
  cv::Mat1f dots = ridge - strokes;
  dots.setTo(0.0f, dots < floor);
  return dots;
}

namespace {

constexpr double kOuterLineShare = 0.25;

// How high the ridge stands along a line of the screen: the mean over
// places 0.05 division apart of the highest ridge pixel within one of it.
double LineStrength(const PreparedPhoto& photo, const GraticuleFit& fit, int family,
                    double line_div) {
  const cv::Mat1f& ridge = photo.ridge;
  const int other = 1 - family;
  const double lo = other == 0 ? 0.0 : -0.5 * fit.divisions[1];
  const double hi = lo + fit.divisions[other];
  constexpr double kStepDiv = 0.05;
  double sum = 0.0;
  int count = 0;
  for (double t = lo; t <= hi + 1e-9; t += kStepDiv) {
    const cv::Point2d screen = family == 0 ? cv::Point2d(line_div, t) : cv::Point2d(t, line_div);
    const cv::Point2d w = photo.WorkingFromPhoto(fit.mapping.ImageFromScreen(screen));
    const int x = static_cast<int>(std::lround(w.x)), y = static_cast<int>(std::lround(w.y));
    ++count;  // a place outside the photo counts as unseen
    if (x < 1 || y < 1 || x + 1 >= ridge.cols || y + 1 >= ridge.rows) continue;
    float best = 0.0f;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) best = std::max(best, ridge(y + dy, x + dx));
    }
    sum += best;
  }
  return count > 0 ? sum / count : 0.0;
}

}  // namespace

OuterLines JudgeOuterLines(const PreparedPhoto& photo, const GraticuleFit& fit) {
  OuterLines result;
  result.agree = true;
  for (int family = 0; family < 2; ++family) {
    const int n = fit.divisions[family];
    const double first = family == 0 ? 0.0 : -0.5 * fit.divisions[1];
    auto strength = [&](int i) { return LineStrength(photo, fit, family, first + i); };
    std::vector<double> inner;
    for (int i = 1; i < n; ++i) inner.push_back(strength(i));
    if (inner.empty()) continue;
    std::nth_element(inner.begin(), inner.begin() + inner.size() / 2, inner.end());
    // A quarter: the outermost lines of the lattices found on the
    // generator's digital screens stand at 0.48 or more of the inner lines'
    // median (vignetting, a trace along one), lines beyond a screen's grid
    // at 0.07 or less.
    const double quarter = kOuterLineShare * inner[inner.size() / 2];
    const bool first_stands = strength(0) >= quarter, last_stands = strength(n) >= quarter;
    if (first_stands && last_stands) continue;
    result.agree = false;
    // One outermost line missing and the line beyond the other end there:
    // the grid lies a division that way.
    double move = 0.0;
    if (!first_stands && last_stands && strength(n + 1) >= quarter) move = 1.0;
    if (first_stands && !last_stands && strength(-1) >= quarter) move = -1.0;
    (family == 0 ? result.shift_div.x : result.shift_div.y) = move;
  }
  return result;
}

}  // namespace impactlab::digitize
