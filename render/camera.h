// How the screen lands in the photo (internal to render/): a pinhole camera
// looking at the flat screen from a tilt, rolled in the image plane, followed
// by radial lens distortion. Everything here is exact and invertible, so the
// truth the renderer reports is the mapping itself.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "render/oscillograph.h"

namespace impactlab::render {

// The camera's pose and framing, as drawn for one photo.
struct CameraPose {
  double rotation_deg = 0.0;        // roll in the image, counter-clockwise as seen
  double tilt_deg = 0.0;            // camera axis off the screen normal
  double tilt_azimuth_deg = 0.0;    // direction of the tilt axis on the screen
  double camera_distance_div = 30;  // pinhole to screen centre, in screen divisions
  double barrel_k1 = 0.0;           // radial distortion at the half diagonal
  double fill = 0.9;                // fraction of the frame the framed outline spans
  cv::Point2d offset{0.0, 0.0};     // -1..1: where the outline sits in the spare frame
};

// The mapping that puts `outline_div` (screen positions, e.g. the bezel's or the
// print's corners) into the middle of an image of `image_size`, spanning
// `pose.fill` of it in the tighter direction. `centre_div` is the screen point
// the camera looks at.
CameraMapping FrameCamera(const CameraPose& pose, const std::vector<cv::Point2d>& outline_div,
                          cv::Point2d centre_div, cv::Size image_size);

// CameraMapping::ScreenFromImage for many pixels: the inverse homography is
// computed once.
class ScreenFromPixel {
 public:
  explicit ScreenFromPixel(const CameraMapping& mapping);

  cv::Point2d operator()(double col, double row) const {
    const double dx = col - centre_px_.x, dy = row - centre_px_.y;
    double s = 1.0;  // undistorted radius / distorted radius
    if (k_per_px2_ != 0.0) {
      // Newton on s + a s^3 = 1 (a = k rd^2) from the series 1 - a + 3 a^2;
      // for |a| <= 0.1 three steps leave less than 1e-15.
      const double k_rd2 = k_per_px2_ * (dx * dx + dy * dy);
      s = 1.0 - k_rd2 + 3.0 * k_rd2 * k_rd2;
      for (int iteration = 0; iteration < 3; ++iteration) {
        const double ks2 = k_rd2 * s * s;
        s -= (s + ks2 * s - 1.0) / (1.0 + 3.0 * ks2);
      }
    }
    const double qx = centre_px_.x + dx * s, qy = centre_px_.y + dy * s;
    const cv::Matx33d& h = screen_from_undistorted_;
    const double w = h(2, 0) * qx + h(2, 1) * qy + h(2, 2);
    return {(h(0, 0) * qx + h(0, 1) * qy + h(0, 2)) / w,
            (h(1, 0) * qx + h(1, 1) * qy + h(1, 2)) / w};
  }

 private:
  cv::Matx33d screen_from_undistorted_;
  cv::Point2d centre_px_;
  double k_per_px2_;  // k1 / r^2
};

// The image length of one screen division at screen point p (the square root
// of the mapping's local area stretch), pixels per division.
double PixelsPerDivisionAt(const CameraMapping& mapping, cv::Point2d p);

// The largest image length of one screen division anywhere in `region_div`
// (the mapping's largest local stretch), pixels per division.
double MaxPixelsPerDivision(const CameraMapping& mapping, const cv::Rect2d& region_div);

}  // namespace impactlab::render
