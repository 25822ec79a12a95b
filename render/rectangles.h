// The rectangles a photo is laid out in, in screen divisions (internal to
// render/): the screen's face and bezel, the print's border, a style's frames.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace impactlab::render {

// A rectangle's corners, clockwise from its first.
inline std::vector<cv::Point2d> Corners(const cv::Rect2d& r) {
  return {{r.x, r.y}, {r.x + r.width, r.y}, {r.x + r.width, r.y + r.height}, {r.x, r.y + r.height}};
}

// The rectangle grown by dx either side and dy above and below.
inline cv::Rect2d Grow(const cv::Rect2d& r, double dx, double dy) {
  return {r.x - dx, r.y - dy, r.width + 2 * dx, r.height + 2 * dy};
}

// The rectangle grown by `by` on every side.
inline cv::Rect2d Grow(const cv::Rect2d& r, double by) {
  return {r.x - by, r.y - by, r.width + 2 * by, r.height + 2 * by};
}

}  // namespace impactlab::render
