// Drawing a photo's look at random, and the rectangles it is framed by
// (internal to render/): what every style's drawing shares.
#pragma once

#include <random>
#include <vector>

#include <opencv2/core.hpp>

namespace impactlab::render {

inline double Uniform(std::mt19937_64& random, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(random);
}

inline int UniformInt(std::mt19937_64& random, int lo, int hi) {
  return std::uniform_int_distribution<int>(lo, hi)(random);
}

// A rectangle's corners, clockwise from its first.
inline std::vector<cv::Point2d> Corners(const cv::Rect2d& r) {
  return {{r.x, r.y}, {r.x + r.width, r.y}, {r.x + r.width, r.y + r.height}, {r.x, r.y + r.height}};
}

// The rectangle grown by dx either side and dy above and below.
inline cv::Rect2d Grow(const cv::Rect2d& r, double dx, double dy) {
  return {r.x - dx, r.y - dy, r.width + 2 * dx, r.height + 2 * dy};
}

}  // namespace impactlab::render
