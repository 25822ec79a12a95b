// The oscilloscope's face (internal to render/): where its parts lie, the
// graticule, the beam drawn flat in screen divisions with its phosphor glow,
// and the bezel and front panel around the face. Light is linear exposure, BGR,
// with the beam's core at brightness 1 near 1; the photo's tone curve comes later.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

#include "render/beam.h"

namespace impactlab::render {

// Where the parts of the scope face lie, in screen divisions.
struct ScreenLayout {
  cv::Rect2d graticule_div;  // x in [0, nx], y in [-ny/2, ny/2]
  cv::Rect2d face_div;       // the visible CRT face: the graticule and a margin
  double face_corner_div = 0.0;
  cv::Rect2d bezel_div;  // the outer edge of the bezel around the face
  double bezel_corner_div = 0.0;
  cv::Point2d centre_div;  // the graticule's centre
};

ScreenLayout LayOutScreen(const std::array<int, 2>& divisions);

// Signed distance from p to the rounded rectangle's edge: negative inside.
inline double RoundedRectDistance(cv::Point2d p, const cv::Rect2d& rect, double corner) {
  const double qx = std::abs(p.x - (rect.x + rect.width / 2)) - (rect.width / 2 - corner);
  const double qy = std::abs(p.y - (rect.y + rect.height / 2)) - (rect.height / 2 - corner);
  const double ox = std::max(qx, 0.0), oy = std::max(qy, 0.0);
  return std::sqrt(ox * ox + oy * oy) + std::min(std::max(qx, qy), 0.0) - corner;
}

// The graticule's lines: the division lines, the centre axes and their minor
// ticks (5 per division, 0.2 div long, unless `ticks` is false), like a
// Tektronix 555's.
class Graticule {
 public:
  explicit Graticule(const cv::Rect2d& graticule_div, bool ticks = true);

  // Squared distance (divisions^2) from p to the nearest line.
  double Distance2(cv::Point2d p) const {
    const double beyond_x = std::max({0.0, x0_ - p.x, p.x - x1_});
    const double beyond_y = std::max({0.0, y0_ - p.y, p.y - y1_});
    const double to_vertical = LatticeDistance(p.x, x0_, 1.0, nx_);
    const double to_horizontal = LatticeDistance(p.y, y0_, 1.0, ny_);
    double best = std::min(to_vertical * to_vertical + beyond_y * beyond_y,
                           to_horizontal * to_horizontal + beyond_x * beyond_x);
    // The centre axes (lines of their own when nx or ny is odd) and their ticks.
    const double off_x_axis = std::abs(p.y - yc_), off_y_axis = std::abs(p.x - xc_);
    best = std::min(best, off_y_axis * off_y_axis + beyond_y * beyond_y);
    best = std::min(best, off_x_axis * off_x_axis + beyond_x * beyond_x);
    if (ticks_ && off_x_axis < kTickReachDiv) {
      const double along = LatticeDistance(p.x, x0_, kTickDiv, x_ticks_);
      const double across = std::max(0.0, off_x_axis - kTickHalfLengthDiv);
      best = std::min(best, along * along + across * across);
    }
    if (ticks_ && off_y_axis < kTickReachDiv) {
      const double along = LatticeDistance(p.y, y0_, kTickDiv, y_ticks_);
      const double across = std::max(0.0, off_y_axis - kTickHalfLengthDiv);
      best = std::min(best, along * along + across * across);
    }
    return best;
  }

 private:
  static constexpr double kTickDiv = 0.2;
  static constexpr double kTickHalfLengthDiv = 0.1;
  static constexpr double kTickReachDiv = 0.5;  // beyond it a tick is never the nearest line

  // Distance from v to the nearest of first + k step, k = 0 .. count.
  static double LatticeDistance(double v, double first, double step, int count) {
    // Truncation instead of std::round: std::round is a library call on plain
    // x86-64, and negative positions clamp to k = 0 either way.
    const int k = std::clamp(static_cast<int>((v - first) / step + 0.5), 0, count);
    return std::abs(v - (first + k * step));
  }

  double x0_, x1_, y0_, y1_, xc_, yc_;
  int nx_, ny_, x_ticks_, y_ticks_;
  bool ticks_;
};

// The light on the face, in exposure units.
struct ScreenLook {
  cv::Vec3f phosphor_bgr{0.3f, 1.0f, 0.3f};    // the beam's core at brightness 1
  cv::Vec3f graticule_bgr{0.1f, 0.1f, 0.1f};   // a graticule line's centre
  cv::Vec3f face_bgr{0.003f, 0.005f, 0.004f};  // ambient light on the face
  double beam_sigma_div = 0.0085;              // the beam core's Gaussian sigma
  double graticule_sigma_div = 0.006;          // a graticule line's Gaussian sigma
  double glow_fraction = 0.15;    // phosphor glow around the beam, relative to the core
  double glow_sigma_div = 0.045;  // its Gaussian sigma
  bool graticule_ticks = true;    // the centre axes' minor ticks
  std::vector<cv::Rect2d> graticule_missing_div;  // where the graticule's paint is worn off
};

// The phosphor's light drawn flat: canvas pixels aligned with the screen.
struct PhosphorCanvas {
  cv::Mat exposure;                // CV_32FC1, brightness 1 at a slow beam's core
  cv::Matx23d canvas_from_screen;  // canvas pixels from screen divisions

  // Bilinear interpolation at a screen position (exact weights, unlike
  // cv::remap's 1/32-pixel ones); zero beyond the canvas.
  float Sample(cv::Point2d screen_div) const;
};

// Draws the beams at `px_per_div` over the face, adds the glow, and blurs the
// result by `blur_px` canvas pixels (the camera's blur, applied here so that the
// photo needs no full-size blur).
PhosphorCanvas RenderPhosphor(const ScreenLayout& layout, const std::vector<TraceBeam>& beams,
                              const ScreenLook& look, double px_per_div, double blur_px);

// What lies around the face.
struct SurroundLook {
  cv::Vec3f bezel_bgr{0.01f, 0.01f, 0.01f};  // the bezel, lit
  double bevel_highlight = 1.0;              // extra light on the bezel's inner lip
  cv::Vec3f outside_bgr{0.0f, 0.0f, 0.0f};   // beyond the bezel: camera hood or panel
  bool knobs = false;                        // front-panel knobs right of the bezel
  cv::Vec3f knob_bgr{0.01f, 0.01f, 0.01f};
};

// The exposure of the bezel or what lies beyond it at screen position p; edges
// ramp over `edge_div`.
cv::Vec3f SurroundExposure(cv::Point2d p, const ScreenLayout& layout, const SurroundLook& look,
                           double edge_div);

}  // namespace impactlab::render
